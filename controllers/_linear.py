"""Linearised plants, linear closed loops, stability margins and pole-placement designs.

Two linearisations of the stage ``m x'' = u - F`` with any friction model of the protocol
(:class:`prefriction.models.FrictionModel`: Dahl (3.2), Maxwell-slip, GMS, LuGre):

- pre-sliding (``regime="presliding"``): near a rest point the friction is a spring of rest
  stiffness ``sigma``, the model's reference stiffness (Dahl: the slope of (3.2) at ``F = 0``;
  Maxwell-slip: the sum of the element stiffnesses; LuGre: ``sigma0``),
  ``P(s) = 1 / (m s^2 + sigma)``;
- sliding (``regime="sliding"``): in gross sliding the friction is the constant ``+-Fc`` and
  drops out of the small-signal model, ``P(s) = 1 / (m s^2)``.

The linear loop is ``x = P u``, ``u = C (r - x)``; a discrete controller (``dt > 0``) is closed
around the ZOH discretisation ``control.c2d(P, dt, "zoh")``, exact at the sample instants.
"""

from __future__ import annotations

import functools
import math
import warnings
from typing import Optional

import control
import numpy as np

from prefriction._validation import check_bool, check_count, check_interval, check_positive
from prefriction.models import Oscillator
from prefriction.simulation.loops.compiled_loop import MAX_DELAY

from ._pid import PID
from .compensators.lugre_observer import LuGreObserver

REGIMES = ("presliding", "sliding")


class UnstableLoopWarning(UserWarning):
    """The linear closed loop of a design is not asymptotically stable (its poles are in the message)."""


def _check_system(system: Oscillator) -> Oscillator:
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
    return system


def _check_regime(regime: str) -> str:
    if regime not in REGIMES:
        raise ValueError(f"regime must be one of {REGIMES}, got {regime!r}")
    return regime


def as_lti(controller: "PID | control.LTI") -> control.StateSpace:
    """Controller as a SISO, proper ``control.StateSpace`` from the error [m] to the force [N].

    Raises
    ------
    TypeError
        If ``controller`` is neither a :class:`PID` nor a python-control LTI system.
    ValueError
        If it is not SISO, not proper (a transfer function with more zeros than poles) or has
        non-finite coefficients.
    """
    if isinstance(controller, PID):
        return controller.ss()
    if not isinstance(controller, (control.TransferFunction, control.StateSpace)):
        raise TypeError(
            "controller must be a controllers.PID or a python-control TransferFunction/StateSpace "
            f"from the error e [m] to the force u [N], got {controller!r} of type {type(controller).__name__}"
        )
    if controller.ninputs != 1 or controller.noutputs != 1:
        raise ValueError(
            f"controller must be SISO (1 input e, 1 output u), got {controller.ninputs} inputs "
            f"and {controller.noutputs} outputs"
        )
    if isinstance(controller, control.TransferFunction):
        num = np.trim_zeros(np.atleast_1d(np.squeeze(controller.num[0][0])), "f")
        den = np.trim_zeros(np.atleast_1d(np.squeeze(controller.den[0][0])), "f")
        if len(num) > len(den):
            raise ValueError(
                f"controller must be proper (degree of numerator <= degree of denominator), "
                f"got numerator degree {len(num) - 1} > denominator degree {len(den) - 1}; "
                "add a derivative filter, e.g. kd s / (tau s + 1)"
            )
        sys = control.ss(controller)
    else:
        sys = controller
    mats = (sys.A, sys.B, sys.C, sys.D)
    if not all(np.all(np.isfinite(M)) for M in mats):
        raise ValueError("controller matrices must be finite, got NaN or inf")
    return sys


def linear_plant(system: Oscillator, regime: str = "presliding", Ts: Optional[float] = None) -> control.StateSpace:
    """Linearised stage from the force ``u`` [N] to the position ``x`` [m].

    Parameters
    ----------
    system : prefriction.Oscillator
        Mass ``m`` [kg] and friction model with rest stiffness ``sigma`` [N/m].
    regime : {"presliding", "sliding"}
        ``1 / (m s^2 + sigma)`` (friction as its rest-stiffness spring, slope of (3.2) at
        ``F = 0``) or ``1 / (m s^2)`` (gross sliding, Coulomb force constant).
    Ts : float, optional
        Sample time [s]: return the exact ZOH discretisation (``control.c2d``).

    Returns
    -------
    control.StateSpace
        States ``x`` [m], ``v`` [m/s]; input ``u``; output ``x``.
    """
    _check_system(system)
    _check_regime(regime)
    m = system.mass
    k = system.friction.sigma if regime == "presliding" else 0.0
    return _plant(m, k, None if Ts is None else check_positive("Ts", Ts))


@functools.lru_cache(maxsize=64)
def _plant(m: float, k: float, Ts: Optional[float]) -> control.StateSpace:
    """``1/(m s^2 + k)`` as a state-space system, ZOH-discretised if ``Ts`` (cached: each loop
    simulation checks its linear loop, and ``c2d`` costs milliseconds)."""
    P = control.ss([[0.0, 1.0], [-k / m, 0.0]], [[0.0], [1.0 / m]], [[1.0, 0.0]], [[0.0]],
                   inputs="u", outputs="x", states=["x", "v"], name="plant")
    return P if Ts is None else control.c2d(P, Ts, method="zoh")


def closed_loop(
    system: Oscillator, controller: "PID | control.LTI", *, regime: str = "presliding", warn: bool = True,
    delay: int = 0,
) -> control.StateSpace:
    """Linear closed loop from the reference ``r`` [m] to the position ``x`` [m].

    ``T = P C / (1 + P C z^-d)`` built with ``control.feedback``. A discrete controller
    (``dt > 0``) is closed around the ZOH-discretised plant, exact at the sample instants; a
    measurement delay of ``d`` samples is the exact discrete delay ``z^-d`` in the feedback
    path (the controller sees ``x(t_{k-d})``, as :func:`controllers.simulate_loop` with
    ``delay=d``). If the loop is not asymptotically stable a :class:`UnstableLoopWarning` lists
    its poles (``warn=True``).

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage: mass [kg] and a friction model with rest stiffness ``sigma`` [N/m].
    controller : PID or control.LTI
        Controller from the error ``e = r - x`` [m] to the force ``u`` [N], continuous or discrete.
    regime : {"presliding", "sliding"}, default "presliding"
        Linearisation of the plant: ``1/(m s^2 + sigma)`` or ``1/(m s^2)``.
    warn : bool, default True
        Warn with the poles if the closed loop is unstable.
    delay : int, default 0
        Measurement delay in whole samples, ``0 <= delay <= 8`` (a discrete controller only).

    Returns
    -------
    control.StateSpace
        The closed loop ``r -> x`` (discrete with the controller's ``dt`` if it is discrete).

    Raises
    ------
    TypeError
        ``system`` is not an Oscillator, ``controller`` no PID or SISO LTI, ``warn`` not
        ``True`` or ``False``.
    ValueError
        ``regime`` unknown, a discrete controller without a sample time, ``delay`` outside
        ``[0, 8]`` or a delay with a continuous controller.
    """
    warn = check_bool("warn", warn)
    delay = check_count("delay", delay, 0, MAX_DELAY, why="the measurement buffer of the compiled loop")
    C = as_lti(controller)
    Ts = _sample_time(C)
    if delay and Ts is None:
        raise ValueError(f"delay={delay!r} samples needs a discrete controller (dt > 0); the controller is continuous")
    P = linear_plant(system, regime, Ts)
    H = 1 if not delay else control.tf([1.0], [1.0] + [0.0] * delay, Ts)  # z^-d
    T = control.ss(control.feedback(P * C, H))
    if warn:
        what = f"linear {regime} closed loop" + (f" with the measurement delay of {delay} samples "
                                                  f"({delay * Ts:.6g} s, z^-{delay}; a shorter delay or a "
                                                  f"lower bandwidth restores the phase it costs)" if delay else "")
        warn_if_unstable(T, what=what, stacklevel=2)
    return T


def _sample_time(C: control.StateSpace) -> Optional[float]:
    if C.dt is None or C.dt == 0:
        return None
    if C.dt is True:
        raise ValueError("controller is discrete with an unspecified sample time (dt=True); give it dt > 0")
    return float(C.dt)


def is_stable(sys: control.LTI) -> bool:
    """True if every pole has negative real part (continuous) or modulus < 1 (discrete)."""
    p = control.poles(sys)
    if p.size == 0:
        return True
    if sys.isdtime(strict=True):
        return bool(np.max(np.abs(p)) < 1.0)
    return bool(np.max(p.real) < 0.0)


def warn_if_unstable(sys: control.LTI, *, what: str, stacklevel: int = 2) -> bool:
    """Warn (``UnstableLoopWarning``) with the poles of ``sys`` if it is not asymptotically stable."""
    if is_stable(sys):
        return False
    p = control.poles(sys)
    domain = "|z| < 1 (discrete)" if sys.isdtime(strict=True) else "Re(s) < 0"
    warnings.warn(
        f"{what} is not asymptotically stable: poles [{', '.join(f'{z.real:.7g}{z.imag:+.7g}j' for z in p)}] "
        f"(stable needs {domain}); the simulation is allowed but will not settle",
        UnstableLoopWarning,
        stacklevel=stacklevel + 1,
    )
    return True


def _plant_numbers(system: Oscillator, regime: str) -> tuple[float, float]:
    _check_system(system)
    _check_regime(regime)
    return system.mass, (system.friction.sigma if regime == "presliding" else 0.0)


def design_pd(
    system: Oscillator, *, wn: float, zeta: float = 0.7, regime: str = "presliding", N: float = 10.0
) -> PID:
    """PD gains that place the closed-loop poles of the linearised stage at ``wn``, ``zeta``.

    Characteristic polynomial ``m s^2 + kd s + (k + kp)`` (``k = sigma`` pre-sliding, 0
    sliding) matched to ``m (s^2 + 2 zeta wn s + wn^2)``: ``kp = m wn^2 - k``,
    ``kd = 2 zeta wn m``. The derivative filter ``tau = 1 / (N wn)`` adds a fast pole; the
    loop with the filter is checked and an :class:`UnstableLoopWarning` names its poles if
    it is unstable.

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage (mass [kg], friction model with ``sigma`` [N/m]).
    wn : float
        Natural frequency of the placed pole pair [rad/s], the target bandwidth.
        Pre-sliding needs ``wn >= sqrt(sigma / m)`` (``kp >= 0``).
    zeta : float, default 0.7
        Damping ratio of the pair [-], ``0 <= zeta <= 10``.
    regime : {"presliding", "sliding"}
        Linearisation designed on (see :func:`linear_plant`).
    N : float, default 10.0
        Derivative filter pole at ``N wn`` [-].
    """
    m, k = _plant_numbers(system, regime)
    wn = check_positive("wn", wn)
    zeta = check_interval("zeta", zeta, 0.0, 10.0)
    N = check_positive("N", N)
    kp = m * wn * wn - k
    if kp < 0.0:
        raise ValueError(
            f"wn must be >= sqrt(sigma/m) = {math.sqrt(k / m):.6g} rad/s for a pre-sliding PD design "
            f"(kp = m wn^2 - sigma >= 0), got wn={wn!r}"
            f"; wn is in rad/s (2 pi f for a bandwidth of f Hz). For a slower loop design on the sliding "
            f"linearisation 1/(m s^2), which has no lower limit: regime=\"sliding\""
        )
    ctrl = PID(kp=kp, kd=2.0 * zeta * wn * m, tau=1.0 / (N * wn))
    warn_if_unstable(closed_loop(system, ctrl, regime=regime, warn=False), what=f"PD design ({regime})", stacklevel=2)
    return ctrl


def design_pid(
    system: Oscillator,
    *,
    wn: float,
    zeta: float = 0.7,
    alpha: float = 1.0,
    regime: str = "presliding",
    N: float = 10.0,
    u_max: Optional[float] = None,
    t_track: Optional[float] = None,
    observer: Optional[LuGreObserver] = None,
) -> PID:
    """PID gains that place the closed-loop poles at ``wn``, ``zeta`` and a real pole ``-alpha wn``.

    ``m s^3 + kd s^2 + (k + kp) s + ki = m (s^2 + 2 zeta wn s + wn^2)(s + alpha wn)``:
    ``kd = m (2 zeta + alpha) wn``, ``kp = m (1 + 2 zeta alpha) wn^2 - k``,
    ``ki = m alpha wn^3`` (``k = sigma`` pre-sliding, 0 sliding). Derivative filter
    ``tau = 1 / (N wn)``; the filtered loop is checked and an :class:`UnstableLoopWarning`
    names its poles if it is unstable. ``u_max`` and ``t_track`` set the anti-windup of
    :class:`PID` (used by :func:`controllers.simulate_loop`).

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage.
    wn : float
        Natural frequency of the placed pair [rad/s] (target bandwidth).
    zeta : float, default 0.7
        Damping ratio of the pair [-], ``0 <= zeta <= 10``.
    alpha : float, default 1.0
        Real pole at ``-alpha wn`` [-], ``0 < alpha < inf``.
    regime, N, u_max, t_track
        As in :func:`design_pd` and :class:`PID`.
    observer : controllers.LuGreObserver, optional
        The LuGre observer the PID will run with: its gain condition
        (:meth:`controllers.LuGreObserver.gain_condition`) is checked on the designed PID. A
        designed PID has a derivative filter, with which the condition fails at high frequency,
        so this raises; the message names the alternatives (``docs/compensation.md#lugre-observer``).

    Raises
    ------
    ValueError
        If ``wn`` is too low for a pre-sliding design (the message names ``regime="sliding"``),
        or ``observer``'s gain condition fails for the designed PID (the message says what fails
        and names :class:`controllers.FrictionObserver` and :class:`controllers.Feedforward`).
    TypeError
        If ``observer`` is not a :class:`controllers.LuGreObserver`.
    """
    m, k = _plant_numbers(system, regime)
    wn = check_positive("wn", wn)
    zeta = check_interval("zeta", zeta, 0.0, 10.0)
    alpha = check_positive("alpha", alpha)
    N = check_positive("N", N)
    kp = m * (1.0 + 2.0 * zeta * alpha) * wn * wn - k
    if kp < 0.0:
        wmin = math.sqrt(k / (m * (1.0 + 2.0 * zeta * alpha)))
        raise ValueError(
            f"wn must be >= sqrt(sigma / (m (1 + 2 zeta alpha))) = {wmin:.6g} rad/s for a pre-sliding "
            f"PID design (kp >= 0), got wn={wn!r}"
            f"; wn is in rad/s (2 pi f for a bandwidth of f Hz). For a slower loop design on the sliding "
            f"linearisation 1/(m s^2), which has no lower limit: regime=\"sliding\""
        )
    ctrl = PID(
        kp=kp, ki=m * alpha * wn ** 3, kd=m * (2.0 * zeta + alpha) * wn, tau=1.0 / (N * wn),
        u_max=u_max, t_track=t_track,
    )
    warn_if_unstable(closed_loop(system, ctrl, regime=regime, warn=False), what=f"PID design ({regime})", stacklevel=2)
    if observer is not None:
        if not isinstance(observer, LuGreObserver):
            raise TypeError(f"observer must be a controllers.LuGreObserver (the one compensator whose stability "
                            f"depends on the PID), got {type(observer).__name__}")
        observer.require_gain_condition(ctrl, system.mass)
    return ctrl
