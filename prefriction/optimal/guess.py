"""First guesses of a point-to-point move: the Coulomb bang-bang profile and the mode sequence
of its simulation through the stage's friction model."""

from __future__ import annotations

import math

import numpy as np

from prefriction.models import Oscillator
from prefriction.signals import ZeroOrderHold

__all__ = ["coulomb_times", "bang_bang_signal", "modes_from_simulation", "guess_forces"]

MAX_PHASES = 8
"""Most phases (velocity-sign changes + 1) a move may have."""
EXTRA_PHASE = 0.3
"""First guess of the duration of a phase other than the main one, in time units sqrt(m / sigma):
short enough that the unforced stage does not reverse on it (a wrong-way branch would drive the
force past Fc and the next reset to NaN)."""


def coulomb_times(distance: float, u_max: float, Fc: float, mass: float) -> tuple[float, float]:
    """Accelerating and braking times [s] of the minimum-time move against Coulomb friction ``Fc``.

    ``a1 = (u_max - Fc) / m`` for ``t1``, then ``a2 = (u_max + Fc) / m`` for ``t2 = a1 t1 / a2``,
    so that ``|distance| = a1 t1^2 (1 + a1 / a2) / 2`` [m] and the stage stops at ``t1 + t2``.
    """
    a1, a2 = (u_max - Fc) / mass, (u_max + Fc) / mass
    t1 = math.sqrt(2.0 * abs(distance) / (a1 * (1.0 + a1 / a2)))
    return t1, a1 * t1 / a2


def bang_bang_signal(distance: float, u_max: float, Fc: float, mass: float) -> tuple[ZeroOrderHold, float]:
    """The Coulomb bang-bang force [N] (0 after the stop) and its duration [s]."""
    t1, t2 = coulomb_times(distance, u_max, Fc, mass)
    s = math.copysign(1.0, distance)
    return ZeroOrderHold([0.0, t1, t1 + t2], [s * u_max, -s * u_max, 0.0], name="u", unit="N"), t1 + t2


def modes_from_simulation(system: Oscillator, distance: float, u_max: float) -> tuple[float, ...]:
    """Velocity signs of the phases: the branches of the Coulomb bang-bang force simulated with the
    stage's friction (:func:`prefriction.simulate`) up to its stop, then, if the last branch moves
    towards the target, one more phase back (the friction force unloads to zero on it)."""
    from prefriction.simulation.simulate import simulate

    u, t_end = bang_bang_signal(distance, u_max, system.friction.Fc, system.mass)
    run = simulate(Oscillator(system.friction, mass=system.mass, u=u), 0.0, t_end=t_end, rtol=1e-8)
    s = math.copysign(1.0, distance)
    modes = [s * (-1.0) ** k for k in range(len(run.reversals) + 1)]
    if modes[-1] == s:
        modes.append(-s)
    if len(modes) > MAX_PHASES:
        raise ValueError(
            f"the Coulomb bang-bang force reverses the stage {len(modes) - 1} times on the way; at most "
            f"{MAX_PHASES} phases are allowed: pass modes=(1.0, -1.0) (or the signs you want) explicitly"
        )
    return tuple(modes)


def guess_forces(modes: tuple, distance: float, u_max: float, Fc: float, mass: float, intervals: int,
                 t_total: float | None, t_unit: float) -> tuple[np.ndarray, list]:
    """Normalised phase durations and forces of the first guess.

    The first phase towards the target carries the bang-bang profile (``t_total`` given: the
    least-effort force of the frictionless stage plus the Coulomb force); the other phases last :data:`EXTRA_PHASE` time units
    ``sqrt(m / sigma)`` with no force.
    """
    s = math.copysign(1.0, distance)
    main = modes.index(s) if s in modes else 0
    T = np.full(len(modes), EXTRA_PHASE)
    U = [np.zeros(intervals) for _ in modes]
    if t_total is None:  # the Coulomb bang-bang profile
        t1, t2 = coulomb_times(distance, u_max, Fc, mass)
        T[main] = (t1 + t2) / t_unit
        mid = (np.arange(intervals) + 0.5) / intervals * (t1 + t2)
        U[main] = np.where(mid < t1, s * u_max, -s * u_max) / Fc
    else:  # least effort without friction, a = 6 d (1 - 2 t/T) / T^2, plus the Coulomb force
        Tm = max(t_total - (len(modes) - 1) * EXTRA_PHASE * t_unit, 0.5 * t_total)
        T[main] = Tm / t_unit
        mid = (np.arange(intervals) + 0.5) / intervals
        U[main] = np.clip(mass * 6.0 * distance * (1.0 - 2.0 * mid) / Tm ** 2 + s * Fc, -u_max, u_max) / Fc
    if t_total is not None:
        T *= t_total / t_unit / T.sum()
    return T, U
