"""``prefriction bench --sweep``: parameter sweeps with one compiled integrator per structure.

One run measures three sweeps of :func:`prefriction.sweep`, each in fresh subprocesses:

- 20 values of gamma in [1, 3] (unforced Dahl oscillator, 50 reversals; structure gamma >= 1),
- 20 values of gamma in [0.3, 0.9] (unforced, 50 reversals; structure gamma < 1, saturating),
- 20 amplitudes in [0.2, 2] N of a :class:`prefriction.signals.Sine` input at 5 Hz (gamma = 1,
  from rest, 1 s),

all with ``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg (``v0 = 1`` m/s unforced) and the default
``rtol = 1e-8``. Each sweep runs once *cold*, in a new process whose compiled-code cache
(``$PREFRICTION_CACHE``) is a fresh empty directory, and then *warm*, in new processes (minimum of
3) that find the structure in that directory, compiled by the cold process. A compile is a new
``.so`` file in the cache directory; the ``prefriction: compiling`` lines on the child's stderr are
counted too. The child reports the end-to-end time of the :func:`prefriction.sweep` call
(compiling or loading included, ``import prefriction`` excluded and reported separately) and the
maximum relative error of the reversal times, positions and forces, against
:func:`prefriction.exact_reversals` (unforced) or a tight scipy reference (forced; DOP853 at
``rtol = 1e-12`` with restarts at every reversal).

The peer is scipy ``solve_ivp(method="DOP853")`` in normalised units with a restart at every
reversal (and at saturation for gamma < 1), at *matched error*: the loosest ``rtol`` in
1e-7 ... 1e-12 (``atol = rtol / 100``) whose error on the first value of the sweep is at most
``max(1e-8, simulator error)``; the whole sweep is then timed at that ``rtol`` in the parent
process. Ratios are scipy time over simulator time, both from the same run.

A second section sweeps 1,000 and 10,000 systems serially, on ``ProcessPoolExecutor(2)`` and on
a dask ``LocalCluster(2 x 1)`` (:mod:`prefriction.cli.bench.sweep.scaling`, target T3).

Modules: ``cases`` (the sweeps, the error), ``child`` (the child process), ``peer`` (the scipy
peer), ``measure`` (one sweep, cold and warm), ``report`` (table, CSV, targets), ``scaling``
(the executors' section); the
Dahl-with-restarts integrator is :mod:`prefriction.cli.bench.restarts`.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from typing import Optional

from prefriction.cli.bench.options import make_out_dir, out_dir
from prefriction.cli.bench.restarts import scipy_reversals
from prefriction.cli.bench.sweep.cases import (FC, MASS, N_REV, N_VALUES, QUICK_VALUES, REF_RTOL, SIGMA, T_END, V0_FREE,
                                               WARM_REPEATS, SweepCase, exact_tables, reversal_error, sweep_cases)
from prefriction.cli.bench.sweep.child import ChildRun, run_child, worker
from prefriction.cli.bench.sweep.measure import SweepRow, measure_case
from prefriction.cli.bench.sweep.peer import ScipyResult, matched_rtol, scipy_peer
from prefriction.cli.bench.sweep.report import format_table, match_notes, targets, write_csv
from prefriction.cli.bench.sweep.scaling import (QUICK_SIZES, SIZES, ScaleRow, format_scaling, measure_scaling,
                                                 scale_systems, scaling_targets)

__all__ = ["ChildRun", "ScaleRow", "ScipyResult", "SweepCase", "SweepRow", "exact_tables", "format_scaling",
           "format_table", "main", "match_notes", "matched_rtol", "measure_case", "measure_scaling", "reversal_error",
           "run_child", "scale_systems", "scaling_targets", "scipy_peer", "scipy_reversals", "sweep_cases", "targets",
           "worker", "write_csv"]


def main(argv: Optional[list[str]] = None) -> int:
    """Entry point of ``prefriction bench --sweep``; returns 0 if every target passes.

    Parameters
    ----------
    argv : list of str, optional
        Options (default ``sys.argv[1:]``): ``--out DIR`` (default ``bench_out``) and ``--quick``
        (4 values per sweep, one warm process and one scipy repeat; T1's speed is not checked).

    Returns
    -------
    int
        0 if the target lines all say PASS, else 1.
    """
    ap = argparse.ArgumentParser(
        prog="prefriction bench --sweep", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Parameter sweeps with one compiled integrator per structure: 20 values of gamma in\n"
                    "[1, 3], 20 in [0.3, 0.9] and 20 amplitudes of a 5 Hz sine input, each run once in a\n"
                    "new process with an empty compiled-code cache (cold) and then in new processes that\n"
                    "find it cached (warm), against scipy DOP853 with restarts at the same error.\n"
                    "Targets T1 (speed, one compile) and T2 (one compile per structure); docs/bench.md.")
    ap.add_argument("--out", default="bench_out", type=out_dir, metavar="DIR",
                    help="output directory for sweep.csv, created if missing (default: bench_out)")
    ap.add_argument("--quick", action="store_true",
                    help="4 values per sweep, one warm process, one scipy repeat (T1 speed not checked)")
    args = ap.parse_args(argv)
    out = make_out_dir(ap, args.out)
    cases = sweep_cases(QUICK_VALUES if args.quick else N_VALUES)
    warm_repeats = 1 if args.quick else WARM_REPEATS
    scipy_repeats = 1 if args.quick else WARM_REPEATS
    start = time.perf_counter()
    rows: list[SweepRow] = []
    with tempfile.TemporaryDirectory(prefix="prefriction-bench-sweep-") as tmp:
        for case in cases:
            rows.extend(measure_case(case, Path(tmp), warm_repeats, scipy_repeats))
    print(f"Sweeps of prefriction.simulation.sweep, sigma = {SIGMA:g} N/m, Fc = {FC:g} N, m = {MASS:g} kg, rtol 1e-8: "
          f"unforced {N_REV} reversals from v0 = {V0_FREE:g} m/s, forced {T_END:g} s from rest.\n"
          f"cold: new process, empty cache; warm: new process, cache from the cold run (min of "
          f"{warm_repeats}). end-to-end = the sweep call incl. compile/load, import excluded.\n"
          f"max error: reversal t, x, F vs exact_reversals (unforced) or scipy DOP853 rtol {REF_RTOL:g} "
          f"(forced). scipy: DOP853 + restarts at the loosest rtol matching max(1e-8, simulator error) "
          f"on the first value, whole sweep timed; ratio = scipy / end-to-end.\n")
    print(format_table(rows))
    for note in match_notes(rows):
        print(note)
    print()
    scale = measure_scaling(QUICK_SIZES, rounds=1) if args.quick else measure_scaling(SIZES)
    print()
    print(format_scaling(scale))
    print()
    lines = targets(rows, cases, args.quick) + scaling_targets(scale, args.quick)
    for line in lines:
        print(line)
    write_csv(out / "sweep.csv", rows)
    print(f"\nwrote {out / 'sweep.csv'} ({time.perf_counter() - start:.0f} s)")
    return 0 if all("PASS" in line for line in lines) else 1
