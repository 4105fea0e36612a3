"""Friction compensation in a positioning loop: PID alone against PID with each compensator.

Stage of ``stage_pid.py`` (m = 1 kg, Dahl sigma = 1e6 N/m, Fc = 1 N, gamma = 1), the same PID
(poles at 150 Hz on the pre-sliding linearisation), sampled at 10 kHz, tracking a 5 um, 1 Hz
sine from rest through its velocity reversals. The compensators use the plant's model
(nominal) or one with +20 % stiffness and -20 % Coulomb force (``mismatch``); the disturbance
observer needs no friction model. Prints the RMS error and the reversal spike (max |e| within
100 ms after the reference reversal at t = 1 s) of each loop, and plots the error there.

Run: ``python examples/compensation.py [outdir] [--quick]`` writes ``compensation.png``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import prefriction as pf
from prefriction import controllers
from prefriction.signals import Sine

TS = 1e-4  # s
SINE = Sine(5e-6, 1.0, phase=-math.pi / 2, offset=5e-6)  # m, Hz: from rest at 0, reversals at 0.5 s, 1 s, ...


def compensators(model: pf.Dahl) -> dict:
    """PID alone and the four compensators with the model ``model``."""
    lugre = pf.LuGre(sigma0=model.sigma, sigma1=0.0, sigma2=0.0, Fc=model.Fc, Fs=model.Fc, vs=1.0)  # = Dahl, gamma 1
    return {
        "PID alone": None,
        "feedforward": controllers.Feedforward(model),
        "LuGre observer": controllers.LuGreObserver(lugre, gain=2e3),
        "friction observer": controllers.FrictionObserver(model, pole=1000.0),
        "disturbance observer": controllers.DisturbanceObserver(bandwidth=2 * math.pi * 300.0),
    }


def main(outdir: "str | Path" = ".", quick: bool = False) -> dict:
    """Run the loops, write ``outdir/compensation.png``, return the errors [m] per case."""
    model = pf.Dahl(sigma=1e6, Fc=1.0)
    system = pf.Oscillator(model, mass=1.0)
    pid = controllers.design_pid(system, wn=2 * math.pi * 150.0)
    t_end = 1.1 if quick else 2.0
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    out = {}
    for ax, (cond, opts) in zip(axes, (("nominal", {}), ("mismatch", {"mismatch": (1.2, 0.8)}))):
        for name, comp in compensators(model).items():
            kw = opts if hasattr(comp, "model") else {}  # the disturbance observer has no model to scale
            res = controllers.simulate_loop(system, pid, SINE, t_end, Ts=TS, compensator=comp, **kw)
            near = (res.t >= 1.0) & (res.t <= 1.1)
            out[(cond, name)] = {"rms": float(np.sqrt(np.mean(res.error ** 2))),
                                 "spike": float(np.max(np.abs(res.error[near])))}
            sel = (res.t >= 0.99) & (res.t <= 1.15)
            ax.plot((res.t[sel] - 1.0) * 1e3, res.error[sel] * 1e9, label=name)
        ax.set_title(f"Dahl stage, 5 µm 1 Hz sine, {cond} model")
        ax.set_xlabel("time after the reference reversal at t = 1 s [ms]")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("tracking error r - x [nm]")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=9)
    fig.tight_layout(rect=(0.0, 0.08, 1.0, 1.0))
    Path(outdir).mkdir(parents=True, exist_ok=True)
    path = Path(outdir) / "compensation.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return {"path": path, "errors": out}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    result = main(outdir, quick)
    print(f"wrote {result['path']}")
    for (cond, name), e in result["errors"].items():
        print(f"  {cond:<9} {name:<21} RMS {e['rms'] * 1e9:9.4g} nm   spike {e['spike'] * 1e9:9.4g} nm")
