"""Figure 3 of the paper: potential energy (3.9) at a reversal against ``|F_i|/Fc``.

``E_p(F_i) = (Fc^2/sigma) (ln(Fc/(Fc - F_i)) - F_i/Fc)`` for a reversal at ``F_i = -a Fc``,
``a`` in (0, 1], drawn on a logarithmic scale for ``sigma/Fc`` in {1, 10, 100, 1000}.
The paper does not state ``Fc``; we take ``Fc = 1 N`` so that ``sigma`` [N/m] equals the
ratio ``sigma/Fc`` [1/m]. The curves are the same curve shifted by ``log10(sigma/Fc)``:
``E_p sigma / Fc^2`` depends on ``a`` only, with maximum ``1 - ln 2 = 0.306853`` at ``a = 1``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

FC = 1.0  # Coulomb force [N]; not stated in the paper
RATIOS = (1.0, 10.0, 100.0, 1000.0)  # sigma/Fc [1/m], as in the paper
RATIO_COLORS = (COLORS[4], COLORS[0], COLORS[1], COLORS[2])  # 10, 100, 1000 1/m as in Figs. 6 and 7


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw Figure 3 into ``outdir/fig3_potential_energy.png``.

    Parameters
    ----------
    outdir : str or Path
        Output directory (created if missing).
    quick : bool
        Coarser grid of amplitudes (for tests).

    Returns
    -------
    dict
        ``a`` (|F_i|/Fc grid), ``E_p`` (dict ratio -> E_p [J] on the grid), ``E_p_max``
        (dict ratio -> max E_p [J]), ``Fc`` [N], ``png`` (path).
    """
    a = np.linspace(0.01, 1.0, 34 if quick else 400)
    fig, axes = new_figure(size=(6.5, 4.5))
    ax = axes[0, 0]
    curves: dict[float, np.ndarray] = {}
    maxima: dict[float, float] = {}
    for color, ratio in zip(RATIO_COLORS, RATIOS):
        sigma = ratio * FC
        e_p = np.asarray(dahl.potential_energy(-a * FC, sigma, FC), dtype=float)
        curves[ratio] = e_p
        maxima[ratio] = float(dahl.potential_energy(-FC, sigma, FC))
        ax.semilogy(a, e_p, color=color, label=rf"$\sigma/F_c$ = {ratio:g} m$^{{-1}}$")
        ax.plot(1.0, maxima[ratio], "o", color=color, ms=4)
    ax.annotate(
        r"max $E_p = (1-\ln 2)\,F_c^2/\sigma = 0.3069\,F_c^2/\sigma$",
        xy=(1.0, maxima[1.0]), xytext=(0.25, 0.6), fontsize=9,
        arrowprops=dict(arrowstyle="->", color="0.3"),
    )
    ax.set_xlabel(r"normalised restoring force at the reversal $|F_i|/F_c$ [-]")
    ax.set_ylabel(r"potential energy $E_p$ (3.9) [J]")
    ax.set_xlim(0.0, 1.04)
    ax.set_ylim(1e-8, 2.0)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right")
    ax.set_title("Fig. 3: potential energy at a reversal")
    add_note(fig, f"Fc = {FC:g} N (not stated in the paper), so sigma [N/m] = sigma/Fc [1/m].")
    png = save(fig, outdir, "fig3_potential_energy.png")
    return {"a": a, "E_p": curves, "E_p_max": maxima, "Fc": FC, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
