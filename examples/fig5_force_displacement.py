"""Figure 5 of the paper: force-displacement curve between two reversals, Fc in {1, 1.5, 2} N.

The branch (3.5) ``f(x) = Fc - (Fc - F_i) exp(-sigma (x - x_i)/Fc)`` runs from the reversal
``x_i`` of (3.8) (force zero crossing at ``x = 0``) to the next reversal ``x_{i+1}``, where the
stored energy (3.7) equals ``E_p(F_i)`` (3.9). The paper states neither sigma nor F_i: we take
``sigma = 1 N/m`` and the largest reversal force ``F_i = -Fc`` (the reversal from sliding).
Markers: exact next reversal (Lambert-W map), next reversal from the corrected (3.13), and
from (3.13) as printed, which coincides with the corrected form only when ``sigma/Fc = 1``
(for ``Fc = 1.5 N`` it lands at about 44 m, for ``Fc = 2 N`` at a negative ``x``; both are off the
plot and listed in the note).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

SIGMA = 1.0  # rest stiffness [N/m]; not stated in the paper
FCS = (1.0, 1.5, 2.0)  # Coulomb forces [N], as in the paper
A_I = 1.0  # |F_i|/Fc at the reversal i; not stated in the paper


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw Figure 5 into ``outdir/fig5_force_displacement.png``.

    Returns
    -------
    dict
        ``curves[Fc]`` with ``x`` [m], ``F`` [N] along the branch, ``x_i``, ``F_i``,
        ``x_next``, ``F_next`` (exact next reversal), ``x_next_approx`` (corrected (3.13)),
        ``x_next_printed`` ((3.13) as printed); ``sigma`` [N/m]; ``png``.
    """
    fig, axes = new_figure(size=(9.2, 4.8))
    ax = axes[0, 0]
    curves: dict[float, dict] = {}
    printed_notes = []
    for color, Fc in zip(COLORS, FCS):
        F_i = -A_I * Fc
        x_i = float(dahl.reversal_abscissa(F_i, SIGMA, Fc))  # (3.8)
        a_next = float(dahl.next_amplitude(A_I))
        x_next = -np.log1p(-a_next) * Fc / SIGMA
        x_next_approx = float(dahl.next_reversal_position_paper(F_i, SIGMA, Fc))
        x_next_printed = float(dahl.next_reversal_position_paper(F_i, SIGMA, Fc, printed=True))
        x = np.linspace(x_i, x_next, 50 if quick else 300)
        F = dahl.branch_force(x, x_i, F_i, SIGMA, Fc)  # (3.5)
        curves[Fc] = {
            "x": x, "F": F, "x_i": x_i, "F_i": F_i, "x_next": x_next, "F_next": a_next * Fc,
            "x_next_approx": x_next_approx, "x_next_printed": x_next_printed,
        }
        ax.plot(x, F, color=color, lw=1.8, label=rf"$F_c$ = {Fc:g} N")
        ax.plot([x_i, x_next], [F_i, a_next * Fc], "o", color=color, ms=5)
        ax.plot(x_next_approx, dahl.branch_force(x_next_approx, x_i, F_i, SIGMA, Fc),
                "x", color=color, ms=8, mew=1.5)
        ax.axhline(Fc, color=color, lw=0.8, ls=":")
        ax.axhline(-Fc, color=color, lw=0.8, ls=":")
        if not (0.0 < x_next_printed < 1.5 * x_next):
            printed_notes.append(rf"$F_c$ = {Fc:g} N: {x_next_printed:.3g} m")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.axvline(0.0, color="0.5", lw=0.8)
    ax.plot([], [], "ko", ms=5, label="reversals $x_i$, $x_{i+1}$ (exact)")
    ax.plot([], [], "kx", ms=8, mew=1.5, label="$x_{i+1}$ from corrected (3.13)")
    ax.plot([], [], ":", color="0.3", lw=0.8, label=r"$\pm F_c$, in the colour of its curve")
    ax.set_xlabel(r"displacement $x$ [m] (force zero crossing at $x = 0$)")
    ax.set_ylabel(r"restoring force $f[x]$ [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=9)  # outside: no data or +-Fc line covered
    ax.set_title("Fig. 5: force-displacement curve between two reversals")
    add_note(fig, rf"$\sigma$ = {SIGMA:g} N/m and $F_i = -F_c$ (not stated in the paper)." "\n"
                  r"(3.13) as printed puts $x_{i+1}$ off the curve at " + "; ".join(printed_notes) + ".",
             lines=2)
    png = save(fig, outdir, "fig5_force_displacement.png")
    return {"curves": curves, "sigma": SIGMA, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
