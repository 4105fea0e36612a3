"""Run time and accuracy of :func:`controllers.simulate_loop` against python-control, same loop, same run.

``python -m controllers.benchmark`` prints two tables for the stage of the examples
(m = 1 kg, sigma = 1e6 N/m, Fc = 1 N, PD placed at 300 Hz, zeta = 0.7, 1 um step):

1. Sampled-data loop, 10 kHz, 1 s: wall time of ``simulate_loop`` (warm, integrator already
   compiled) against ``control.input_output_response`` on ``control.interconnect`` of
   :func:`controllers.plant_iosys` (ZOH-sampled plant) and the discrete controller, plus the
   largest position difference between the two at the sample instants.
2. Continuous loop: python-control's own continuous simulation of ``plant_iosys`` with the
   continuous PD (``solve_ivp`` across the reversal kinks) over a ladder of tolerances,
   against ``simulate_loop`` at ``rtol = 1e-11``: position error relative to the step, error of
   the residual position error, and wall time. This is the accuracy shortfall of
   ``plant_iosys`` documented in its notes.
"""

from __future__ import annotations

import argparse
import time
from typing import Any, Optional

import control
import numpy as np

from ._iosys import plant_iosys
from ._linear import design_pd
from ._loop import simulate_loop
from .example_stage import stage

STEP = 1e-6  # reference step [m]


def _loop(P: control.NonlinearIOSystem, C: control.StateSpace) -> control.InterconnectedSystem:
    """Interconnection ``e = r - x``, ``u = C e``, ``x = P u`` with input ``r`` and outputs ``x, u``."""
    sj = control.summing_junction(inputs=["r", "-x"], output="e", name="sum")
    C = control.ss(C, inputs="e", outputs="u", name="controller")
    return control.interconnect([P, C, sj], inplist=["r"], outlist=["x", "u"], name="loop")


def _best_time(fun, repeats: int) -> tuple[float, Any]:
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t0)
    return best, out


def sampled_timing(*, t_end: float = 1.0, Ts: float = 1e-4, repeats: int = 2) -> dict[str, float]:
    """Wall time of a sampled-data loop: ``simulate_loop`` against ``input_output_response``.

    Returns a dict with ``t_ours``, ``t_python_control`` [s] (minimum over ``repeats``),
    ``ratio`` (python-control / ours), ``n_samples`` and ``max_dx_rel`` (largest position
    difference at the sample instants, relative to the step).
    """
    system = stage()
    Cd = design_pd(system, wn=2 * np.pi * 300.0, zeta=0.7).c2d(Ts)
    simulate_loop(system, Cd, STEP, 10 * Ts)  # warm-up: compile or load the integrator
    t_ours, ours = _best_time(lambda: simulate_loop(system, Cd, STEP, t_end), repeats)
    loop = _loop(plant_iosys(system, Ts=Ts), Cd)
    t = ours.t
    t_pc, resp = _best_time(lambda: control.input_output_response(loop, t, np.full(t.shape, STEP)), repeats)
    x_pc = np.asarray(resp.outputs[0])
    return {
        "t_ours": t_ours,
        "t_python_control": t_pc,
        "ratio": t_pc / t_ours,
        "n_samples": float(len(t)),
        "max_dx_rel": float(np.max(np.abs(x_pc - ours.x)) / STEP),
    }


def continuous_accuracy(
    *, t_end: float = 0.05, rtols: tuple = (1e-3, 1e-6, 1e-9), methods: tuple = ("RK45", "LSODA")
) -> list[dict[str, Any]]:
    """python-control's continuous simulation of ``plant_iosys`` against ``simulate_loop``.

    Each row: ``method``, ``rtol`` (1e-3 means python-control's defaults, ``atol = 1e-6``;
    otherwise ``atol`` is ``rtol`` times the state scales ``Fc/sigma``, ``Fc/sqrt(m sigma)``,
    ``Fc``, ``Fc/sigma``), ``time`` [s], ``max_dx_rel`` (largest position error over the
    output times, relative to the step) and ``residual_rel`` (error of the final ``r - x``
    relative to the reference's final ``r - x``). The first row is ``simulate_loop`` itself
    at ``rtol = 1e-8`` against the ``rtol = 1e-11`` reference.
    """
    system = stage()
    C = design_pd(system, wn=2 * np.pi * 300.0, zeta=0.7).ss()
    t = np.linspace(0.0, t_end, 2001)
    simulate_loop(system, C, STEP, t_end, t_out=t, rtol=1e-8)  # warm-up (compile)
    ref = simulate_loop(system, C, STEP, t_end, t_out=t, rtol=1e-11)
    e_ref = ref.residual_error
    rows = []
    t8, ours8 = _best_time(lambda: simulate_loop(system, C, STEP, t_end, t_out=t, rtol=1e-8), 2)
    rows.append({"method": "simulate_loop", "rtol": 1e-8, "time": t8,
                 "max_dx_rel": float(np.max(np.abs(ours8.x - ref.x)) / STEP),
                 "residual_rel": abs(ours8.residual_error - e_ref) / abs(e_ref)})
    loop = _loop(plant_iosys(system), C)
    scale = np.array([1e-6, 1e-3, 1.0, 1e-6])  # x [m], v [m/s], F [N], filter state [m]
    for method in methods:
        for rtol in rtols:
            kw: dict[str, Any] = {"method": method}
            if rtol != 1e-3:
                kw.update(rtol=rtol, atol=rtol * scale)
            tt, resp = _best_time(
                lambda: control.input_output_response(loop, t, np.full(t.shape, STEP), solve_ivp_kwargs=kw), 1
            )
            x = np.asarray(resp.outputs[0])
            rows.append({"method": f"input_output_response {method}", "rtol": rtol, "time": tt,
                         "max_dx_rel": float(np.max(np.abs(x - ref.x)) / STEP),
                         "residual_rel": abs((STEP - x[-1]) - e_ref) / abs(e_ref)})
    return rows


def format_tables(timing: dict[str, float], rows: Optional[list[dict[str, Any]]]) -> str:
    """Readable text of both tables."""
    out = [
        f"Sampled-data PD loop, Ts = 1e-4 s, {int(timing['n_samples'])} samples (stage m=1 kg, sigma=1e6 N/m, Fc=1 N, 1 um step)",
        f"{'simulator':<44} {'wall time [s]':>14} {'relative':>9}",
        f"{'controllers.simulate_loop (warm)':<44} {timing['t_ours']:>14.3f} {1.0:>9.2f}",
        f"{'control.input_output_response (plant_iosys)':<44} {timing['t_python_control']:>14.3f} {timing['ratio']:>9.2f}",
        f"max |x_python-control - x_ours| / step at the samples: {timing['max_dx_rel']:.2e}",
    ]
    if rows:
        out += [
            "",
            "Continuous PD loop, 0.05 s: error against simulate_loop at rtol = 1e-11",
            f"{'simulator':<34} {'rtol':>7} {'time [s]':>9} {'max|dx|/step':>13} {'residual err':>13}",
        ]
        for r in rows:
            tag = "default" if r["rtol"] == 1e-3 and r["method"] != "simulate_loop" else f"{r['rtol']:.0e}"
            out.append(f"{r['method']:<34} {tag:>7} {r['time']:>9.3f} {r['max_dx_rel']:>13.2e} {r['residual_rel']:>13.2e}")
    return "\n".join(out)


def main(argv: Optional[list[str]] = None) -> int:
    """Command line: ``python -m controllers.benchmark [--t-end 1.0] [--repeats 2] [--no-accuracy]``."""
    ap = argparse.ArgumentParser(prog="python -m controllers.benchmark", description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated time of the sampled loop [s]")
    ap.add_argument("--repeats", type=int, default=2, help="repeats per timing (minimum is reported)")
    ap.add_argument("--no-accuracy", action="store_true", help="skip the continuous accuracy table")
    args = ap.parse_args(argv)
    timing = sampled_timing(t_end=args.t_end, repeats=args.repeats)
    rows = None if args.no_accuracy else continuous_accuracy()
    print(format_tables(timing, rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
