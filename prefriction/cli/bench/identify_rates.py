"""``prefriction bench --identify``: success rate against the start distance, interval coverage, and
the cost of force-displacement fits against the record length.

- Success rate: :func:`prefriction.identify._success.success_table` on the 24 stages of
  :data:`prefriction.identify._success.GRID` (every free parameter started log-uniformly within
  a factor ``d`` of the truth, ``d`` in :data:`DISTANCES`; a success when every estimate lands
  within 5 %), one fit per distance on each record, a record per stage and seed
  (:data:`SEEDS`), each stage and seed in a fresh process so that its peak resident set size
  (``ru_maxrss``) is its own; per model against the start distance, with the wall and CPU time
  and the memory, and the coverage of the fits' 95 % intervals per model.
- A free Dahl ``gamma``: :func:`gamma_lines` (the 2.5 kg closed-loop ``gamma = 2`` stage of
  :data:`prefriction.identify._success.STAGES`, starts within a factor 2).
- Models with in-branch events (Maxwell-slip, GMS): :mod:`prefriction.cli.bench.identify_events`.
- Coverage: :func:`prefriction.identify._coverage.coverage_table` (how often the 95 % intervals
  hold the truth on seeded records generated from the equations).
- Cost: a Maxwell-slip(3) :class:`ForceDisplacement` fit of the tribometer record (12-60 s) at
  three sample counts: wall and CPU time of the fit, CPU time of one residual and Jacobian
  evaluation, and its log-log slope against the samples (target: at most 1.3, linear).
"""

from __future__ import annotations

import dataclasses
import json
import math
import resource
import subprocess
import sys
import time
import warnings
from typing import Any

__all__ = ["coverage_lines", "cost_lines", "gamma_lines", "main_rates", "success_lines"]

COVERAGE_TARGET = 0.90
"""Least fraction of the 95 % intervals that must hold the truth."""
SLOPE_TARGET = 1.3
"""Largest log-log slope of the force-displacement fit time against the samples."""


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def _success_stage(index: int, fits: int, samples: int, distances: tuple[float, ...], seed: int = 0,
                   stages: str = "GRID") -> list[dict]:
    """One stage of :data:`prefriction.identify._success.GRID` (or of ``STAGES``) and one seed, in this
    process; rows with the process's peak RSS."""
    from prefriction.identify import _success

    stage = getattr(_success, stages)[index]
    rows = _success.success_table((stage,), distances, fits=fits, samples=samples, seed=seed,
                                  progress=lambda line: print(line, file=sys.stderr, flush=True))
    return [dataclasses.asdict(r) for r in rows]


QUICK_STAGES = (3, 7, 17, 20)
"""Stages of the grid in ``--quick``: one per model (Dahl, LuGre, Dahl+b+offset, LuGre+b+offset)."""
DISTANCES = (1.25, 1.5, 2.0)
"""Start distances of the full run: starts log-uniform within ``[1/d, d]`` times the truth."""
SEEDS = (0, 1)
"""Seeds of the full run: each gives every stage a new record and new starts."""


def success_lines(quick: bool) -> tuple[list[str], bool]:
    """The success-rate tables of the stage grid (one fresh process per stage): per stage, pooled
    per model against the start distance, and the coverage of the fits' intervals; ``ok`` when
    at least 90 % of all fits succeed at the largest distance."""
    from prefriction.identify import _success

    fits, samples = 1, (500 if quick else 1000)
    distances, seeds = ((1.5, 2.0), (0,)) if quick else (DISTANCES, SEEDS)
    stages = QUICK_STAGES if quick else range(len(_success.GRID))
    rows, failed = _stage_rows("GRID", stages, seeds, fits, samples, distances)
    lines = [f"Motion fits from starts log-uniform within a factor d of the truth (every free parameter, mass "
             f"and offset included), {fits} seeded start per distance on each of {len(seeds)} records per stage, "
             f"success = every estimate within 5 %", _success.table_text(rows), "",
             "Per model and start distance (given start alone: without the second start from the data; wall and "
             "CPU time of one fit; peak RSS of the stage's process)", _success.distance_text(rows), "",
             "Coverage of the 95 % intervals of these fits", _success.coverage_text(rows)]
    lines += [f"stage FAILED: {f}" for f in failed]
    top = [r for r in rows if r.distance == max(distances)]
    ok = not failed and sum(r.successes for r in top) >= 0.9 * sum(r.fits for r in top)
    lines.append(f"target >= 90 % of the fits within 5 % from a factor {max(distances):g}: {'PASS' if ok else 'FAIL'}")
    return lines, ok


def _stage_rows(stages: str, indices: Any, seeds: tuple[int, ...], fits: int, samples: int,
                distances: tuple[float, ...]) -> tuple[list, list[str]]:
    """The success rows of ``indices`` into ``_success.GRID`` or ``_success.STAGES`` (``stages``), one
    fresh process per stage and seed, and a line per process that failed."""
    from prefriction.identify import _success

    rows, failed = [], []
    for seed, i in ((s, i) for s in seeds for i in indices):
        stage = getattr(_success, stages)[i]
        print(f"bench --identify: success rate of {stage.name}, seed {seed} ...", file=sys.stderr, flush=True)
        out = subprocess.run([sys.executable, "-m", "prefriction.cli.bench.identify_rates", "success", str(i),
                              str(fits), str(samples), ",".join(map(str, distances)), str(seed), stages],
                             stdout=subprocess.PIPE, text=True, check=False)  # its progress on our stderr
        if out.returncode != 0:
            failed.append(f"{stage.name}, seed {seed}: exit code {out.returncode}, see the messages above")
            continue
        rows += [_success.row_from_dict(r) for r in json.loads(out.stdout.strip().splitlines()[-1])]
    return rows, failed


GAMMA_STAGE = 2
"""The stage of :data:`prefriction.identify._success.STAGES` with a free Dahl ``gamma`` (2.5 kg, 2 kHz,
10 nm, closed loop, ``gamma = 2`` + viscous + offset)."""
GAMMA_SEEDS = (0, 1, 2)
"""Seeds of its full run (``--quick``: seed 0)."""


def gamma_lines(quick: bool) -> tuple[list[str], bool]:
    """Success of the stage with a free Dahl ``gamma`` (:data:`GAMMA_STAGE`, 1,000 samples, one start per
    seed within a factor 2; the start from the force balance, ``identify/balance_start.py``); ``ok`` when
    at least 90 % of the fits land within 5 %."""
    from prefriction.identify import _success

    seeds = (0,) if quick else GAMMA_SEEDS
    rows, failed = _stage_rows("STAGES", (GAMMA_STAGE,), seeds, 1, 1000, (2.0,))
    ok = not failed and sum(r.successes for r in rows) >= 0.9 * sum(r.fits for r in rows)
    records = f"{len(seeds)} record{'s' if len(seeds) > 1 else ''}"
    lines = [f"Dahl with a free gamma = 2 (stage {_success.STAGES[GAMMA_STAGE].name}), 1,000 samples, one start "
             f"within a factor 2 on each of {records}", _success.table_text(rows),
             "Coverage of their 95 % intervals", _success.coverage_text(rows)]
    lines += [f"stage FAILED: {f}" for f in failed]
    lines.append(f"target >= 90 % of the fits within 5 %: {'PASS' if ok else 'FAIL'}")
    return lines, ok


def coverage_lines(quick: bool) -> tuple[list[str], bool]:
    """The coverage table; ``ok`` when every case with declared noise reaches :data:`COVERAGE_TARGET`
    pooled over its parameters."""
    from prefriction.identify._coverage import coverage_table, table_text

    runs = 8 if quick else 40
    rows = coverage_table(runs=runs, progress=lambda line: print(line, file=sys.stderr, flush=True))
    judged = [r for r in rows if not r.case.endswith("undeclared")]
    ok = all(r.pooled >= COVERAGE_TARGET for r in judged)
    lines = [f"Coverage of the 95 % intervals, {runs} seeded records per case (mean and sd of z = (estimate - "
             f"truth) / stderr in brackets: 0 and 1 are honest, an sd below 1 conservative)", table_text(rows),
             f"target every case with its noise declared >= {COVERAGE_TARGET:.0%} of the intervals hold the "
             f"truth: {'PASS' if ok else 'FAIL'} (the undeclared row shows the bias it avoids)"]
    return lines, ok


def _cost_one(step: int) -> dict:
    import prefriction as pf
    from prefriction import identify
    from prefriction.data import tribometer

    data = tribometer().window(12.0, 60.0, step=step)
    start = pf.MaxwellSlip([3e4, 1e4, 3e3], [0.8, 0.8, 0.8])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        identify.fit(start, tribometer().window(12.0, 13.0, step=step), offset=True)  # warm: imports, first build
        t0, c0 = time.perf_counter(), time.process_time()
        res = identify.fit(start, data, offset=True)
        elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
    return {"n": len(data), "fit_s": elapsed, "cpu_s": cpu, "eval_s": _evaluation_cpu(start, data), "rss_mb": _rss_mb(),
            "rms": res.rms}


def _evaluation_cpu(model, data) -> float:
    """CPU seconds of one residual and Jacobian evaluation of the fit's problem (the cost per
    solver iteration; the fit's own cost also carries its data-dependent iteration count)."""
    import numpy as np

    from prefriction.identify.parameters import ParameterSpace
    from prefriction.identify.prescribed import PrescribedProblem, _inputs, _Series

    space = ParameterSpace(model, None, None, None, offset=float(np.std(data.F)))
    problem = PrescribedProblem.get(model, space, len(data), 1)
    args = _inputs(space, _Series.of(data), data)
    w = np.append(space.theta0, 0.0)
    c0 = time.process_time()
    for _ in range(5):
        problem.residual(w, *args)
        problem.jacobian(w, *args)
    return (time.process_time() - c0) / 5.0


def cost_lines(quick: bool) -> tuple[list[str], bool]:
    """Maxwell-slip(3) force-displacement fits of the tribometer record against its length, each
    in a fresh process; ``ok`` when the log-log slope is at most :data:`SLOPE_TARGET`."""
    rows = []
    for step in (8, 4, 2) if quick else (4, 2, 1):
        print(f"bench --identify: Maxwell-slip(3) force-displacement fit, step {step} ...", file=sys.stderr,
              flush=True)
        out = subprocess.run([sys.executable, "-m", "prefriction.cli.bench.identify_rates", "cost", str(step)],
                             capture_output=True, text=True, check=False)
        if out.returncode != 0:
            return [f"force-displacement cost: the fit failed:\n{out.stderr[-1500:]}"], False
        rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
    lines = ["Maxwell-slip(3) + offset ForceDisplacement fit of the tribometer record (12-60 s), each in a fresh "
             "process (the problem's build included); CPU = the process's CPU time (all its threads), the slope's "
             "measure: wall time on a loaded machine is mostly waiting",
             f"{'samples':>8} {'wall [s]':>9} {'CPU [s]':>8} {'CPU us/sample':>14} {'eval CPU [ms]':>14} "
             f"{'peak RSS [MB]':>14}"]
    for r in rows:
        lines.append(f"{r['n']:>8} {r['fit_s']:>9.2f} {r['cpu_s']:>8.2f} {1e6 * r['cpu_s'] / r['n']:>14.0f} "
                     f"{1e3 * r['eval_s']:>14.1f} {r['rss_mb']:>14.0f}")
    ratio = math.log(rows[-1]["n"] / rows[0]["n"])
    slope = math.log(rows[-1]["cpu_s"] / rows[0]["cpu_s"]) / ratio
    slope_eval = math.log(rows[-1]["eval_s"] / rows[0]["eval_s"]) / ratio
    ok = slope_eval <= SLOPE_TARGET
    lines.append(f"fit CPU time against the samples: log-log slope {slope:.2f} (it also carries the iteration count, "
                 f"which depends on the record)")
    lines.append(f"target one residual + Jacobian evaluation at most linear in the samples (log-log slope <= "
                 f"{SLOPE_TARGET}): slope {slope_eval:.2f} {'PASS' if ok else 'FAIL'}")
    return lines, ok


def main_rates(quick: bool) -> bool:
    """Print the five tables (the event models' from :mod:`prefriction.cli.bench.identify_events`);
    True if every target passes."""
    from prefriction.cli.bench.identify_events import event_lines

    ok = True
    for part in (success_lines, gamma_lines, event_lines, coverage_lines, cost_lines):
        lines, good = part(quick)
        print("\n".join(lines) + "\n", flush=True)
        ok &= good
    return ok


if __name__ == "__main__":
    if sys.argv[1] == "success":
        dist = tuple(float(d) for d in sys.argv[5].split(","))
        seed_arg = int(sys.argv[6]) if len(sys.argv) > 6 else 0
        which = sys.argv[7] if len(sys.argv) > 7 else "GRID"
        print(json.dumps(_success_stage(int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), dist, seed_arg, which)))
    elif sys.argv[1] == "cost":
        print(json.dumps(_cost_one(int(sys.argv[2]))))
