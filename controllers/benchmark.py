"""Benchmark of the compiled sampled-data loop against python-control, same loop, same run.

``python -m prefriction.controllers.benchmark`` (``prefriction bench --loops``) prints, for the PID loop of
``examples/stage_pid.py`` (stage m = 1 kg, sigma = 1e6 N/m, Fc = 1 N; PID placed at 150 Hz,
zeta = 0.7; 10 kHz ZOH; 1 um step; 1 s):

1. the warm time per sample of :func:`controllers.simulate_loop` and of
   ``control.input_output_response`` on ``control.interconnect`` of
   :func:`controllers.plant_iosys` (ZOH-sampled plant) and the discrete PID, and the error of
   both against :func:`controllers.zoh_reference.zoh_reference` (scipy DOP853 at rtol 1e-12
   with restarts at every zero velocity), relative to the step;
2. a 100-gain tuning sweep (pole placement from 110 to 200 Hz), end to end in a fresh process
   with an empty compile cache: wall time and the number of compiles (the lines
   ``prefriction: compiling`` on stderr);
3. the time per sample for loops of 0.1, 1 and 10 s with a sinusoidal reference (the plant
   moves in every period, so the three do the same work per sample);

and the targets as PASS/FAIL (``docs/controllers.md#benchmark``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Optional

import control
import numpy as np

from prefriction.signals import Sine

from ._iosys import plant_iosys
from ._linear import design_pid
from ._loop import simulate_loop
from .example_stage import TS, stage
from .zoh_reference import zoh_reference

STEP = 1e-6  # reference step [m]
RTOL = 1e-10  # tolerance of simulate_loop in the benchmark: error about 1e-10 of the step
TARGET_US, TARGET_SPEEDUP, TARGET_ERROR, TARGET_SPREAD = 5.0, 50.0, 1e-9, 1.5


def _pid() -> control.StateSpace:
    """The discrete PID of ``examples/stage_pid.py``."""
    return design_pid(stage(), wn=2 * np.pi * 150.0, zeta=0.7, alpha=1.0).c2d(TS)


def _loop(P: control.NonlinearIOSystem, C: control.StateSpace) -> control.InterconnectedSystem:
    """Interconnection ``e = r - x``, ``u = C e``, ``x = P u`` with input ``r`` and output ``x``."""
    sj = control.summing_junction(inputs=["r", "-x"], output="e", name="sum")
    C = control.ss(C, inputs="e", outputs="u", name="controller")
    return control.interconnect([P, C, sj], inplist=["r"], outlist=["x"], name="loop")


def _best_time(fun, repeats: int) -> tuple[float, Any]:
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t0)
    return best, out


def sampled_timing(*, t_end: float = 1.0, rtol: float = RTOL, repeats: int = 3) -> dict[str, Any]:
    """Time per sample and error of the PID loop: ``simulate_loop`` against python-control.

    Returns a dict: ``n_samples``, ``t_ours``, ``t_python_control`` [s] (warm; the minimum of
    ``repeats`` for ours, one run of python-control), ``us_ours``, ``us_python_control`` [us per
    sample], ``speedup``, ``err_ours``, ``err_python_control`` (largest position error at the
    samples against the scipy reference, relative to the step), ``stats`` (the loop's
    :class:`~prefriction.simulation.loops.LoopStats`) and ``t_reference`` [s].
    """
    system, Cd = stage(), _pid()
    simulate_loop(system, Cd, STEP, 10 * TS, rtol=rtol)  # warm-up: compile or load
    t_ours, ours = _best_time(lambda: simulate_loop(system, Cd, STEP, t_end, rtol=rtol), repeats)
    n = len(ours.t)
    r = np.full(n, STEP)
    t_pc, resp = _best_time(lambda: control.input_output_response(_loop(plant_iosys(system, Ts=TS), Cd), ours.t, r), 1)
    t_ref, x_ref = _best_time(lambda: zoh_reference(system, Cd, r, TS), 1)
    periods = max(n - 1, 1)
    return {
        "n_samples": n, "t_ours": t_ours, "t_python_control": t_pc, "t_reference": t_ref,
        "us_ours": 1e6 * t_ours / periods, "us_python_control": 1e6 * t_pc / periods, "speedup": t_pc / t_ours,
        "err_ours": float(np.max(np.abs(ours.x - x_ref)) / STEP),
        "err_python_control": float(np.max(np.abs(np.atleast_2d(resp.outputs)[0] - x_ref)) / STEP),
        "stats": ours.loop_stats,
    }


def _sweep_worker(n: int, t_end: float, rtol: float) -> None:
    """Run ``n`` PID designs (110 to 200 Hz) on the stage; print the wall time."""
    system = stage()
    start = time.perf_counter()
    for wn_hz in np.linspace(110.0, 200.0, n):
        simulate_loop(system, design_pid(system, wn=2 * np.pi * wn_hz, zeta=0.7).c2d(TS), STEP, t_end, rtol=rtol)
    print(f"{time.perf_counter() - start:.6f}")


def sweep_from_empty_cache(*, n: int = 100, t_end: float = 0.1, rtol: float = RTOL) -> dict[str, Any]:
    """A tuning sweep over ``n`` gains in a fresh process with an empty compile cache.

    Returns a dict: ``n``, ``t_end``, ``wall`` (end to end, process start included) and
    ``loop_time`` (the loops alone) [s], and ``compiles`` (lines ``prefriction: compiling``).
    """
    root = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory(prefix="prefriction-bench-") as cache:
        env = dict(os.environ, PREFRICTION_CACHE=cache, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""))
        code = f"from controllers.benchmark import _sweep_worker; _sweep_worker({n}, {t_end!r}, {rtol!r})"
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=3600)
        wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"the sweep process failed: {proc.stderr.strip()[-2000:]}")
    compiles = sum(line.startswith("prefriction: compiling") for line in proc.stderr.splitlines())
    return {"n": n, "t_end": t_end, "wall": wall, "loop_time": float(proc.stdout.split()[-1]), "compiles": compiles}


def length_scaling(*, lengths: tuple = (0.1, 1.0, 10.0), rtol: float = RTOL, repeats: int = 2) -> list[dict[str, float]]:
    """Warm time per sample of the PID loop following a 1 um, 20 Hz sine, for each length [s]:
    ``us`` the loop itself (``LoopStats.wall_time``), ``us_call`` the whole ``simulate_loop``
    call (with its fixed cost: the linear loop check, the output arrays)."""
    system, Cd = stage(), _pid()
    ref = Sine(amplitude=STEP, frequency=20.0)
    rows = []
    for T in lengths:
        simulate_loop(system, Cd, ref, 10 * TS, rtol=rtol)
        best, best_call = np.inf, np.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            res = simulate_loop(system, Cd, ref, T, rtol=rtol)
            best_call = min(best_call, time.perf_counter() - t0)
            best = min(best, res.loop_stats.wall_time)
        periods = max(len(res.t) - 1, 1)
        rows.append({"t_end": T, "n_samples": len(res.t), "us": 1e6 * best / periods, "us_call": 1e6 * best_call / periods})
    return rows


def _verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def format_tables(timing: dict[str, Any], sweep: Optional[dict[str, Any]], lengths: Optional[list]) -> str:
    """The benchmark's tables and its targets as PASS/FAIL."""
    n = timing["n_samples"]
    out = [
        f"Sampled PID loop of examples/stage_pid.py, Ts = {TS:g} s, {n} samples, 1 um step, rtol = {RTOL:g}",
        f"{'simulator':<44} {'wall [s]':>9} {'us/sample':>10} {'max|x - x_ref|/step':>20}",
        f"{'controllers.simulate_loop (compiled, warm)':<44} {timing['t_ours']:>9.4f} {timing['us_ours']:>10.3g} "
        f"{timing['err_ours']:>20.2e}",
        f"{'control.input_output_response (plant_iosys)':<44} {timing['t_python_control']:>9.3f} "
        f"{timing['us_python_control']:>10.4g} {timing['err_python_control']:>20.2e}",
        f"x_ref: scipy DOP853 at rtol 1e-12 with restarts at zero velocity ({timing['t_reference']:.3g} s)",
        f"loop: {timing['stats'].summary()}",
    ]
    targets = [
        (f"time per sample <= {TARGET_US:g} us (warm)", f"{timing['us_ours']:.3g} us", timing["us_ours"] <= TARGET_US),
        (f"speed-up over python-control >= {TARGET_SPEEDUP:g}x", f"{timing['speedup']:.0f}x",
         timing["speedup"] >= TARGET_SPEEDUP),
        (f"error <= {TARGET_ERROR:g} of the step", f"{timing['err_ours']:.2e}", timing["err_ours"] <= TARGET_ERROR),
    ]
    if sweep is not None:
        out += ["", f"Tuning sweep: {sweep['n']} PID gains, {sweep['t_end']:g} s loops, fresh process, empty cache: "
                    f"{sweep['wall']:.3g} s end to end ({sweep['loop_time']:.3g} s in the loops), "
                    f"{sweep['compiles']} compile(s)"]
        targets.append(("tuning sweep from an empty cache: one compile", f"{sweep['compiles']}", sweep["compiles"] == 1))
    if lengths:
        out += ["", "Loop length (1 um, 20 Hz sine reference), us per sample in the loop (whole call): " + ", ".join(
            f"{r['t_end']:g} s: {r['us']:.3g} ({r['us_call']:.3g})" for r in lengths)]
        us = [r["us"] for r in lengths]
        spread = max(us) / min(us)
        targets.append((f"time per sample over the lengths within {TARGET_SPREAD:g}x", f"{spread:.2f}x",
                        spread <= TARGET_SPREAD))
    out += ["", f"{'target':<52} {'measured':>10}  verdict"]
    out += [f"{name:<52} {val:>10}  {_verdict(ok)}" for name, val, ok in targets]
    return "\n".join(out)


def run(*, t_end: float = 1.0, repeats: int = 3, sweep: int = 100, lengths: tuple = (0.1, 1.0, 10.0)) -> str:
    """Run the benchmark (progress on stderr) and return its table."""
    print("bench --loops: timing the 1 s loop and python-control ...", file=sys.stderr, flush=True)
    timing = sampled_timing(t_end=t_end, repeats=repeats)
    sw = None
    if sweep:
        print(f"bench --loops: {sweep}-gain sweep from an empty cache ...", file=sys.stderr, flush=True)
        sw = sweep_from_empty_cache(n=sweep)
    rows = None
    if lengths:
        print("bench --loops: loop lengths " + ", ".join(f"{T:g} s" for T in lengths) + " ...", file=sys.stderr, flush=True)
        rows = length_scaling(lengths=lengths)
    return format_tables(timing, sw, rows)


def main(argv: Optional[list[str]] = None) -> int:
    """Command line: ``python -m prefriction.controllers.benchmark [--t-end 1] [--repeats 3] [--sweep 100] [--lengths 0.1 1 10]``.

    Returns 0 when every target passes, 1 when one fails.
    """
    ap = argparse.ArgumentParser(prog="python -m prefriction.controllers.benchmark", description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated time of the timed loop [s]")
    ap.add_argument("--repeats", type=int, default=3, help="repeats of the warm timing (the minimum is reported)")
    ap.add_argument("--sweep", type=int, default=100, help="gains in the tuning sweep (0: skip)")
    ap.add_argument("--lengths", type=float, nargs="*", default=[0.1, 1.0, 10.0], help="loop lengths [s] (none: skip)")
    args = ap.parse_args(argv)
    table = run(t_end=args.t_end, repeats=args.repeats, sweep=args.sweep, lengths=tuple(args.lengths))
    print(table)
    return 1 if " FAIL" in table else 0


if __name__ == "__main__":
    raise SystemExit(main())
