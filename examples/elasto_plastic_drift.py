"""No drift below breakaway: the elasto-plastic model against LuGre under a biased oscillating force.

A mass of 0.5 kg on friction with ``sigma0 = 1e5 N/m``, ``sigma1 = 300 N s/m``, ``sigma2 = 0.4 N s/m``,
``Fc = 1 N``, ``Fs = 1.5 N``, ``vs = 1 mm/s`` is driven by ``u(t) = 0.2 N + 0.2 N sin(2 pi 10 Hz t)``:
the force stays within ``[0, 0.4] N``, below the breakaway force ``sigma0 z_ba = 0.5 N`` of the
elasto-plastic model (Dupont et al. 2002, :class:`prefriction.ElastoPlastic`, ``z_ba = 5 um``)
and far below the static force of both models. LuGre (:class:`prefriction.LuGre`, the same
numbers) lets the bristle creep on every cycle (``z' = v - sigma0 |v| z / g(v)`` never stops
dissipating), so the mean position drifts; the elasto-plastic bristle stays elastic
(``alpha = 0``) and the motion settles to a periodic one about a fixed point.

``elasto_plastic_drift.png`` shows the position over time for both and the drift per cycle
(the change of the cycle-mean position from one cycle to the next) over the cycles. Returned:
the drift per cycle [m] of each model over the last ten cycles. Run:
``python examples/elasto_plastic_drift.py [outdir]`` (a few seconds once compiled).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import prefriction as pf
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 0.5  # [kg]
LUGRE = dict(sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3)
Z_BA = 5e-6  # [m]: breakaway force sigma0 z_ba = 0.5 N
BIAS, AMPLITUDE, FREQUENCY = 0.2, 0.2, 10.0  # [N], [N], [Hz]
CYCLES = 40
PER_CYCLE = 100  # samples per cycle
FLOOR = 1e-9  # [nm]: where the log axis shows a drift of zero


def models() -> dict[str, pf.FrictionModel]:
    """The two models of the figure."""
    return {"LuGre": pf.LuGre(**LUGRE), "elasto-plastic": pf.ElastoPlastic(**LUGRE, z_ba=Z_BA)}


def run(model: pf.FrictionModel, cycles: int = CYCLES) -> pf.SimulationResult:
    """The biased oscillating force on ``model`` from rest, sampled ``PER_CYCLE`` times a cycle."""
    u = pf.signals.Constant(BIAS) + pf.signals.Sine(amplitude=AMPLITUDE, frequency=FREQUENCY)
    t_end = cycles / FREQUENCY
    times = np.linspace(0.0, t_end, cycles * PER_CYCLE + 1)
    return pf.simulate(pf.Oscillator(model, mass=MASS, u=u), 0.0, t_end=t_end, rtol=1e-10, dense=times)


def drift_per_cycle(res: pf.SimulationResult) -> np.ndarray:
    """Change of the cycle-mean position [m] from each cycle to the next."""
    x = res.x[:-1].reshape(-1, PER_CYCLE)
    return np.diff(x.mean(axis=1))


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/elasto_plastic_drift.png``; return ``drift`` [m per cycle] over the last ten
    cycles and ``span`` [m] (largest minus least position) per model, and ``png``."""
    cycles = 20 if quick else CYCLES
    out: dict = {"drift": {}, "span": {}}
    fig, axes = new_figure(1, 2, size=(12.0, 4.6))
    for (name, model), color in zip(models().items(), COLORS):
        res = run(model, cycles)
        d = drift_per_cycle(res)
        out["drift"][name] = float(np.mean(d[-10:]))
        out["span"][name] = float(np.ptp(res.x))
        axes[0, 0].plot(res.t, res.x * 1e6, color=color, lw=1.2, label=f"{name}")
        axes[0, 1].plot(np.arange(1, len(d) + 1), np.maximum(np.abs(d) * 1e9, FLOOR), color=color, lw=1.4, marker="o", ms=3,
                        label=f"{name}: {out['drift'][name] * 1e9:.3g} nm/cycle (last 10)")
    ax = axes[0, 0]
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel(r"position $x$ [$\mu$m]")
    ax.set_title(f"u = {BIAS:g} N + {AMPLITUDE:g} N sin(2 pi {FREQUENCY:g} Hz t), below breakaway", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax = axes[0, 1]
    ax.set_yscale("log")
    ax.set_xlabel("cycle number [-]")
    ax.set_ylabel(f"|drift| per cycle [nm] (below {FLOOR:g}: at {FLOOR:g})")
    ax.set_title("change of the cycle-mean position", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="center right", fontsize=8, framealpha=0.95)
    add_note(fig, f"m = {MASS:g} kg, sigma0 = 1e5 N/m, sigma1 = 300 N s/m, sigma2 = 0.4 N s/m, Fc = 1 N, Fs = 1.5 N, "
                  f"vs = 1 mm/s; elasto-plastic z_ba = {Z_BA * 1e6:g} um (breakaway force 0.5 N)")
    out["png"] = save(fig, outdir, "elasto_plastic_drift.png")
    return out


if __name__ == "__main__":
    result = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    for key in ("LuGre", "elasto-plastic"):
        print(f"{key}: drift {result['drift'][key]:.3g} m/cycle, span {result['span'][key]:.3g} m")
