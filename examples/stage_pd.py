"""PD positioning of a friction stage: 1 um and 10 nm steps, sampled at 10 kHz (controllers issue).

Stage (SI, see :mod:`controllers.example_stage`): m = 1 kg, sigma = 1e6 N/m, Fc = 1 N, Dahl
gamma = 1, round numbers of the order of small ball-screw / linear-guide stages, pre-sliding
range Fc/sigma = 1 um; chosen, not fitted to a particular machine.

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

from prefriction import controllers
from prefriction.controllers.example_stage import report, stage, step_responses

T_END = 0.02  # s


def main(outdir: "str | Path" = ".") -> dict:
    """Simulate both steps, write ``outdir/stage_pd.png`` and return the plotted numbers (SI)."""
    design = controllers.design_pd(stage(), wn=2 * np.pi * 300.0, zeta=0.7)
    out = step_responses(design, T_END, Path(outdir) / "stage_pd.png")
    return {**out, "kp": design.kp, "kd": design.kd, "tau": design.tau}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, _ = script_args(sys.argv[1:], allow_quick=False)
    print(report(main(outdir)))
