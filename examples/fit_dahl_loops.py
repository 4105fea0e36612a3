"""Fit Dahl (sigma, Fc, gamma) to noisy force-displacement loops; coverage of the 95 % intervals.

Synthetic measurements: the Dahl force (3.2) along growing loops, from the closed-form branches
(``prefriction.identify.synthetic.dahl_loops``), with 1 % force noise. One fit is shown (data,
fit, residuals); then the same fit over ``seeds`` noise draws counts how often each 95 %
interval holds the true value. A second figure panel shows pre-sliding loops, from which ``Fc``
cannot be identified (``IdentifiabilityWarning``).

Run: ``python examples/fit_dahl_loops.py [outdir] [--quick]``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import prefriction as pf
from prefriction import identify
from prefriction.identify.synthetic import dahl_loops

TRUE = pf.Dahl(sigma=2.0e4, Fc=1.5, gamma=1.5)
START = pf.Dahl(sigma=1.4e4, Fc=1.1, gamma=1.2)


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Fit, coverage count and figure; returns the numbers and the figure path."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t = np.linspace(0.0, 3.0, 241)
    shape = np.sin(2 * np.pi * t) * (0.3 + 0.7 * t / 3.0)
    x = 3.0 * TRUE.Fc / TRUE.sigma * shape
    noise = 0.01 * TRUE.Fc
    res = identify.fit(START, dahl_loops(TRUE, t, x, noise, np.random.default_rng(0)))
    print(res.report())
    seeds = 5 if quick else 20
    truth = np.array([TRUE.sigma, TRUE.Fc, TRUE.gamma])
    inside = np.zeros(3, dtype=int)
    for seed in range(seeds):
        r = identify.fit(START, dahl_loops(TRUE, t, x, noise, np.random.default_rng(100 + seed)))
        inside += (r.low <= truth) & (truth <= r.high)
        print(f"seed {seed + 1}/{seeds}", file=sys.stderr, end="\r")
    print(file=sys.stderr)
    coverage = dict(zip(res.names, (inside / seeds).tolist()))
    print(f"coverage of the 95 % intervals over {seeds} seeds: "
          + ", ".join(f"{n} {100 * c:.0f} %" for n, c in coverage.items()))

    xs = 0.01 * TRUE.Fc / TRUE.sigma * shape
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", identify.IdentifiabilityWarning)
        small = identify.fit(pf.Dahl(1.4e4, 1.1, 1.5), dahl_loops(TRUE, t, xs, 2e-4 * TRUE.Fc, np.random.default_rng(1)),
                             fixed=["gamma"])
    warned = [str(w.message) for w in caught if issubclass(w.category, identify.IdentifiabilityWarning)]
    print("pre-sliding loops:", small.unidentifiable, "|", warned[0] if warned else "no warning")

    fig, axes = plt.subplots(2, 2, figsize=(11, 7), height_ratios=[2.0, 1.0], layout="constrained")
    for col, (r, title) in enumerate(((res, "loops into gross sliding (3 Fc/sigma)"),
                                      (small, "pre-sliding loops (0.01 Fc/sigma)"))):
        d = r.data
        ax, axr = axes[0, col], axes[1, col]
        ax.plot(d.x * 1e6, d.F, ".", ms=3, color="0.6", label="data (Dahl + noise)")
        ax.plot(d.x * 1e6, r.fitted, "-", lw=1.1, color="C0", label="fitted Dahl")
        ax.set_xlabel("displacement $x$ [µm]")
        ax.set_ylabel("friction force F [N]")
        lines = [f"{n} = {v:.4g}{'' if u == '-' else ' ' + u} (not identifiable)" if n in r.unidentifiable else f"{n} = {v:.4g} ± {1.96 * s:.2g}{'' if u == '-' else ' ' + u}"
                 for n, u, v, s in zip(r.names, r.units, r.estimates, r.stderr)]
        ax.set_title(title + "\n" + ", ".join(lines) + " (95 %)", fontsize=9)
        ax.legend(loc="lower right", fontsize=8)
        ax.grid(alpha=0.3)
        axr.plot(d.t, r.residuals * 1e3, ".", ms=3, color="C3")
        axr.axhline(0.0, color="0.3", lw=0.8)
        axr.set_xlabel("time t [s]")
        axr.set_ylabel("residual [mN]")
        axr.grid(alpha=0.3)
    png = outdir / "fit_dahl_loops.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return {"png": png, "result": res, "coverage": coverage, "seeds": seeds, "pre_sliding": small}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    main(outdir, quick=quick)
