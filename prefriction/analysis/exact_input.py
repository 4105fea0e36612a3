"""What every exact reference (:func:`prefriction.exact_reversals`, the Maxwell-slip closed form)
checks of its initial state, and the limits it holds to."""

from __future__ import annotations

from typing import Any

from prefriction._validation import check_count, check_finite
from prefriction.models import Oscillator
from prefriction.units import Scales

__all__ = ["MAX_REVERSALS", "MAX_SPEED", "check_initial_state"]

MAX_REVERSALS = 10_000_000
"""Most reversals :func:`exact_reversals` computes in one call (about 0.5 GB and two minutes)."""
MAX_SPEED = 1e150
"""Largest ``|v0|`` in velocity units ``Fc / sqrt(m sigma)`` (initial energy ``< 1e300 Fc^2 / sigma``)."""


def check_initial_state(system: Oscillator, sc: Scales, v0: Any, x0: Any, F0: Any, n: Any,
                        maximum: int = MAX_REVERSALS) -> tuple[float, float, float, int]:
    """``v0`` [m/s], ``x0`` [m], ``F0`` [N] and ``n`` of an exact reference, checked.

    ``|v0|`` is at most ``MAX_SPEED`` velocity units ``Fc / sqrt(m sigma)`` (the initial kinetic
    energy in units ``Fc^2 / sigma`` then stays far below the double-precision range), ``|F0| <= Fc``,
    ``1 <= n <= maximum`` (default :data:`MAX_REVERSALS`); the oscillator must move (``v0 != 0``
    or ``F0 != 0``).
    """
    Fc = system.friction.Fc
    v_max = MAX_SPEED * sc.v
    v0 = check_finite("v0", v0)
    if abs(v0) > v_max:
        raise ValueError(
            f"v0 must be a finite real number in [-{v_max:.6g}, {v_max:.6g}] m/s ({MAX_SPEED:g} velocity units "
            f"Fc/sqrt(m sigma): larger initial energies overflow double precision), got {v0!r}"
        )
    x0 = check_finite("x0", x0)
    F0 = check_finite("F0", F0)
    if abs(F0) > Fc:
        raise ValueError(f"F0 must lie in [-Fc, Fc] = [{-Fc!r}, {Fc!r}] N, got {F0!r}")
    n = check_count("n", n, minimum=1, maximum=maximum, why="memory and run time")
    if v0 == 0.0 and F0 == 0.0:
        raise ValueError(
            "v0 = 0 and F0 = 0: the oscillator is at rest at its equilibrium and nothing moves "
            "(allowed: v0 != 0 or F0 != 0)"
        )
    if 0.5 * (v0 / sc.v) ** 2 + (F0 / Fc) ** 2 == 0.0:
        raise ValueError(
            f"v0 = {v0!r} m/s and F0 = {F0!r} N give an initial energy below the double-precision range "
            f"(allowed: |v0| > {1e-150 * sc.v!r} m/s or |F0| > {1e-150 * Fc!r} N)"
        )
    return v0, x0, F0, n
