"""PID positioning of a friction stage: 1 µm and 10 nm steps, sampled at 10 kHz (controllers issue).

Stage as in ``stage_pd.py`` (see :mod:`controllers.example_stage`: m = 1 kg, sigma = 1e6 N/m,
Fc = 1 N, Dahl gamma = 1; pre-sliding range Fc/sigma = 1 µm; chosen, not fitted to a machine).

Controller: PID placed on the pre-sliding linearisation 1/(m s^2 + sigma): pole pair at
wn = 2 pi 150 Hz, zeta = 0.7, real pole at -wn, derivative filter at 10 wn, ZOH at Ts = 1e-4 s.
The integrator removes the residual error that a PD loop leaves (|e| <= Fc/kp): near rest the
Dahl friction acts as the pre-sliding spring, and the final value theorem on the linearised
loop gives e -> 0 (``pd_bound`` of the result: Fc/kp of a PD with this kp, not drawn: a PID
has no such bound).

Run: ``python examples/stage_pid.py [outdir]`` writes ``stage_pid.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import controllers
from prefriction.controllers.example_stage import FC, report, stage, step_responses

T_END = 0.04  # s


def main(outdir: "str | Path" = ".") -> dict:
    """Simulate both steps, write ``outdir/stage_pid.png`` and return the plotted numbers (SI)."""
    design = controllers.design_pid(stage(), wn=2 * np.pi * 150.0, zeta=0.7, alpha=1.0)
    out = step_responses(design, T_END, Path(outdir) / "stage_pid.png")
    return {**out, "kp": design.kp, "ki": design.ki, "kd": design.kd, "tau": design.tau, "pd_bound": FC / design.kp}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, _ = script_args(sys.argv[1:], allow_quick=False)
    print(report(main(outdir)))
