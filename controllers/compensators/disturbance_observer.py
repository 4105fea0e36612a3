"""A linear disturbance observer: the nominal inverse plant with a Q-filter (model-free)."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy.linalg import expm

from prefriction._validation import check_interval, check_positive

from ._base import Compensator

__all__ = ["DisturbanceObserver"]


@dataclass(frozen=True)
class _Structure:
    n_state: int = 3
    n_param: int = 12

    def function(self) -> ca.Function:
        c, meas, ref, p = ca.SX.sym("c", 3), ca.SX.sym("meas", 2), ca.SX.sym("ref", 4), ca.SX.sym("par", 12)
        xi, y_prev = c[:2], c[2]
        Ad = ca.reshape(p[0:4], 2, 2)
        Bd = ca.reshape(p[4:8], 2, 2)  # columns: u, y
        Cd, Dy = p[8:10], p[10]
        y, u_prev = meas[0], meas[1]
        xi_next = ca.mtimes(Ad, xi) + ca.mtimes(Bd, ca.vertcat(u_prev, y_prev))
        force = ca.dot(Cd, xi_next) + Dy * y
        return ca.Function("disturbance_observer", [c, meas, ref, p], [ca.vertcat(xi_next, y), force])


@dataclass(frozen=True)
class DisturbanceObserver(Compensator):
    """Disturbance observer: ``F^ = Q(s) (u - m_n s^2 y)`` with ``Q(s) = w^2 / (s^2 + 2 zeta w s + w^2)``.

    The force that the nominal plant ``1 / (m_n s^2)`` does not explain, ``u - m_n x''``, is the
    friction (and any other disturbance, and the mismatch of the mass); the Q-filter of
    bandwidth ``w`` (unit static gain, relative degree two so that ``Q m_n s^2`` is proper)
    makes it realisable and limits the noise it passes. ``F^`` is added to the controller's
    force (Ohnishi's disturbance observer; a model-free peer of the friction observers).

    Realisation: observable canonical form with the shared denominator, inputs ``u`` and ``y``:
    ``Q = w^2 / a(s)`` and ``-m_n s^2 Q = -m_n w^2 + m_n w^2 (2 zeta w s + w^2) / a(s)``;
    discretised with a zero-order hold over ``Ts`` (exact for the held force ``u``). In the
    loop ``F^_k`` uses ``u_{k-1}`` and ``y_{k-1}`` in the state and ``y_k`` directly.

    Parameters
    ----------
    bandwidth : float
        Q-filter natural frequency ``w`` [rad/s], ``0 < w < inf`` (below the Nyquist frequency
        ``pi / Ts`` of the loop).
    mass : float, optional
        Nominal mass ``m_n`` [kg], ``> 0``; default the stage's mass.
    zeta : float, default 1.0
        Q-filter damping [-], ``0 < zeta <= 10`` (1: a double real pole).

    Examples
    --------
    >>> from prefriction import controllers
    >>> dob = controllers.DisturbanceObserver(bandwidth=2000.0)
    >>> params, state0 = dob.numbers(mass=1.0, Ts=1e-4, x0=0.0)
    >>> params.shape, state0.shape
    ((12,), (3,))
    """

    bandwidth: float
    mass: float | None = None
    zeta: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "bandwidth", check_positive("bandwidth", self.bandwidth))
        if self.mass is not None:
            object.__setattr__(self, "mass", check_positive("mass", self.mass))
        object.__setattr__(self, "zeta", check_interval("zeta", self.zeta, 0.0, 10.0))
        if self.zeta == 0.0:
            raise ValueError("zeta must be > 0 (a stable Q-filter; allowed 0 < zeta <= 10), got 0.0")

    def structure(self) -> _Structure:
        """The compiled structure (one for every disturbance observer)."""
        return _Structure()

    def continuous(self, mass: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C, D)`` of the continuous observer, inputs ``[u, y]``, output ``F^`` [N]."""
        m = self.mass if self.mass is not None else check_positive("mass", mass)
        w, z = self.bandwidth, self.zeta
        A = np.array([[-2.0 * z * w, 1.0], [-w * w, 0.0]])
        B = np.array([[0.0, m * w * w * 2.0 * z * w], [w * w, m * w ** 4]])
        return A, B, np.array([[1.0, 0.0]]), np.array([[0.0, -m * w * w]])

    def numbers(self, mass: float, Ts: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
        """``params = [Ad, Bd, Cd, Dy, 0]`` (column-major) of the ZOH discretisation; state
        ``[xi, y_{k-1}]`` at the steady state of a stage resting at ``x0`` with ``u = 0``."""
        Ts = check_positive("Ts", Ts)
        if self.bandwidth * Ts >= np.pi:
            raise ValueError(f"bandwidth must be below the Nyquist frequency pi / Ts = {np.pi / Ts:.6g} rad/s, "
                             f"got {self.bandwidth!r}")
        A, B, C, D = self.continuous(mass)
        E = expm(np.block([[A, B], [np.zeros((2, 4))]]) * Ts)
        Ad, Bd = E[:2, :2], E[:2, 2:]
        xi0 = np.linalg.solve(np.eye(2) - Ad, Bd[:, 1] * x0)
        params = np.concatenate([Ad.T.ravel(), Bd.T.ravel(), C[0], [D[0, 1], 0.0]])
        return params, np.array([xi0[0], xi0[1], x0])

    def __str__(self) -> str:
        return f"DisturbanceObserver(w={self.bandwidth:.4g} rad/s)"
