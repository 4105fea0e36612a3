"""Fit Dahl (sigma, Fc) to the free decay of the oscillator (2.1): the paper's own situation.

Synthetic measurements: the unforced Dahl oscillator released with a velocity that carries it
into gross sliding; reversal times, positions and forces from ``prefriction.exact_reversals``,
the samples in between from scipy DOP853 at ``rtol = 1e-12``
(``prefriction.identify.synthetic.dahl_free_decay``), with position noise. The amplitudes decay
like ``3 / (2 n)`` (``docs/mathematics.md#convergence``). The fit is multiple shooting over
segments of 50 samples with constrained Gauss-Newton (``docs/identify_motion.md``), the
reversals located inside the sub-steps; the figure shows the data, the fit, the residuals and
the reversals of the fitted motion against the exact ones. With the mass free as well, the
fit warns that a free decay cannot tell ``m``, ``sigma`` and ``Fc`` apart.

Run: ``python examples/fit_dahl_free_decay.py [outdir] [--quick]``.
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
from prefriction.identify.synthetic import dahl_free_decay

TRUE = pf.Dahl(sigma=1.0e4, Fc=1.0, gamma=1.0)
MASS = 1.0
START = pf.Dahl(sigma=1.3e4, Fc=0.8, gamma=1.0)


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Fit the free decay, compare the reversal times, write the figure."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    tu = np.sqrt(MASS / TRUE.sigma)
    t = np.linspace(0.0, (24.0 if quick else 40.0) * tu, 121 if quick else 241)
    v0 = 1.2 * TRUE.Fc / np.sqrt(MASS * TRUE.sigma)
    noise = 0.003 * TRUE.Fc / TRUE.sigma
    data = dahl_free_decay(TRUE, MASS, v0, t, noise, np.random.default_rng(0))
    print("fitting (builds the nonlinear program once, a few seconds)", file=sys.stderr)
    res = identify.fit(START, data, fixed=["gamma"], tol=1e-8)
    print(res.report())
    exact = pf.exact_reversals(pf.Oscillator(TRUE, mass=MASS), v0, 40)
    tau = res.nuisance["reversal times [s]"]
    err = np.abs(tau - exact.t[: tau.size])
    print(f"{tau.size} reversals located; largest error against the exact times {err.max() / (t[1] - t[0]):.3f} samples")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", identify.IdentifiabilityWarning)
        free_mass = identify.fit(START, identify.Motion(data.t, data.x), fixed=["gamma"], mass0=0.8,
                                 reversals=tau, tol=1e-8)
    print("mass free:", free_mass.unidentifiable, f"({len(caught)} warnings);",
          f"sigma/m = {free_mass.estimate('sigma') / free_mass.estimate('mass'):.5g} 1/s^2,",
          f"Fc/m = {free_mass.estimate('Fc') / free_mass.estimate('mass'):.5g} m/s^2")

    fig, (ax, axr) = plt.subplots(2, 1, figsize=(8, 6.5), height_ratios=[2.2, 1.0], layout="constrained")
    ax.plot(t * 1e3, data.x * 1e6, ".", ms=3, color="0.6", label="data (exact + DOP853, noise)")
    ax.plot(t * 1e3, res.fitted * 1e6, "-", lw=1.1, color="C0", label="fitted Dahl (multiple shooting)")
    xr = np.interp(exact.t[: tau.size], t, res.fitted)
    ax.plot(exact.t[: tau.size] * 1e3, exact.x[: tau.size] * 1e6, "o", mfc="none", color="C1", ms=7,
            label="exact reversals")
    ax.plot(tau * 1e3, xr * 1e6, "x", color="C3", ms=6, label="fitted reversal times")
    lines = ", ".join(f"{n} = {v:.5g} ± {1.96 * s:.2g}{'' if u == '-' else ' ' + u}" for n, u, v, s in zip(res.names, res.units, res.estimates, res.stderr))
    ax.set_title(f"free decay, mass {MASS} kg known: {lines} (95 %)", fontsize=9)
    ax.set_xlabel("time t [ms]")
    ax.set_ylabel("position $x$ [µm]")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    axr.plot(t * 1e3, res.residuals * 1e9, ".", ms=3, color="C3")
    axr.axhline(0.0, color="0.3", lw=0.8)
    axr.set_xlabel("time t [ms]")
    axr.set_ylabel("residual x - fit [nm]")
    axr.grid(alpha=0.3)
    png = outdir / "fit_dahl_free_decay.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return {"png": png, "result": res, "reversal_error": float(err.max()), "free_mass": free_mass}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    main(outdir, quick=quick)
