"""A reduced-order asymptotic observer of velocity and friction from the position alone (Ruderman)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from prefriction._validation import check_positive
from prefriction.models import Dahl, ElastoPlastic, LuGre
from prefriction.models.base import FrictionModel

from ._base import Compensator

__all__ = ["FrictionObserver"]


@dataclass(frozen=True)
class _Structure:
    n_state: int = 3
    n_param: int = 7

    def function(self) -> ca.Function:
        c, meas, ref, p = ca.SX.sym("c", 3), ca.SX.sym("meas", 2), ca.SX.sym("ref", 4), ca.SX.sym("par", 7)
        xi1, xi2, y_prev = c[0], c[1], c[2]
        sigma, Fc, mass, l1, l2, Ts, gamma = (p[i] for i in range(7))
        y, u_prev = meas[0], meas[1]
        v_prev = xi1 + l1 * y_prev  # the velocity estimate at t_{k-1}
        x3_prev = xi2 + l2 * y_prev  # the friction estimate at t_{k-1}
        # sigma(t) = sigma w^(gamma - 1), w = 1 - sgn(x2) x3 / Fc in (0, 2) for the true state; the
        # estimate's w clipped into [0, 2] (gamma = 1: w^0 = 1, sigma(t) = sigma)
        w = ca.fmin(ca.fmax(1.0 - ca.sign(v_prev) * x3_prev / Fc, 0.0), 2.0)
        sigma_t = sigma * w ** (gamma - 1.0)
        beta = sigma_t * ca.fabs(v_prev) / Fc
        # xi' = M xi + M L y + B2 u, M = [[-l1, -1/m], [sigma(t) - l2, -beta]]: trapezoidal rule
        M = ca.SX(2, 2)
        M[0, 0], M[0, 1], M[1, 0], M[1, 1] = -l1, -1.0 / mass, sigma_t - l2, -beta
        L = ca.vertcat(l1, l2)
        xi = ca.vertcat(xi1, xi2)
        drive = ca.mtimes(M, L) * 0.5 * (y_prev + y) + ca.vertcat(u_prev / mass, 0.0)
        I2 = ca.SX.eye(2)
        xi_next = ca.solve(I2 - 0.5 * Ts * M, ca.mtimes(I2 + 0.5 * Ts * M, xi) + Ts * drive)
        force = xi_next[1] + l2 * y
        return ca.Function("friction_observer", [c, meas, ref, p], [ca.vertcat(xi_next, y), force])


def _dahl_numbers(model: FrictionModel) -> tuple[float, float, float]:
    """Rest stiffness ``sigma`` [N/m], Coulomb force ``Fc`` [N] and shape factor ``gamma`` [-] of
    the observer's Dahl model (``gamma = 1`` for LuGre and ElastoPlastic)."""
    if isinstance(model, Dahl):
        if model.gamma < 1.0:
            raise ValueError(f"model must be a Dahl model with gamma >= 1 (the observer's friction state-space; "
                             f"gamma < 1 saturates at |F| = Fc, where sigma(t) = sigma w^(gamma - 1) is unbounded), "
                             f"got gamma={model.gamma!r}; fit the gamma >= 1 structure (identify.fit's default "
                             f"structures='given' from a start with gamma >= 1, or fixed=['gamma'] at 1), or "
                             f"compensate with controllers.Feedforward, which takes any gamma")
        return model.sigma, model.Fc, model.gamma
    if isinstance(model, (LuGre, ElastoPlastic)):
        return model.sigma0, model.Fc, 1.0
    raise TypeError(f"model must be a prefriction.Dahl (gamma >= 1), LuGre or ElastoPlastic model, got {model!r} "
                    f"of type {type(model).__name__}")


@dataclass(frozen=True)
class FrictionObserver(Compensator):
    """Reduced-order asymptotic observer of velocity and friction from the position alone.

    After M. Ruderman, "Reduced-order asymptotic observer of nonlinear friction for precise
    motion control", Control Engineering Practice, 2025 (arXiv 2504.21316), and "Robust
    asymptotic observer of motion states with nonlinear friction", IFAC World Congress 2023
    (arXiv 2305.15870): the stage ``x1' = x2``, ``m x2' = u - x3`` with the dynamic friction
    force written as a state with a time-varying coefficient (the Dahl form (3.2) with
    ``gamma = 1``; ``gamma > 1`` below),

        x3' = sigma x2 - beta(t) x3,    beta(t) = sigma |x2| / Fc >= 0,

    i.e. ``w' = A22(t) w + B2 u`` for ``w = [x2, x3]``, observed through the measured
    displacement ``y = x1`` (``y' = x2``). The reduced-order Luenberger observer with gain
    ``L = [l1, l2]`` estimates ``w^ = xi + L y`` with

        xi' = M(t) xi + M(t) L y + B2 u,    M(t) = A22(t) - L [1, 0] = [[-l1, -1/m], [sigma - l2, -beta]],

    and its error ``w - w^`` obeys ``e' = M(t) e``. The compensation force is the estimate
    ``x3^``. Design (the dominant, slowest pole): the poles at rest (``beta = 0``) are
    ``-p`` and ``-p_fast``: ``l1 = p + p_fast``, ``l2 = sigma - m p p_fast``. The eigenvalues
    of ``M(t)`` stay real and negative for every ``beta`` in ``[0, (sqrt(p_fast) -
    sqrt(p))^2]``, i.e. up to the speed :attr:`max_velocity`, and again for ``beta >=
    (sqrt(p_fast) + sqrt(p))^2``; in the band between they are a complex pair with a negative real
    part. No condition on how fast ``beta(t)`` varies (which the stability of the time-varying
    error system needs) is computed or checked. The equations are reconstructed from the papers'
    abstracts, not taken from them (``docs/compensation.md#friction-observer``).

    Dahl models with ``gamma > 1`` (our own extension, not from the papers): (3.2) is the same
    form with a state-dependent stiffness,

        x3' = sigma(t) x2 - beta(t) x3,    sigma(t) = sigma w^(gamma - 1),    beta(t) = sigma(t) |x2| / Fc,

    ``w = 1 - sgn(x2) x3 / Fc``, which lies in ``(0, 2)`` on every branch; the observer evaluates
    it with the estimates, clipped into ``[0, 2]``, and ``M(t)`` takes ``sigma(t) - l2`` in place
    of ``sigma - l2``. The gains are designed at rest (``sigma(t) = sigma``); the frozen
    eigenvalues keep negative real parts while ``sigma(t) - l2 > -m l1 beta(t)``, which holds for
    every ``w`` when ``l2 <= 0`` (``m p p_fast >= sigma``). ``gamma < 1`` is refused: it
    saturates at ``|F| = Fc`` (``w = 0``), where ``sigma(t)`` is unbounded.

    Assumptions (stated as in the abstract of the 2025 paper; the paper's equation numbers
    could not be read here, see ``docs/compensation.md``): only the displacement is measured;
    the friction follows the Dahl-type state-space above (pre-sliding and sliding, no Stribeck
    effect, no viscous term); ``m``, ``sigma``, ``Fc`` are known; the eigenvalues of
    ``M(t)`` are real and negative at all times (speeds below :attr:`max_velocity`); ``beta``
    is evaluated with the estimated velocity. In the sampled loop ``xi`` is advanced by the
    trapezoidal rule over each period with ``beta`` frozen at its start, ``y`` linear and the
    held force ``u_{k-1}``.

    Parameters
    ----------
    model : prefriction.Dahl, prefriction.LuGre or prefriction.ElastoPlastic
        Model of the stage's friction: Dahl with ``gamma >= 1`` (``sigma``, ``Fc``, ``gamma``), LuGre or
        ElastoPlastic (``sigma0``, ``Fc``; the Stribeck, damping and breakaway terms are not used).
    pole : float
        Dominant (slowest) observer pole ``p`` [rad/s], ``0 < p < inf``.
    fast_pole : float, optional
        Second pole at rest ``p_fast`` [rad/s], ``> pole``; default ``10 pole``.

    Examples
    --------
    >>> import prefriction as pf
    >>> from prefriction import controllers
    >>> obs = controllers.FrictionObserver(pf.Dahl(sigma=1e6, Fc=1.0), pole=500.0)
    >>> round(obs.max_velocity(), 6)  # m/s
    0.002338
    """

    model: FrictionModel
    pole: float
    fast_pole: float | None = None

    def __post_init__(self) -> None:
        _dahl_numbers(self.model)
        object.__setattr__(self, "pole", check_positive("pole", self.pole))
        fast = 10.0 * self.pole if self.fast_pole is None else check_positive("fast_pole", self.fast_pole)
        if not fast > self.pole:
            raise ValueError(f"fast_pole must be > pole = {self.pole!r} rad/s (distinct real poles), got {fast!r}")
        object.__setattr__(self, "fast_pole", fast)

    def gains(self, mass: float) -> tuple[float, float]:
        """Observer gains ``(l1, l2)`` [1/s, N/m] placing the poles at rest at ``-pole``, ``-fast_pole``."""
        sigma = _dahl_numbers(self.model)[0]
        return self.pole + self.fast_pole, sigma - mass * self.pole * self.fast_pole

    def max_velocity(self) -> float:
        """Largest speed [m/s] for which the eigenvalues of ``M(t)`` are real and negative:
        ``Fc (sqrt(p_fast) - sqrt(p))^2 / sigma`` (at ``sigma(t) = sigma``)."""
        sigma, Fc, _ = _dahl_numbers(self.model)
        return Fc * (math.sqrt(self.fast_pole) - math.sqrt(self.pole)) ** 2 / sigma

    def structure(self) -> _Structure:
        """The compiled structure (one for every such observer)."""
        return _Structure()

    def numbers(self, mass: float, Ts: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
        """``params = [sigma, Fc, m, l1, l2, Ts, gamma]``; state ``[xi1, xi2, y_{k-1}]`` of a stage
        at rest at ``x0`` with no friction force (``xi = -L x0``)."""
        sigma, Fc, gamma = _dahl_numbers(self.model)
        l1, l2 = self.gains(mass)
        return np.array([sigma, Fc, mass, l1, l2, Ts, gamma]), np.array([-l1 * x0, -l2 * x0, x0])

    def __str__(self) -> str:
        return f"FrictionObserver(p={self.pole:.4g} rad/s)"
