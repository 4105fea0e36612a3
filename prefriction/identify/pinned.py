"""Estimates that end on a bound the data cannot pin them to: a fit that is not a success.

A converged solver can stop with a parameter on the edge of its allowed range, for instance a Dahl
``gamma`` at 0 or a stiffness at its lower end, because the data do not determine that parameter
and the descent ran down a flat valley to the wall. The estimate is then an artefact of the
bound, not of the data. This module tells such an end (:func:`unpinned`) from an estimate that
rests on a bound the truth may take: a structure boundary (Dahl's ``gamma = 1``, which
``structures="both"`` crosses), a parameter relation (``Fs >= Fc``), or a bound the data do pin
(a viscous coefficient at 0 with a small standard error: a stage without viscous friction).
"""

from __future__ import annotations

import numpy as np

__all__ = ["unpinned", "unpinned_message"]

_OPEN_SIDES = ("the declared range", "the user bound")
"""What a bound must be for an estimate on it to count as unpinned (not a structure boundary or a
relation to another parameter)."""


def unpinned(names: list[str], estimates: np.ndarray, stderr: np.ndarray, low: np.ndarray, high: np.ndarray,
             scale: np.ndarray, lower: dict[str, float], upper: dict[str, float], why_low: dict[str, str],
             why_high: dict[str, str], limit: float) -> tuple[tuple[str, str], ...]:
    """The estimates on a bound of the declared range or a user bound that the data do not pin down.

    An estimate is on a bound when it lies within ``1e-6`` of its scale (or of the bound) of it
    (as :func:`prefriction.identify.statistics.at_bounds` says). It is unpinned when its 95 %
    interval (before any cut) is wider than its whole allowed range, or when its standard error
    exceeds ``limit`` times ``max(|estimate|, |scale|)`` (the start value: an estimate at 0 has
    no relative error of its own).

    Parameters
    ----------
    names : list of str
        Free parameter names.
    estimates, stderr, low, high, scale : numpy.ndarray
        Estimates, standard errors, uncut 95 % interval ends and the start values (physical units).
    lower, upper : dict
        The allowed range of each name.
    why_low, why_high : dict
        What each end of the range is (``"the declared range"``, ``"the user bound"``, a structure
        boundary, another parameter).
    limit : float
        The relative standard error above which a parameter is not identifiable.

    Returns
    -------
    tuple of (str, str)
        ``(name, why)`` per unpinned estimate, ``why`` naming the bound and the spread.
    """
    out = []
    for i, n in enumerate(names):
        a, b = lower[n], upper[n]
        for side, bound, why in (("lower", a, why_low[n]), ("upper", b, why_high[n])):
            if why not in _OPEN_SIDES or not np.isfinite(bound):
                continue
            if abs(estimates[i] - bound) > 1e-6 * max(abs(scale[i]), abs(bound)):
                continue
            se = float(stderr[i])
            width = float(high[i] - low[i])
            wide = not width <= (b - a)
            loose = not se <= limit * max(abs(float(estimates[i])), abs(float(scale[i])))
            if wide or loose:
                spread = (f"its 95 % interval ({width:.3g} wide) is wider than its allowed range [{a:.6g}, {b:.6g}]"
                          if wide else f"its standard error {se:.3g} exceeds {100.0 * limit:.3g} % of "
                                       f"{max(abs(float(estimates[i])), abs(float(scale[i]))):.3g}")
                out.append((n, f"{n} = {float(estimates[i]):.6g} ends on its {side} bound {bound:.6g} ({why}) and "
                               f"{spread}"))
    return tuple(out)


def unpinned_message(found: tuple[tuple[str, str], ...], tried: str) -> str:
    """The message of a fit that ends with unpinned estimates (:func:`unpinned`): which
    parameters the data cannot pin down, what was tried, and what helps."""
    names = [n for n, _ in found]
    return (f"the solver stopped, but the data cannot pin down {', '.join(names)}: "
            + "; ".join(why for _, why in found)
            + f". The estimate is the bound's, not the data's: this is not a successful fit{tried}. What helps: fix "
              f"{'it' if len(names) == 1 else 'them'} at a value you know (fixed={names!r}), a longer record or one "
              f"that excites {'it' if len(names) == 1 else 'them'} more (larger moves, more reversals), or start "
              f"values closer to the truth (docs/identify.md#bounds)")
