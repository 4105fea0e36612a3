"""PD positioning of a friction stage: 1 um and 10 nm steps, sampled at 10 kHz (controllers issue).

Stage values (SI): m = 1 kg, sigma = 1e6 N/m, Fc = 1 N, Dahl gamma = 1. They are round numbers
of the order found for small ball-screw / linear-guide stages in the pre-sliding literature: a
moving mass of about a kilogram, a Coulomb force of about a newton, and a pre-sliding range
Fc/sigma = 1 um (rolling contacts show micrometre-scale pre-sliding displacements, see e.g. the
survey of Armstrong-Helouvry, Dupont and Canudas de Wit, Automatica 30 (1994) 1083-1138).
They are chosen, not fitted to a particular machine.

Controller: PD placed on the pre-sliding linearisation 1/(m s^2 + sigma) at wn = 2 pi 300 Hz,
zeta = 0.7, derivative filter at 10 wn, discretised with ZOH at Ts = 1e-4 s (10 kHz). With Dahl
friction a PD loop stops where the friction balances the proportional force, so the residual
error obeys |e| <= Fc/kp. The 1 um step reaches the nonlinear part of the Dahl curve; the 10 nm
step stays near the pre-sliding spring, where the final value theorem on the linearisation
predicts e = r sigma / (sigma + kp).

Run: ``python examples/stage_pd.py [outdir]`` writes ``stage_pd.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import controllers
from controllers.plotting import plot_steps
import prefriction

M, SIGMA, FC = 1.0, 1e6, 1.0  # kg, N/m, N
TS = 1e-4  # s (10 kHz)
T_END = 0.02  # s
STEPS = ((1e-6, "1 um"), (1e-8, "10 nm"))  # m


def main(outdir: "str | Path" = ".") -> dict:
    """Simulate both steps, write ``outdir/stage_pd.png`` and return the plotted numbers (SI)."""
    system = prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)
    design = controllers.design_pd(system, wn=2 * np.pi * 300.0, zeta=0.7)
    Cd = design.c2d(TS)
    margins = controllers.margins(system, Cd)
    results = {f"step {label}": controllers.simulate_loop(system, Cd, r, T_END) for r, label in STEPS}
    path = plot_steps(
        results, Path(outdir) / "stage_pd.png",
        title=f"{design}, Ts = {TS:g} s; stage m = {M:g} kg, sigma = {SIGMA:g} N/m, Fc = {FC:g} N (Dahl)",
    )
    steps = {}
    for (r, label), res in zip(STEPS, results.values()):
        steps[label] = {
            "step": r, "t": res.t, "reference": res.reference, "x": res.x, "u": res.u, "F": res.F,
            "error": res.error, "residual_error": res.residual_error, "bound": res.error_bound,
            "settling_time": res.settling_time(), "reversals": len(res.reversals),
            "reversal_x": res.reversals.x, "reversal_F": res.reversals.F,
        }
    return {
        "path": path, "kp": design.kp, "kd": design.kd, "tau": design.tau, "Ts": TS,
        "m": M, "sigma": SIGMA, "Fc": FC, "phase_margin": margins.phase_margin,
        "gain_margin": margins.gain_margin, "steps": steps,
    }


if __name__ == "__main__":
    out = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    print(f"wrote {out['path']}; kp = {out['kp']:.4g} N/m, Fc/kp = {FC / out['kp']:.4g} m, "
          f"phase margin {out['phase_margin']:.3g} deg, gain margin {out['gain_margin']:.3g}")
    for label, s in out["steps"].items():
        print(f"  step {label}: residual error {s['residual_error']:.4g} m (|e| kp/Fc = "
              f"{abs(s['residual_error']) * out['kp'] / FC:.4f}), settling {s['settling_time'] * 1e3:.3g} ms, "
              f"{s['reversals']} reversals")
