"""Fit friction models to a measured tribometer record and validate them on held-out cycles.

The record (``prefriction.data.tribometer()``, FrictionModels.jl ``examples/test_data_2.txt``,
MIT licence): 5 N normal load, a 0.23 mm triangular stroke at about 0.26 mm/s, 200 Hz. Every
model is fitted with a force offset (``offset=True``) on 12-60 s and validated on the held-out
cycles of 150-198 s (``FitResult.validate``: the initial state from the first 2 s, which are
not scored). Prints one table (estimates with 95 % intervals and bound flags, rms on the fitted
part and on the held-out part, fit %) and writes one figure.

Usage::

    python examples/fit_measured_loops.py OUTDIR [--quick]

``--quick`` fits every 4th sample (50 Hz) instead of all of them.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import prefriction as pf
from prefriction import identify
from prefriction.data import tribometer

FIT, HELD_OUT, SKIP = (12.0, 60.0), (150.0, 198.0), 2.0
GMS_FIXED = ["alpha[0]", "alpha[1]", "alpha[2]", "vs", "delta", "sigma2", "damping[0]", "damping[1]", "damping[2]"]
MODELS = [  # (label, start model, fit keywords)
    ("Dahl, gamma < 1", pf.Dahl(sigma=4e4, Fc=2.4, gamma=0.5), dict(structures="given")),
    ("Dahl, gamma >= 1", pf.Dahl(sigma=4e4, Fc=2.4, gamma=1.5), dict(structures="given")),
    ("Maxwell-slip, 3 elements", pf.MaxwellSlip(stiffness=[1e5, 4e4, 5e3], slip_force=[0.3, 1.8, 0.2]),
     dict(max_iter=1000)),   # slip deflections 3, 45, 40 um: inside the stroke (docs/identify.md#limits)
    ("GMS, 3 elements", pf.GMS(k=[2e5, 4e4, 1e4], alpha=[0.4, 0.33, 0.27], Fc=2.35, Fs=2.5, vs=1e-4, C=20.0,
                               sigma2=1.0, damping=[1e-3] * 3), dict(fixed=GMS_FIXED)),
    ("LuGre", pf.LuGre(sigma0=4e4, sigma1=1.0, sigma2=1.0, Fc=2.3, Fs=2.5, vs=1e-4),
     dict(fixed=["sigma1", "sigma2", "vs"], max_iter=300)),
    ("Dahl + Viscous", pf.Dahl(sigma=4e4, Fc=2.4, gamma=0.5) + pf.Viscous(10.0), dict(structures="given")),
]


def fit_all(step: int) -> list[tuple[str, identify.FitResult, list[str], identify.Validation]]:
    """Fit every model on the fitting window and validate it on the held-out one."""
    rec = tribometer()
    data, held = rec.window(*FIT, step=step), rec.window(*HELD_OUT)
    out = []
    for label, start, kw in MODELS:
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = identify.fit(start, data, offset=True, **kw)
        val = res.validate(held, skip=SKIP)
        print(f"fitted {label} in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        out.append((label, res, [str(w.message).split(";")[0] for w in caught], val))
    return out


def table(results: list) -> str:
    """One table: per model the rms (fitted, held-out), fit % and the estimates with intervals."""
    head = f"{'model':<26} {'rms fit [N]':>11} {'rms held-out [N]':>16} {'fit % held-out':>14}"
    rows = [head, "-" * len(head)]
    for label, res, caught, val in results:
        rows.append(f"{label:<26} {res.rms:>11.4f} {val.rms:>16.4f} {val.fit_percent:>14.2f}"
                    + ("" if res.success else "   NOT CONVERGED"))
        for i, (n, u, v, lo, hi) in enumerate(zip(res.names, res.units, res.estimates, res.low, res.high)):
            flag = "; ".join(f for f in (res.flags[i], "not identifiable" if n in res.unidentifiable else "") if f)
            rows.append(f"    {n:<13} {v:>11.5g} {u:<6} [{lo:.5g}, {hi:.5g}]" + (f"  ({flag})" if flag else ""))
    return "\n".join(rows)


def figure(results: list, path: Path) -> Path:
    """Held-out loops of the measured force against the best model, and every model's error."""
    import matplotlib.pyplot as plt

    best = min(results, key=lambda r: r[3].rms)
    held = tribometer().window(*HELD_OUT)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 8.0), height_ratios=[1.4, 1.0], layout="constrained")
    v = best[3]
    keep = np.searchsorted(held.t, v.t)
    ax1.plot(held.x[keep] * 1e3, v.measured, "-", lw=0.6, color="0.6", label="measured (held-out 150-198 s)")
    ax1.plot(held.x[keep] * 1e3, v.predicted, "-", lw=0.8, color="C0",
             label=f"predicted: {best[0]} (rms {v.rms:.3f} N)")
    ax1.set_xlabel("position x [mm]")
    ax1.set_ylabel("friction force F [N]")
    ax1.legend(loc="center", frameon=True, fontsize=8)
    ax1.grid(alpha=0.3)
    window = (v.t >= 160.0) & (v.t <= 166.0)
    for k, (label, _res, _c, val) in enumerate(results):
        ax2.plot(val.t[window], (val.measured - val.predicted)[window], lw=0.9, color=f"C{k}",
                 label=f"{label}: {val.rms:.3f} N")
    ax2.axhline(0.0, color="0.3", lw=0.8)
    ax2.set_xlabel("time t [s]")
    ax2.set_ylabel("held-out error F - prediction [N]")
    ax2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8, frameon=False,
               title="model: held-out rms over 152-198 s", title_fontsize=8)
    ax2.grid(alpha=0.3)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    """Run the fits, print the table, write ``OUTDIR/fit_measured_loops.png``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir", type=Path)
    parser.add_argument("--quick", action="store_true", help="fit every 4th sample (50 Hz)")
    args = parser.parse_args(argv)
    args.outdir.mkdir(parents=True, exist_ok=True)
    step = 4 if args.quick else 1
    results = fit_all(step)
    print(f"tribometer record: fitted on {FIT[0]:g}-{FIT[1]:g} s (every {step}. sample), validated on "
          f"{HELD_OUT[0]:g}-{HELD_OUT[1]:g} s (initial state from the first {SKIP:g} s, not scored), offset fitted")
    print(table(results))
    both = identify.fit(pf.Dahl(sigma=4e4, Fc=2.4, gamma=1.5), tribometer().window(*FIT, step=step), offset=True,
                        structures="both")
    print(both.notes[-1])
    print(f"figure: {figure(results, args.outdir / 'fit_measured_loops.png')}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
