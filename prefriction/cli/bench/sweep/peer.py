"""The scipy peer of ``prefriction bench --sweep``: DOP853 with restarts at matched error.

The loosest ``rtol`` of :data:`~prefriction.cli.bench.sweep.cases.LADDER` whose error on the
first value of a sweep is at most the error to match; the whole sweep timed at that ``rtol``
(``docs/bench.md#sweep``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from prefriction.cli.bench.restarts import scipy_reversals
from prefriction.cli.bench.sweep.cases import FREQUENCY, LADDER, N_REV, SCIPY_BUDGET, T_END, SweepCase, reversal_error
from prefriction.cli.bench.timing import min_time
from prefriction.units import Scales


def _scipy_table(case: SweepCase, value: float, rtol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reversals ``(t, x, F)`` [SI] of one value of ``case`` by :func:`scipy_reversals`."""
    system = case.system(value)
    sc = Scales.of(system)
    if case.forced:
        w = 2.0 * math.pi * FREQUENCY * sc.t  # normalised angular frequency
        amp = value / sc.F
        R = scipy_reversals(1.0, case.v0 / sc.v, rtol, t_end=T_END / sc.t, u=lambda t: amp * math.sin(w * t))
    else:
        R = scipy_reversals(case.gamma_of(value), case.v0 / sc.v, rtol, n=N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def scipy_sweep(case: SweepCase, rtol: float, values: Sequence[float]) -> list[tuple[np.ndarray, ...]]:
    """Reversal tables of :func:`_scipy_table` for every value (warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [_scipy_table(case, v, rtol) for v in values]


def _max_error(tables: Sequence[tuple[np.ndarray, ...]], refs: Sequence[tuple[np.ndarray, ...]]) -> float:
    """Largest :func:`reversal_error` over paired tables."""
    return max(reversal_error(*tab, *ref) for tab, ref in zip(tables, refs))


@dataclass
class ScipyResult:
    """The matched-error scipy DOP853 sweep of one case."""

    rtol: float
    seconds: float
    error: float
    matched: bool
    ladder: list[tuple[float, float]] = field(default_factory=list)


def matched_rtol(case: SweepCase, refs: Sequence[tuple[np.ndarray, ...]], target: float) -> tuple[float, bool, list]:
    """Loosest rtol of :data:`LADDER` whose error on the first value is at most ``target``.

    Parameters
    ----------
    case : SweepCase
        The sweep.
    refs : sequence of (t, x, F)
        Reference reversals per value (only the first is used).
    target : float
        Error to match.

    Returns
    -------
    (float, bool, list)
        The rtol (the tightest of the ladder if none matches), whether it matches, and the
        ``(rtol, error)`` pairs tried, loosest first (the ladder stops at the first match).
    """
    tried = []
    for rtol in LADDER:
        err = _max_error(scipy_sweep(case, rtol, case.values[:1]), refs[:1])
        tried.append((rtol, err))
        if err <= target:
            return rtol, True, tried
    return LADDER[-1], False, tried


def scipy_peer(case: SweepCase, refs: Sequence[tuple[np.ndarray, ...]], target: float, repeats: int) -> ScipyResult:
    """Time the whole scipy DOP853 sweep at the matched rtol (minimum of ``repeats``).

    Parameters
    ----------
    case : SweepCase
        The sweep.
    refs : sequence of (t, x, F)
        Reference reversals per value.
    target : float
        Error to match (see :func:`matched_rtol`).
    repeats : int
        Most repeats of the timed sweep; fewer once they took :data:`SCIPY_BUDGET` seconds.

    Returns
    -------
    ScipyResult
        rtol, best time [s], max error over the sweep and the ladder tried.
    """
    rtol, matched, tried = matched_rtol(case, refs, target)
    tables, best = min_time(lambda: scipy_sweep(case, rtol, case.values), calls=max(1, repeats),
                            stop_spent=SCIPY_BUDGET)
    return ScipyResult(rtol, best, _max_error(tables, refs), matched, tried)
