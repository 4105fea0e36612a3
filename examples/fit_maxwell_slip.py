"""Fit a four-element Maxwell-slip model (stiffness and slip force of each element) to noisy loops.

Synthetic measurements: the force of four elasto-plastic elements in parallel (Iwan 1966) along
growing displacement loops, each element's force from the closed-form stop operator
``z_i <- clip(z_i + k_i dx, -W_i, W_i)`` (``prefriction.identify.synthetic.maxwell_slip_loops``),
with force noise of 0.5 % of the total slip force. The loop peaks grow from 9 to 37 um, past every
element's slip deflection ``W_i / k_i`` (4, 10, 15, 20 um), so each element's kink in the virgin
curve is seen and its two parameters are identifiable. The fit moves all eight parameters; the
95 % intervals are then checked over ``seeds`` noise draws. A last fit shows the
``IdentifiabilityWarning`` when two elements share one slip deflection (only their sums are
determined).

Run: ``python examples/fit_maxwell_slip.py [outdir] [--quick]``.
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
from prefriction.identify.synthetic import maxwell_slip_loops

TRUE = pf.MaxwellSlip([5.0e4, 3.0e4, 2.0e4, 1.0e4], [0.2, 0.3, 0.3, 0.2])      # N/m, N
START = pf.MaxwellSlip([4.0e4, 3.5e4, 1.5e4, 1.2e4], [0.15, 0.35, 0.25, 0.25])
NOISE = 0.005  # [N], 0.5 % of sum W_i = 1 N


def loops(t: np.ndarray) -> np.ndarray:
    """Growing loops [m]: three periods, peaks from 9 to 37 um."""
    return 40e-6 * np.sin(2 * np.pi * t) * (0.15 + 0.85 * t / t[-1])


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Fit, coverage over seeds, the tied-elements case and the figure; returns the numbers."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t = np.linspace(0.0, 3.0, 301)
    x = loops(t)
    truth = np.concatenate([TRUE.stiffness, TRUE.slip_force])
    res = identify.fit(START, maxwell_slip_loops(TRUE, t, x, NOISE, np.random.default_rng(0)))
    print(res.report())
    seeds = 2 if quick else 20
    inside = np.zeros(truth.size, dtype=int)
    for seed in range(seeds):
        r = identify.fit(START, maxwell_slip_loops(TRUE, t, x, NOISE, np.random.default_rng(100 + seed)))
        inside += (r.low <= truth) & (truth <= r.high)
        print(f"seed {seed + 1}/{seeds}", file=sys.stderr, end="\r")
    print(file=sys.stderr)
    coverage = dict(zip(res.names, (inside / seeds).tolist()))
    print(f"coverage of the 95 % intervals over {seeds} seeds: "
          + ", ".join(f"{n} {100 * c:.0f} %" for n, c in coverage.items())
          + f"; all {100 * inside.sum() / (seeds * truth.size):.0f} %")

    tied = pf.MaxwellSlip([5.0e4, 3.0e4, 2.0e4, 1.5e4], [0.2, 0.3, 0.3, 0.225])  # elements 3, 4: 15 um
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", identify.IdentifiabilityWarning)
        tie = identify.fit(START, maxwell_slip_loops(tied, t, x, NOISE, np.random.default_rng(1)))
    print(f"two elements with one slip deflection: not identifiable {tie.unidentifiable} "
          f"({len(caught)} warnings)")
    png = _figure(res, truth, coverage, seeds, outdir)
    return {"png": png, "result": res, "coverage": coverage, "seeds": seeds, "tied": tie, "x": x, "t": t}


def _figure(res: identify.FitResult, truth: np.ndarray, coverage: dict, seeds: int, outdir: Path) -> Path:
    d = res.data
    fig, axes = plt.subplot_mosaic("LE;RR", figsize=(11, 7.5), height_ratios=[2.0, 1.0], layout="constrained")
    ax = axes["L"]
    ax.plot(d.x * 1e6, d.F, ".", ms=3, color="0.6", label="data (stop operators + noise)")
    ax.plot(d.x * 1e6, res.fitted, "-", lw=1.0, color="C0", label="fitted Maxwell-slip")
    ax.set_xlabel("displacement $x$ [µm]")
    ax.set_ylabel("friction force F [N]")
    ax.set_title(f"growing loops, 4 elements, noise sd {NOISE * 1e3:.0f} mN; residual sd "
                 f"{res.statistics.sigma_hat * 1e3:.2f} mN", fontsize=9)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.12 * (hi - lo))  # a free strip above the loops for the legend
    ax.legend(loc="upper center", ncol=2, fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes["E"]
    n = truth.size // 2
    k, W = res.estimates[:n], res.estimates[n:]
    hk, hW = res.high[:n] - k, res.high[n:] - W
    ax.errorbar(k / 1e3, W, xerr=hk / 1e3, yerr=hW, fmt="s", ms=5, color="C0", capsize=3,
                label="fit, 95 % intervals")
    ax.plot(truth[:n] / 1e3, truth[n:], "o", mfc="none", ms=11, color="C3", label="true elements")
    offsets = [(8, -16), (8, -16), (-100, -16), (8, -16)]  # points; element 2 left of element 1
    for i in range(n):
        ax.annotate(f"{i}: W/k = {1e6 * truth[n + i] / truth[i]:.0f} µm", (truth[i] / 1e3, truth[n + i]),
                    textcoords="offset points", xytext=offsets[i], fontsize=8)
    ax.set_xlabel("element stiffness k_i [kN/m]")
    ax.set_ylabel("element slip force W_i [N]")
    ax.set_xlim(0.0, 1.35 * truth[:n].max() / 1e3)
    ax.set_ylim(0.1, 0.42)
    worst = 100 * min(coverage.values())
    ax.set_title(f"the four elements (seed 0); over {seeds} noise seeds each 95 % interval\n"
                 f"held the truth in >= {worst:.0f} % of them", fontsize=9)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)

    ax = axes["R"]
    ax.plot(d.t, res.residuals * 1e3, ".", ms=3, color="C3")
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("residual F - fit [mN]")
    ax.grid(alpha=0.3)
    png = outdir / "fit_maxwell_slip.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    main(outdir, quick=quick)
