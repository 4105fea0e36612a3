"""The stiff and extreme cases of ``prefriction bench`` (``docs/bench.md#stability``).

Each case of :func:`prefriction.cli.bench.cases.stability_cases` runs over the tolerance
ladder at 50 reversals and once for ``n_long`` reversals; it passes if its error stays within
10x the tolerance over the ladder, and the long run within ``10 rtol`` over its first 50
reversals and ``10 rtol n / 50`` over all of them (global errors grow linearly with the
number of cycles).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from prefriction.cli.bench.cases import DEFAULT_METHOD, N_REV, Case, exact, reversal_error, stability_cases
from prefriction.cli.bench.timing import progress
from prefriction.cli.bench.work_precision import Row, simulate_point
from prefriction.reversals import ReversalTable
from prefriction.simulation.simulate import simulate


@dataclass
class StabilityRow:
    """Result of one stiff or extreme case.

    Attributes
    ----------
    case : str
        Case name.
    worst_ratio, worst_tol : float
        Largest ``error / tol`` over the ladder (50 reversals) and the tolerance where it occurs.
    err_long_50, err_long_all : float
        Error of the long run over its first 50 and over all its reversals.
    n_long : int
        Reversals of the long run.
    tol_long : float
        ``rtol`` of the long run.
    seconds_long : float
        Integration time of the long run [s].
    energy_drift : float
        ``|E_p(last) / E_p,ref(last) - 1|`` of the long run (``inf`` if reversals are missing).
    passed : bool
        The verdict of ``docs/bench.md#stability``.
    """

    case: str
    worst_ratio: float
    worst_tol: float
    err_long_50: float
    err_long_all: float
    n_long: int
    tol_long: float
    seconds_long: float
    energy_drift: float
    passed: bool


def _long_run(case: Case, ref: ReversalTable, n_long: int, tol_long: float, worst: float, worst_tol: float) -> StabilityRow:
    """The long run of ``case`` and the verdict of the case."""
    r = simulate(case.system, case.v0, F0=case.F0, reversals=n_long, rtol=tol_long)
    tab = r.reversals
    e50 = reversal_error(case, tab.t, tab.x, tab.F, ref, N_REV)
    eall = reversal_error(case, tab.t, tab.x, tab.F, ref, n_long)
    drift = abs(tab.E_p[-1] / ref.E_p[n_long - 1] - 1.0) if len(tab) == n_long else math.inf
    ok = worst <= 10.0 and e50 <= 10.0 * tol_long and eall <= 10.0 * tol_long * n_long / N_REV
    return StabilityRow(case.name, worst, worst_tol, e50, eall, len(tab), tol_long, r.stats.wall_time, drift, ok)


def stability(ladder: list[float], n_long: int, tol_long: float,
              cases: Optional[list[Case]] = None) -> tuple[list[StabilityRow], list[Row]]:
    """Every stiff/extreme case over the ladder (50 reversals) and one run of ``n_long`` reversals.

    Parameters
    ----------
    ladder : list of float
        Tolerances.
    n_long : int
        Reversals of the long run.
    tol_long : float
        ``rtol`` of the long run.
    cases : list of Case, optional
        Default :func:`prefriction.cli.bench.cases.stability_cases`.

    Returns
    -------
    (list of StabilityRow, list of Row)
        One verdict row per case, and every ladder point (errors; one warm run each).
    """
    out, rows = [], []
    cases = stability_cases() if cases is None else cases
    for k, case in enumerate(cases, 1):
        progress(f"stability [{k}/{len(cases)}]: {case.name}")
        ref = exact(case, max(n_long, N_REV))
        worst, worst_tol = 0.0, ladder[0]
        for tol in ladder:
            row = simulate_point(case, tol, DEFAULT_METHOD, ref, 1, min_seconds=0.0)  # errors only
            rows.append(row)
            if row.error / tol > worst:
                worst, worst_tol = row.error / tol, tol
        out.append(_long_run(case, ref, n_long, tol_long, worst, worst_tol))
    return out, rows
