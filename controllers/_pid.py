"""PD and PID controllers for the pre-sliding positioning loop, as python-control LTI objects.

A :class:`PID` is a small, validated description (gains, derivative filter, optional force
limit for anti-windup) that produces its linear form as a python-control ``StateSpace`` or
``TransferFunction`` from the position error ``e = r - x`` [m] to the force ``u`` [N]:

    C(s) = kp + ki / s + kd s / (tau s + 1)

The anti-windup (back-calculation) acts only when a force limit ``u_max`` is given, and only in
:func:`controllers.simulate_loop` (sampled or continuous loops): a saturation is not linear, so
the LTI object itself cannot carry it. Exported as a plain LTI object (``pid.ss()``,
``pid.c2d(Ts)``) the controller is the unsaturated linear law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import control
import numpy as np

from prefriction._validation import check_nonnegative, check_positive


@dataclass(frozen=True, kw_only=True)
class PID:
    """PID controller with a first-order derivative filter and optional anti-windup.

    ``C(s) = kp + ki / s + kd s / (tau s + 1)``, input the position error ``e = r - x`` [m],
    output the force ``u`` [N]. With ``ki = 0`` it is a PD controller (no integrator state).

    Parameters
    ----------
    kp : float
        Proportional gain [N/m], ``0 <= kp < inf``.
    ki : float, default 0.0
        Integral gain [N/(m s)], ``0 <= ki < inf``.
    kd : float, default 0.0
        Derivative gain [N s/m], ``0 <= kd < inf``.
    tau : float, optional
        Time constant of the derivative filter [s], ``0 < tau < inf``. Default
        ``tau = kd / (N kp)`` (that is ``Td / N`` with ``Td = kd / kp``, Astrom and Hagglund).
    N : float, default 10.0
        Derivative filter ratio used when ``tau`` is not given, ``0 < N < inf``.
    u_max : float, optional
        Force limit [N], ``0 < u_max < inf``. Only :func:`controllers.simulate_loop` uses it,
        for sampled and continuous loops: the plant receives ``clip(u, -u_max, u_max)`` and the
        integrator is corrected by back-calculation. ``None``: no limit, the loop is the linear law.
    t_track : float, optional
        Tracking time constant of the back-calculation anti-windup [s], ``0 < t_track < inf``:
        ``d/dt (ki * integral) = ki e + (sat(u) - u) / t_track``. Default
        ``sqrt(Ti Td)`` with ``Ti = kp / ki``, ``Td = kd / kp`` (Astrom and Hagglund), or
        ``Ti`` if ``kd = 0``.

    Raises
    ------
    ValueError
        If a gain is negative or not finite, ``tau``, ``N``, ``u_max`` or ``t_track`` is not
        finite and positive, or ``kd > 0`` with ``kp = 0`` and no ``tau``.
    TypeError
        If an argument is not a real number or an unknown keyword is given.
    """

    kp: float
    ki: float = 0.0
    kd: float = 0.0
    tau: Optional[float] = None
    N: float = 10.0
    u_max: Optional[float] = None
    t_track: Optional[float] = None

    def __post_init__(self) -> None:
        for name in ("kp", "ki", "kd"):
            object.__setattr__(self, name, check_nonnegative(name, getattr(self, name)))
        object.__setattr__(self, "N", check_positive("N", self.N))
        if self.tau is not None:
            object.__setattr__(self, "tau", check_positive("tau", self.tau))
        elif self.kd > 0.0:
            if self.kp == 0.0:
                raise ValueError(
                    f"tau must be given when kd > 0 and kp = 0 (the default tau = kd / (N kp) "
                    f"needs kp > 0), got kd={self.kd!r}, kp=0.0, tau=None"
                )
            object.__setattr__(self, "tau", self.kd / (self.N * self.kp))
        if self.u_max is not None:
            object.__setattr__(self, "u_max", check_positive("u_max", self.u_max))
        if self.t_track is not None:
            object.__setattr__(self, "t_track", check_positive("t_track", self.t_track))

    @property
    def has_integrator(self) -> bool:
        """True if ``ki > 0`` (the controller has an integrator state)."""
        return self.ki > 0.0

    @property
    def tracking_time(self) -> Optional[float]:
        """Back-calculation tracking time constant [s] (``None`` without integrator)."""
        if not self.has_integrator:
            return None
        if self.t_track is not None:
            return self.t_track
        Ti = self.kp / self.ki
        if self.kd > 0.0 and self.kp > 0.0:
            return math.sqrt(Ti * self.kd / self.kp)
        return Ti if Ti > 0.0 else 1.0 / self.ki

    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """State-space matrices: states [integral of e (if ki > 0), filtered e (if kd > 0)]."""
        A, B, C = [], [], []
        if self.has_integrator:  # xi' = e, contributes ki * xi
            A.append(0.0)
            B.append(1.0)
            C.append(self.ki)
        D = self.kp
        if self.kd > 0.0:  # xf' = (e - xf) / tau, contributes (kd / tau) (e - xf)
            A.append(-1.0 / self.tau)
            B.append(1.0 / self.tau)
            C.append(-self.kd / self.tau)
            D += self.kd / self.tau
        n = len(A)
        return (
            np.diag(A).reshape(n, n),
            np.array(B, dtype=float).reshape(n, 1),
            np.array(C, dtype=float).reshape(1, n),
            np.array([[D]]),
        )

    def ss(self) -> control.StateSpace:
        """Continuous linear controller as ``control.StateSpace`` (input ``e`` [m], output ``u`` [N])."""
        return control.ss(*self._matrices(), inputs="e", outputs="u", name="controller")

    def tf(self) -> control.TransferFunction:
        """Continuous linear controller ``kp + ki/s + kd s/(tau s + 1)`` as ``control.TransferFunction``.

        Built from the polynomial coefficients (not converted from :meth:`ss`, which would
        cost digits).
        """
        integ = np.array([1.0, 0.0]) if self.has_integrator else np.array([1.0])
        filt = np.array([self.tau, 1.0]) if self.kd > 0.0 else np.array([1.0])
        den = np.polymul(integ, filt)
        num = self.kp * den
        if self.has_integrator:
            num = np.polyadd(num, self.ki * filt)
        if self.kd > 0.0:
            num = np.polyadd(num, self.kd * np.polymul([1.0, 0.0], integ))
        return control.tf(num, den, inputs="e", outputs="u", name="controller")

    def c2d(self, Ts: float, method: str = "zoh") -> control.StateSpace:
        """Discrete linear controller for sample time ``Ts`` [s] (``control.c2d``, default ZOH)."""
        Ts = check_positive("Ts", Ts)
        return control.c2d(self.ss(), Ts, method=method)

    def back_calculation_gain(self) -> np.ndarray:
        """Per-state anti-windup gain ``k`` in ``xc' = A xc + B e + k (sat(u) - u)`` [1/(N s)]."""
        n = int(self.has_integrator) + int(self.kd > 0.0)
        k = np.zeros(n)
        if self.has_integrator:
            k[0] = 1.0 / (self.ki * self.tracking_time)
        return k

    def __str__(self) -> str:
        parts = [f"kp={self.kp:.6g} N/m"]
        if self.has_integrator:
            parts.append(f"ki={self.ki:.6g} N/(m s)")
        if self.kd > 0.0:
            parts.append(f"kd={self.kd:.6g} N s/m, tau={self.tau:.4g} s")
        if self.u_max is not None:
            parts.append(f"u_max={self.u_max:.4g} N")
        return ("PID(" if self.has_integrator else "PD(") + ", ".join(parts) + ")"


def pd(kp: float, kd: float, *, tau: Optional[float] = None, N: float = 10.0) -> PID:
    """PD controller ``kp + kd s / (tau s + 1)`` from the error [m] to the force [N].

    Parameters
    ----------
    kp : float
        Proportional gain [N/m], >= 0.
    kd : float
        Derivative gain [N s/m], >= 0.
    tau : float, optional
        Derivative filter time constant [s], > 0; default ``kd / (N kp)``.
    N : float, default 10
        Derivative filter ratio used when ``tau`` is not given, > 0.

    Returns
    -------
    PID
    """
    return PID(kp=kp, kd=kd, tau=tau, N=N)


def pid(
    kp: float,
    ki: float,
    kd: float,
    *,
    tau: Optional[float] = None,
    N: float = 10.0,
    u_max: Optional[float] = None,
    t_track: Optional[float] = None,
) -> PID:
    """PID controller ``kp + ki/s + kd s / (tau s + 1)`` from the error [m] to the force [N].

    Parameters
    ----------
    kp : float
        Proportional gain [N/m], >= 0.
    ki : float
        Integral gain [N/(m s)], >= 0.
    kd : float
        Derivative gain [N s/m], >= 0.
    tau : float, optional
        Derivative filter time constant [s], > 0; default ``kd / (N kp)``.
    N : float, default 10
        Derivative filter ratio used when ``tau`` is not given, > 0.
    u_max : float, optional
        Force limit [N], > 0, with back-calculation anti-windup (sampled and continuous loops).
    t_track : float, optional
        Tracking time constant [s] of the anti-windup (see :class:`PID`).

    Returns
    -------
    PID
    """
    return PID(kp=kp, ki=ki, kd=kd, tau=tau, N=N, u_max=u_max, t_track=t_track)
