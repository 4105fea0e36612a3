"""Fit all six LuGre parameters to the force measured along a prescribed, growing oscillation.

Synthetic measurements: the LuGre model (Canudas de Wit, Olsson, Astrom, Lischinsky 1995)
driven by the velocity ``v(t) = (V0 + c t) cos(2 pi f t)``, whose reversals are known
(``cos = 0``). The force comes from scipy's Radau at ``rtol = 1e-9``, restarted at each
reversal (``prefriction.identify.synthetic.lugre_force``), with force noise of 0.5 % of ``Fc``.
The peak speed grows to about twice the Stribeck velocity, so the record holds pre-sliding
after each reversal (``sigma0``, ``sigma1``), the Stribeck drop (``Fs``, ``vs``) and sliding at
several speeds (``Fc``, ``sigma2``). The fit moves all six parameters from start values 20-40 %
off; the 95 % intervals are then checked over ``seeds`` noise draws.

Run: ``python examples/fit_lugre.py [outdir] [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import prefriction as pf
from prefriction import identify
from prefriction.identify.synthetic import lugre_force

TRUE = pf.LuGre(sigma0=1.0e5, sigma1=300.0, sigma2=40.0, Fc=1.0, Fs=1.5, vs=1.0e-3)
START = pf.LuGre(sigma0=0.8e5, sigma1=200.0, sigma2=30.0, Fc=1.2, Fs=1.4, vs=1.3e-3)
NOISE = 0.005   # [N], 0.5 % of Fc
FREQ = 2.0      # [Hz]
V0, RAMP = 1.0e-4, 1.2e-3   # [m/s], [m/s^2]: v(t) = (V0 + RAMP t) cos(2 pi FREQ t)
DURATION = 1.5  # [s], three periods


def velocity(t: np.ndarray | float) -> np.ndarray | float:
    """Prescribed velocity [m/s]."""
    return (V0 + RAMP * t) * np.cos(2 * np.pi * FREQ * t)


def position(t: np.ndarray) -> np.ndarray:
    """Prescribed displacement [m], the integral of :func:`velocity` from 0."""
    w = 2 * np.pi * FREQ
    return V0 * np.sin(w * t) / w + RAMP * (t * np.sin(w * t) / w + (np.cos(w * t) - 1.0) / w**2)


def reversal_times() -> np.ndarray:
    """Zeros of the velocity in the record [s]."""
    k = np.arange(int(2 * FREQ * DURATION) + 1)
    tau = (k + 0.5) / (2 * FREQ)
    return tau[tau < DURATION]


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Reference force, fit, coverage over seeds and the figure; returns the numbers."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t = np.linspace(0.0, DURATION, 601)
    x = position(t)
    print("reference force: Radau, restarted at the 6 reversals", file=sys.stderr)
    clean = lugre_force(TRUE, t, velocity, reversal_times())
    names = [p.name for p in type(TRUE).parameters]
    truth = np.array([getattr(TRUE, n) for n in names])

    def data(seed: int) -> identify.ForceDisplacement:
        return identify.ForceDisplacement(t, x, clean + NOISE * np.random.default_rng(seed).standard_normal(t.size))

    res = identify.fit(START, data(0))
    print(res.report())
    seeds = 1 if quick else 20
    inside = np.zeros(truth.size, dtype=int)
    for seed in range(seeds):
        r = identify.fit(START, data(100 + seed))
        inside += (r.low <= truth) & (truth <= r.high)
        print(f"seed {seed + 1}/{seeds}", file=sys.stderr, end="\r")
    print(file=sys.stderr)
    coverage = dict(zip(res.names, (inside / seeds).tolist()))
    print(f"coverage of the 95 % intervals over {seeds} seeds: "
          + ", ".join(f"{n} {100 * c:.0f} %" for n, c in coverage.items()))
    png = _figure(res, t, coverage, seeds, outdir)
    return {"png": png, "result": res, "coverage": coverage, "seeds": seeds, "clean": clean, "t": t}


def _figure(res: identify.FitResult, t: np.ndarray, coverage: dict, seeds: int, outdir: Path) -> Path:
    d = res.data
    fig, axes = plt.subplot_mosaic("LS;RR", figsize=(11, 7.5), height_ratios=[2.0, 1.0], layout="constrained")
    ax = axes["L"]
    ax.plot(d.x * 1e6, d.F, ".", ms=2.5, color="0.6", label="data (Radau reference + noise)")
    ax.plot(d.x * 1e6, res.fitted, "-", lw=0.9, color="C0", label="fitted LuGre")
    ax.set_xlabel("displacement $x$ [µm]")
    ax.set_ylabel("friction force F [N]")
    lines = [f"{n} = {v:.4g} ± {1.96 * s:.2g}{'' if u == '-' else ' ' + u}" for n, u, v, s in zip(res.names, res.units, res.estimates, res.stderr)]
    ax.set_title("force along the prescribed motion (95 %):\n" + ", ".join(lines[:3]) + "\n"
                 + ", ".join(lines[3:]), fontsize=8)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.12 * (hi - lo))  # a free strip above the loops for the legend
    ax.legend(loc="upper center", ncol=2, fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes["S"]
    v = velocity(t)
    ax.plot(v * 1e3, d.F, ".", ms=2.5, color="0.6", label="data")
    vv = np.linspace(-1.05, 1.05, 401) * np.abs(v).max()
    ax.plot(vv * 1e3, TRUE.steady_force(vv), "-", lw=2.5, color="C3", alpha=0.5, label="true steady state")
    ax.plot(vv * 1e3, res.model.steady_force(vv), "--", lw=1.2, color="C0", label="fitted steady state")
    ax.set_xlabel("velocity v [mm/s]")
    ax.set_ylabel("friction force F [N]")
    worst = 100 * min(coverage.values())
    ax.set_title(f"Stribeck curve g(v) + sigma2 v; over {seeds} noise seeds each 95 % interval\n"
                 f"held the truth in >= {worst:.0f} % of them", fontsize=8)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes["R"]
    ax.plot(d.t, res.residuals * 1e3, ".", ms=2.5, color="C3")
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("residual F - fit [mN]")
    ax.grid(alpha=0.3)
    png = outdir / "fit_lugre.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    main(outdir, quick=quick)
