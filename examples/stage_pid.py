"""PID positioning of a friction stage: 1 um and 10 nm steps, sampled at 10 kHz (controllers issue).

Stage values as in ``stage_pd.py`` (m = 1 kg, sigma = 1e6 N/m, Fc = 1 N, Dahl gamma = 1: round
numbers of the order of small ball-screw / linear-guide stages in the pre-sliding literature,
pre-sliding range Fc/sigma = 1 um; chosen, not fitted to a particular machine).

Controller: PID placed on the pre-sliding linearisation 1/(m s^2 + sigma): pole pair at
wn = 2 pi 150 Hz, zeta = 0.7, real pole at -wn, derivative filter at 10 wn, ZOH at Ts = 1e-4 s.
The integrator removes the residual error that a PD loop leaves (|e| <= Fc/kp): near rest the
Dahl friction acts as the pre-sliding spring, and the final value theorem on the linearised
loop gives e -> 0. The error panel draws Fc/kp of this PID's proportional gain for comparison.

Run: ``python examples/stage_pid.py [outdir]`` writes ``stage_pid.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import controllers
import prefriction
from controllers.plotting import plot_steps

M, SIGMA, FC = 1.0, 1e6, 1.0  # kg, N/m, N
TS = 1e-4  # s (10 kHz)
T_END = 0.04  # s
STEPS = ((1e-6, "1 um"), (1e-8, "10 nm"))  # m


def main(outdir: "str | Path" = ".") -> dict:
    """Simulate both steps, write ``outdir/stage_pid.png`` and return the plotted numbers (SI)."""
    system = prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)
    design = controllers.design_pid(system, wn=2 * np.pi * 150.0, zeta=0.7, alpha=1.0)
    Cd = design.c2d(TS)
    margins = controllers.margins(system, Cd)
    results = {f"step {label}": controllers.simulate_loop(system, Cd, r, T_END) for r, label in STEPS}
    path = plot_steps(
        results, Path(outdir) / "stage_pid.png", bound=FC / design.kp,
        title=f"{design}, Ts = {TS:g} s; stage m = {M:g} kg, sigma = {SIGMA:g} N/m, Fc = {FC:g} N (Dahl)",
    )
    steps = {}
    for (r, label), res in zip(STEPS, results.values()):
        steps[label] = {
            "step": r, "t": res.t, "reference": res.reference, "x": res.x, "u": res.u, "F": res.F,
            "error": res.error, "residual_error": res.residual_error, "pd_bound": FC / design.kp,
            "settling_time": res.settling_time(), "reversals": len(res.reversals),
            "reversal_x": res.reversals.x, "reversal_F": res.reversals.F,
        }
    return {
        "path": path, "kp": design.kp, "ki": design.ki, "kd": design.kd, "tau": design.tau, "Ts": TS,
        "m": M, "sigma": SIGMA, "Fc": FC, "phase_margin": margins.phase_margin,
        "gain_margin": margins.gain_margin, "steps": steps,
    }


if __name__ == "__main__":
    out = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    print(f"wrote {out['path']}; kp = {out['kp']:.4g} N/m, ki = {out['ki']:.4g} N/(m s), "
          f"phase margin {out['phase_margin']:.3g} deg, gain margin {out['gain_margin']:.3g}")
    for label, s in out["steps"].items():
        print(f"  step {label}: residual error {s['residual_error']:.4g} m (PD bound Fc/kp = {s['pd_bound']:.4g} m), "
              f"settling {s['settling_time'] * 1e3:.3g} ms, {s['reversals']} reversals")
