"""PID with a force limit: back-calculation anti-windup on the friction stage (controllers issue).

Stage as in ``stage_pd.py`` (see :mod:`controllers.example_stage`: m = 1 kg, sigma = 1e6 N/m,
Fc = 1 N, Dahl gamma = 1; pre-sliding range Fc/sigma = 1 um).
PID as in ``stage_pid.py`` (pre-sliding pole placement at 150 Hz, zeta = 0.7, 10 kHz ZOH), now
with an actuator limit u_max = 3 N and a 5 um step, five pre-sliding ranges: the stage slides
and the force saturates. With back-calculation (tracking time sqrt(Ti Td), Astrom and
Hagglund) the integrator stops winding up while the force is limited; without it
(tracking time 1e6 s, i.e. plain clipping) the wound-up integrator overshoots further.

Run: ``python examples/stage_antiwindup.py [outdir]`` writes ``stage_antiwindup.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import controllers
from prefriction.controllers.example_stage import TS, stage, title
from prefriction.controllers.plotting import plot_steps

T_END = 0.03  # s
STEP = 5e-6  # m
U_MAX = 3.0  # N


def main(outdir: "str | Path" = ".") -> dict:
    """Simulate the saturated loop with and without anti-windup; write the PNG, return the numbers."""
    system = stage()
    pid = controllers.design_pid(system, wn=2 * np.pi * 150.0, zeta=0.7, u_max=U_MAX)
    clip_only = controllers.PID(kp=pid.kp, ki=pid.ki, kd=pid.kd, tau=pid.tau, u_max=U_MAX, t_track=1e6)
    results = {
        f"anti-windup ($T_t$ = {pid.tracking_time * 1e3:.2g} ms)": controllers.simulate_loop(system, pid, STEP, T_END, Ts=TS),
        "clipping only": controllers.simulate_loop(system, clip_only, STEP, T_END, Ts=TS),
    }
    path = plot_steps(
        results, Path(outdir) / "stage_antiwindup.png",
        title=title(pid, ", 5 µm step"),
    )
    cases = {}
    for label, res in zip(("anti-windup", "clipping only"), results.values()):
        cases[label] = {
            "t": res.t, "x": res.x, "u": res.u, "F": res.F, "error": res.error,
            "overshoot": float(np.max(res.x) - STEP), "peak_force": float(np.max(np.abs(res.u))),
            "residual_error": res.residual_error, "settling_time": res.settling_time,
            "reversals": len(res.reversals),
        }
    return {"path": path, "kp": pid.kp, "ki": pid.ki, "kd": pid.kd, "u_max": U_MAX, "step": STEP,
            "tracking_time": pid.tracking_time, "cases": cases}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, _ = script_args(sys.argv[1:], allow_quick=False)
    out = main(outdir)
    print(f"wrote {out['path']}")
    for label, c in out["cases"].items():
        print(f"  {label:<14} overshoot {c['overshoot'] * 1e9:8.1f} nm, peak |u| {c['peak_force']:.3g} N, "
              f"settling {c['settling_time'] * 1e3:.3g} ms, residual {c['residual_error']:.3g} m")
