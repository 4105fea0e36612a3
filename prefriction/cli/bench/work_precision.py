"""Work-precision rows of ``prefriction bench``: error against warm run time per solver and tolerance.

:func:`simulate_point` measures one tolerance of :func:`prefriction.simulate` (compile timed
separately, then warm runs); :func:`headline` measures the headline case for every simulate
method and, with ``peers``, for every peer of :mod:`prefriction.cli.bench.peers`
(``docs/bench.md#peers``, ``docs/bench.md#timing``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Callable

from prefriction.cli.bench.cases import HEADLINE, N_REV, Case, exact, reversal_error
from prefriction.cli.bench.peers import SCIPY_METHODS, control_abs_form, scipy_events, scipy_noevents
from prefriction.cli.bench.timing import min_time, progress
from prefriction.reversals import ReversalTable
from prefriction.simulation.simulate import METHODS, simulate


@dataclass
class Row:
    """One measured point of the work-precision table.

    Attributes
    ----------
    case, solver : str
        Case name and solver (row name of ``docs/bench.md#peers``).
    tol : float
        Tolerance (``nan`` on a note-only row).
    error : float
        Max relative error of the reversals (``inf`` for a failed or incomplete run).
    seconds : float
        Warm run time [s].
    compile_seconds : float
        One-time setup of a simulate run (build, compile or load) [s]; 0 for the peers.
    note : str
        JIT mode of a simulate row, or why a peer row failed or stopped.
    """

    case: str
    solver: str
    tol: float
    error: float
    seconds: float
    compile_seconds: float = 0.0
    note: str = ""


def simulate_point(case: Case, tol: float, method: str, ref: ReversalTable, repeats: int,
                   n: int = N_REV, min_seconds: float = 0.3) -> Row:
    """Compile (timed separately), then time warm runs of simulate.

    Millisecond runs: the minimum of the integration times (``stats.wall_time``) over at least
    ``repeats`` runs and ``min_seconds`` of them (at most 500 runs).

    Parameters
    ----------
    case : Case
        The case.
    tol : float
        ``rtol`` of simulate.
    method : str
        One of :data:`prefriction.simulation.simulate.METHODS`.
    ref : ReversalTable
        The exact reversals.
    repeats : int
        Least number of warm runs.
    n : int, optional
        Reversals per run, default 50.
    min_seconds : float, optional
        Least time spent in warm runs [s], default 0.3.

    Returns
    -------
    Row
        Error over the first ``min(n, 50)`` reversals, warm time and compile time.
    """
    first = simulate(case.system, case.v0, F0=case.F0, reversals=n, rtol=tol, method=method)

    def run() -> tuple:
        r = simulate(case.system, case.v0, F0=case.F0, reversals=n, rtol=tol, method=method)
        return r.reversals.t, r.reversals.x, r.reversals.F, r.stats.wall_time

    res, best = min_time(run, calls=repeats, most=500, fill=min_seconds, seconds=lambda r: r[3])
    err = reversal_error(case, res[0], res[1], res[2], ref, min(n, N_REV))
    return Row(case.name, f"simulate[{method}]", tol, err, best, first.stats.setup_time, first.stats.jit)


def _peers(case: Case) -> list[tuple[str, Callable[[float], tuple]]]:
    """The peers of ``case`` as (row name, function of the tolerance)."""
    solvers: list[tuple[str, Callable[[float], tuple]]] = []
    for m in SCIPY_METHODS:
        solvers.append((f"scipy {m} +events", lambda tol, m=m: scipy_events(case, tol, m)))
    for m in ("DOP853", "LSODA"):
        solvers.append((f"scipy {m} |v| form", lambda tol, m=m: scipy_noevents(case, tol, m)))
    solvers.append(("python-control |v| form", lambda tol: control_abs_form(case, tol)))
    return solvers


def peer_rows(case: Case, ref: ReversalTable, solvers: list[tuple[str, Callable[[float], tuple]]],
              ladder: list[float], repeats: int, budget: float) -> list[Row]:
    """Work-precision rows of the peers ``solvers`` on ``case`` over ``ladder``.

    A peer that raises is a measured outcome: its row has an infinite error and the reason in its
    note. Once one run of a peer takes longer than ``budget``, its tighter tolerances are skipped
    and a note row says so.

    Parameters
    ----------
    case : Case
        The case.
    ref : ReversalTable
        Its exact reversals (at least 50).
    solvers : list of (str, callable)
        Row name and a function of the tolerance returning the reversal times [s], positions [m]
        and forces [N].
    ladder : list of float
        Tolerances, loosest first.
    repeats : int
        Warm repeats per point (one if a call takes 0.5 s or more).
    budget : float
        Run time beyond which a peer's tighter tolerances are skipped [s].

    Returns
    -------
    list of Row
        The rows, peer by peer.
    """
    rows = []
    for name, fn in solvers:
        progress(f"{case.name.split()[0]}: {name}")  # the case's first word ("headline")
        for tol in ladder:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res, sec = min_time(lambda: fn(tol), calls=repeats, stop_best=0.5)
                err = reversal_error(case, res[0], res[1], res[2], ref)
                rows.append(Row(case.name, name, tol, err, sec))
            except Exception as exc:  # a peer failing is a measured outcome, not a bench failure
                rows.append(Row(case.name, name, tol, math.inf, math.nan, note=f"failed: {exc}"[:60]))
                sec = 0.0
            if sec > budget:  # tighter tolerances would only take longer
                rows.append(Row(case.name, name, math.nan, math.nan, math.nan,
                                note=f"tighter tolerances skipped (run took {sec:.1f} s > {budget:g} s)"))
                break
    return rows


def headline(ladder: list[float], repeats: int, peers: bool, budget: float) -> list[Row]:
    """Work-precision rows of the headline case for simulate and (if ``peers``) every peer.

    Parameters
    ----------
    ladder : list of float
        Tolerances, loosest first.
    repeats : int
        Warm repeats per point (simulate: four times as many, its runs take milliseconds).
    peers : bool
        Measure the peers too.
    budget : float
        Once a peer's run takes longer than this [s], its tighter tolerances are skipped.

    Returns
    -------
    list of Row
        simulate rows (every method, every tolerance), then the peer rows.
    """
    case = HEADLINE
    ref = exact(case, N_REV)
    progress(f"headline: simulate over {len(ladder)} tolerances")
    rows = [simulate_point(case, tol, m, ref, 4 * repeats) for m in METHODS for tol in ladder]
    if peers:
        rows += peer_rows(case, ref, _peers(case), ladder, repeats, budget)
    return rows
