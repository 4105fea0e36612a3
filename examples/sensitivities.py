"""Sensitivities of the reversal table: branch sensitivities against the exact map.

Unforced Dahl oscillator (gamma = 1, ``sigma = 1e4 N/m``, ``Fc = 2 N``, mass 0.5 kg,
``v0 = 0.03 m/s``), 12 reversals. Figure ``sensitivities.png``: (a) logarithmic sensitivities
``(p / F_i) dF_i/dp`` of the reversal forces to ``sigma``, ``Fc``, the mass and ``v0`` from
:func:`prefriction.sensitivity.sensitivities` (CasADi forward sensitivities) with the closed
form of :func:`prefriction.sensitivity.exact_sensitivities` as markers; (b) the relative
difference of the two for forces and positions (``docs/sensitivities.md``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import prefriction as pf  # noqa: E402
from prefriction.sensitivity import exact_sensitivities, sensitivities  # noqa: E402

SYSTEM = pf.Oscillator(pf.Dahl(1e4, 2.0), mass=0.5)
V0, N = 0.03, 12
NAMES = ("sigma", "Fc", "mass", "v0")


def main(outdir: str | Path = ".") -> dict:
    """Compute both, draw ``sensitivities.png``, return the largest relative difference."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    res = sensitivities(SYSTEM, V0, reversals=N, parameters=NAMES)
    ex = exact_sensitivities(SYSTEM, V0, N)
    i = np.arange(N)
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.4))
    for j, name in enumerate(NAMES):
        p = res.values[j]
        ax[0].plot(i, p * res.dF[:, j] / res.F, "-", color=f"C{j}", label=f"{name} (CasADi)")
        ax[0].plot(i, p * ex["dF"][:, j] / ex["F"], "o", color=f"C{j}", mfc="none", label=f"{name} (exact map)")
        ax[1].semilogy(i, np.abs(res.dF[:, j] / ex["dF"][:, j] - 1) + 1e-17, "-o", ms=3, color=f"C{j}", label=f"dF/d{name}")
        ax[1].semilogy(i, np.abs(res.dx[:, j] / ex["dx"][:, j] - 1) + 1e-17, "--s", ms=3, color=f"C{j}", label=f"dx/d{name}")
    ax[0].set(xlabel="reversal number i [-]", ylabel="(p / F_i) dF_i/dp [-]", title="(a) logarithmic sensitivities of the forces")
    ax[0].legend(ncol=2, fontsize=8, loc="center right", title="sigma and mass coincide: both enter through c = m sigma v0^2 / (2 Fc^2)", title_fontsize=7)
    ax[1].set(xlabel="reversal number i [-]", ylabel="relative difference [-]", title="(b) CasADi against the exact map", ylim=(1e-13, 1e-6))
    ax[1].legend(ncol=2, fontsize=7, loc="upper left")
    fig.tight_layout()
    png = outdir / "sensitivities.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    err = max(np.max(np.abs(res.dF / ex["dF"] - 1)), np.max(np.abs(res.dx / ex["dx"] - 1)))
    return {"max_relative_difference": float(err), "result": res, "pngs": [png]}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, _ = script_args(sys.argv[1:], allow_quick=False)
    out = main(outdir)
    print(out["result"].summary())
    print(f"largest relative difference against the exact map: {out['max_relative_difference']:.3g}")
