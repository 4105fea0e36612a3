"""``prefriction bench``: error against run time of :func:`prefriction.simulate` and its peers.

One run measures, against :func:`prefriction.exact_reversals`:

- the work-precision of every ``simulate`` method over the tolerance ladder 1e-4 ... 1e-11, of
  scipy ``solve_ivp`` (RK45, DOP853, LSODA, Radau, BDF) with event restarts at ``v = 0``, of
  scipy without events on the ``|v|`` form ``F' = sigma (v - |v| F / Fc)`` (reversals located
  afterwards on the dense output) and of python-control ``input_output_response`` (``|v|`` form),
  on the headline case ``sigma / Fc = 1e4``, ``m = 1``, ``v0 = 1`` (SI units);
- the stiff and extreme cases (``sigma / Fc`` 1e-2 ... 1e10, mass 1e-6 ... 1e3, first-excursion
  energy ratio ``sigma m v0^2 / (2 Fc^2)`` 1e-20 ... 1e6, ``F0 = +-0.999999 Fc``, gamma in
  {0, 0.5, 1, 2, 5}) over the same ladder, plus one run of 1e4 reversals each.

Error = max relative error over the first 50 reversals of the times, the positions (relative to
``max(|x|, Fc / sigma)``) and the forces; a missing or extra reversal is an infinite error.
Run times are warm (compiled code loaded, minimum of repeats); the one-time JIT compile time is
reported separately. Peers integrate the same normalised equations
(``docs/mathematics.md#normalised-units``), with ``rtol = tol`` and ``atol = tol / 100``. The
error definition, the cases and the targets are described in ``docs/bench.md``.

``--models``, ``--sweep``, ``--elements``, ``--loops``, ``--compensation``, ``--identify``, ``--along`` and
``--export`` run other benchmarks instead: :mod:`prefriction.cli.bench.models`,
:mod:`prefriction.cli.bench.sweep`, :mod:`prefriction.cli.bench.elements`, :mod:`prefriction.cli.bench_loops`,
:mod:`prefriction.controllers.compensation_bench`, :mod:`prefriction.cli.bench.identify`,
:mod:`prefriction.along.bench` and :mod:`prefriction.export.bench`. The modules of this package: ``options`` (the command
line), ``cases`` (cases, error, reference), ``peers``, ``work_precision`` (headline rows),
``stiff`` (stiff and extreme cases), ``reference_rows`` (rows against independent references),
``restarts`` (scipy DOP853 with restarts), ``costs`` (target 3, exact analytics),
``plain_c`` and ``c_reference`` (the plain-C reference, target 4), ``report``
(tables, CSV, figure), ``verdict`` (targets), ``timing`` (shared timing helpers).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Optional

from prefriction.simulation.compiled import compiled_seconds
from prefriction.cli.bench import reference_rows
from prefriction.cli.bench.c_reference import c_available, c_comparison, c_section, c_target
from prefriction.cli.bench.cases import HEADLINE, LADDER, QUICK_LADDER, Case, reversal_error, stability_cases
from prefriction.cli.bench.costs import analytics_timing, linear_cost
from prefriction.cli.bench.models import main as _models_main
from prefriction.cli.bench.options import parse
from prefriction.cli.bench.report import (format_rows, format_stability, headline_section, plot, reference_section,
                                          stiff_section, write_csv)
from prefriction.cli.bench.stiff import StabilityRow, stability
from prefriction.cli.bench.verdict import targets
from prefriction.cli.bench.work_precision import Row, headline

__all__ = ["HEADLINE", "Case", "Row", "StabilityRow", "format_rows", "headline", "linear_cost", "main",
           "reversal_error", "stability", "stability_cases", "targets"]


def _loops(repeats: Optional[int]) -> int:
    """``--loops``: the table of :func:`prefriction.cli.bench_loops.run`; 0 if every target passes."""
    from prefriction.cli import bench_loops

    text = bench_loops.run() if repeats is None else bench_loops.run(repeats=repeats)
    print(text)
    verdicts = [line for line in text.splitlines() if line.rstrip().endswith(("PASS", "FAIL"))]
    return 0 if verdicts and all(line.rstrip().endswith("PASS") for line in verdicts) else 1


def main(argv: Optional[list[str]] = None) -> int:
    """Command line entry point of ``prefriction bench``; returns 0 if every target passes.

    Parameters
    ----------
    argv : list of str, optional
        Options (default ``sys.argv[1:]``); ``prefriction bench --help`` lists them.

    Returns
    -------
    int
        0 if every target line says PASS, else 1 (argparse errors exit with status 2).
    """
    args = parse(argv)
    if args.along:  # prefriction.along.bench (docs/along.md#speed)
        from prefriction.along import bench as along_bench

        return along_bench.main(args.repeats, args.quick)
    if args.loops:
        return _loops(args.repeats)
    if args.export:
        from prefriction.export import bench as export_bench

        text = export_bench.run(args.repeats or 5)
        print(text)
        return 0 if text.rstrip().endswith("PASS") else 1
    if args.emps is not None:
        from prefriction.cli.bench import emps

        return emps.main(args.emps)
    if args.native:
        from prefriction.cli.bench import native_rows

        return native_rows.main(args.quick)
    if args.identify:
        from prefriction.cli.bench import identify

        return identify.main(args.quick)
    if args.sweep:
        from prefriction.cli.bench import sweep

        return sweep.main(["--out", str(args.out)] + (["--quick"] if args.quick else []))
    if args.models:
        return _models_main(args.out, args.quick)
    if args.compensation:
        from prefriction.controllers.compensation_bench import main as compensation_main

        return compensation_main(["--out", str(args.out)])
    if args.elements:
        from prefriction.cli.bench import elements

        return elements.main(args.quick)
    out: Path = args.out
    ladder = QUICK_LADDER if args.quick else LADDER
    repeats = args.repeats or (1 if args.quick else 5)
    n_long = 500 if args.quick else 10_000
    t_start = time.perf_counter()

    rows = headline(ladder, repeats, peers=not args.stability, budget=0.5 if args.quick else 4.0)
    print(headline_section(rows))
    cmp = c_comparison(5 if args.quick else 40) if c_available() else None
    print(c_section(cmp) if cmp else "\nPlain-C reference: not measured (no C compiler)")
    stab, stab_rows = stability(ladder, n_long, 1e-8)
    print(stiff_section(stab, ladder, n_long))
    checks = reference_rows.run(args.quick)
    print(reference_section(checks))
    t50, tlong = linear_cost(1e-8, n_long, repeats)
    print("\nExact analytics (the reference itself):")
    for line in analytics_timing(repeats, n_amp=100_000 if args.quick else 1_000_000):
        print("  " + line)
    comp = compiled_seconds()  # every compile of this process, whatever section caused it
    print(f"\nOne-time JIT compile (gcc, cached on disk): {comp:.1f} s in this run "
          f"(0 when every integrator was already in the cache)")
    print()
    lines = targets(rows, stab, t50, tlong, n_long, ladder, checks) + ([c_target(cmp)] if cmp else [])
    for line in lines:
        print(line)
    write_csv(out / "bench.csv", rows + stab_rows)
    with (out / "stability.txt").open("w") as fh:
        fh.write(format_stability(stab) + "\n\n" + reference_rows.format_rows(checks) + "\n")
    plot(out / "work_precision.png", [r for r in rows if r.case == HEADLINE.name])
    print(f"\nwrote {out / 'bench.csv'}, {out / 'work_precision.png'}, {out / 'stability.txt'} "
          f"({time.perf_counter() - t_start:.0f} s)")
    return 0 if all("PASS" in line for line in lines if line.startswith("target")) else 1
