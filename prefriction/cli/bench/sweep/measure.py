"""Measurement of one sweep of ``prefriction bench --sweep``: cold and warm child processes and the scipy peer."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from prefriction.cli.bench.sweep.cases import REF_RTOL, TARGET_ERROR, SweepCase, exact_tables
from prefriction.cli.bench.sweep.child import ChildRun, run_child
from prefriction.cli.bench.sweep.peer import scipy_peer, scipy_sweep
from prefriction.cli.bench.timing import progress


@dataclass
class SweepRow:
    """One row of the table: a cold or warm sweep of one case and its scipy peer."""

    case: str
    run: str
    n_values: int
    compiles: int
    compile_lines: int
    end_to_end_s: float
    per_value_ms: float
    import_s: float
    setup_s: float
    sim_wall_s: float
    max_rel_error: float
    reference: str
    scipy_rtol: float
    scipy_s: float
    scipy_error: float
    ratio: float
    repeats: int
    jit: str


def _reference(case: SweepCase, work: Path) -> tuple[list[tuple[np.ndarray, ...]], Optional[str]]:
    """Reference reversals of every value, and the path of their JSON file for the children.

    Unforced: :func:`prefriction.exact_reversals` (the children compute it themselves, no file).
    Forced: scipy DOP853 at :data:`REF_RTOL`, written to ``work/ref_<key>.json``.
    """
    if not case.forced:
        return exact_tables(case), None
    progress(f"{case.label}: reference, scipy DOP853 at rtol {REF_RTOL:g} with restarts")
    refs = scipy_sweep(case, REF_RTOL, case.values)
    path = work / f"ref_{case.key}.json"
    path.write_text(json.dumps({k: [list(map(float, tab[i])) for tab in refs] for i, k in enumerate("txF")}))
    return refs, str(path)


def _child_row(case: SweepCase, run: str, children: list[ChildRun], reference: str) -> SweepRow:
    """A table row from one (cold) or several (warm) child runs; times are their minimum."""
    best = min(children, key=lambda c: c.report["sweep_s"])
    rep = best.report
    errors = [c.report["error"] for c in children]
    jit = ",".join(f"{k}:{v}" for k, v in sorted(rep["jit"].items()))
    return SweepRow(
        case=case.label, run=run, n_values=len(case.values),
        compiles=max(c.new_libraries for c in children),
        compile_lines=max(c.compile_lines for c in children),
        end_to_end_s=rep["sweep_s"], per_value_ms=rep["per_value_ms"],
        import_s=min(c.report["import_s"] for c in children), setup_s=rep["setup_s"],
        sim_wall_s=rep["sim_wall_s"],
        max_rel_error=math.inf if None in errors else max(errors), reference=reference,
        scipy_rtol=math.nan, scipy_s=math.nan, scipy_error=math.nan, ratio=math.nan,
        repeats=len(children), jit=jit,
    )


def measure_case(case: SweepCase, work: Path, warm_repeats: int, scipy_repeats: int) -> list[SweepRow]:
    """Cold and warm sweeps of one case in child processes, then its scipy peer here.

    Parameters
    ----------
    case : SweepCase
        The sweep.
    work : pathlib.Path
        Scratch directory: the case's cache directory ``cache_<key>`` and reference file go here.
    warm_repeats : int
        Warm child processes (their minimum time is reported).
    scipy_repeats : int
        Repeats of the timed scipy sweep.

    Returns
    -------
    list of SweepRow
        The cold and the warm row, with the figures of the scipy peer filled in.
    """
    refs, ref_path = _reference(case, work)
    reference = f"scipy DOP853 rtol {REF_RTOL:g}" if case.forced else "exact_reversals"
    cache = work / f"cache_{case.key}"
    cache.mkdir()
    spec = {"case": case.key, "n": len(case.values), "reference": ref_path}
    progress(f"{case.label}: cold sweep of {len(case.values)} values (new process, empty cache {cache})")
    cold = run_child(spec, cache)
    warm = []
    for k in range(warm_repeats):
        progress(f"{case.label}: warm sweep [{k + 1}/{warm_repeats}] (new process, cache from the cold run)")
        warm.append(run_child(spec, cache))
    rows = [_child_row(case, "cold", [cold], reference), _child_row(case, "warm", warm, reference)]
    target = max(TARGET_ERROR, cold.report["error"] if cold.report["error"] is not None else 0.0)
    progress(f"{case.label}: scipy DOP853 + restarts, matching error {target:.1e} on the first value")
    peer = scipy_peer(case, refs, target, scipy_repeats)
    ladder = ", ".join(f"{r:g}: {e:.1e}" for r, e in peer.ladder)
    progress(f"{case.label}: scipy ladder [{ladder}] -> rtol {peer.rtol:g}; sweep {peer.seconds:.2f} s")
    for row in rows:
        row.scipy_rtol, row.scipy_s, row.scipy_error = peer.rtol, peer.seconds, peer.error
        row.ratio = peer.seconds / row.end_to_end_s
    return rows
