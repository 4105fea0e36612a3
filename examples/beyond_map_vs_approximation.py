"""Beyond the paper: the exact reversal map against the approximation (3.11)-(3.13).

For a reversal at ``|F_i| = a Fc`` the next reversal lies at the distance ``x_{i+1}`` from the
force zero crossing where the stored energy (3.7) returns ``E_p`` (3.9). Exactly,
``x_{i+1} sigma/Fc = c + 1 + W0(-exp(-(1 + c)))`` with ``c = a - ln(1 + a)`` (real principal
branch of Lambert W, which the paper thought unusable). The paper replaces ``Omega`` by the
secant (3.11) and gets (3.13); with the erratum corrected (no extra factor ``Fc/sigma``),
``x_{i+1} = E_p / (Fc (1 - r^(3/5)))``, ``r = Fc/(Fc - F_i)``. Both are universal in the
normalised units (no dependence on sigma, Fc, m). The figure shows both maps and the
relative error of the approximate ``x_{i+1}`` (and of ``|F_{i+1}|``) over ``a`` in [1e-4, 1];
the error tends to ``5/6 - 1 = -16.7 %`` as ``a -> 0``. (3.13) as printed is also evaluated
for ``sigma/Fc = 10``: off by -64 % at ``a = 1``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

TABLE_AMPLITUDES = (1.0, 0.8, 0.6, 0.4, 0.2, 0.1, 0.01, 1e-4)
PRINTED_RATIO = 10.0  # sigma/Fc [1/m] at which (3.13) as printed is evaluated


def displacement(a_next: np.ndarray) -> np.ndarray:
    """Normalised distance ``x sigma/Fc`` from the zero crossing to a reversal of amplitude ``a_next``."""
    return -np.log1p(-np.asarray(a_next, dtype=float))


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/beyond_map_vs_approximation.png``.

    Returns
    -------
    dict
        ``a`` (grid), ``y_exact``, ``y_approx`` (normalised ``x_{i+1} sigma/Fc``),
        ``rel_error_x`` and ``rel_error_F`` (approximate/exact - 1 for ``x_{i+1}`` and
        ``|F_{i+1}|``), ``table`` (list of rows ``(a, a_next_exact, a_next_approx, err_x, err_F,
        err_x_printed)`` at :data:`TABLE_AMPLITUDES`), ``limit`` (-1/6); ``png``.
    """
    a = np.logspace(-4, 0, 60 if quick else 400)
    a_exact = np.asarray(dahl.next_amplitude(a), dtype=float)
    a_approx = np.asarray(dahl.next_amplitude_paper(a), dtype=float)
    y_exact, y_approx = displacement(a_exact), displacement(a_approx)
    err_x = y_approx / y_exact - 1.0
    err_f = a_approx / a_exact - 1.0

    ta = np.asarray(TABLE_AMPLITUDES)
    te, tp = np.asarray(dahl.next_amplitude(ta), float), np.asarray(dahl.next_amplitude_paper(ta), float)
    tye, typ = displacement(te), displacement(tp)
    tyr = displacement(dahl.next_amplitude_paper(ta, sigma_over_Fc=PRINTED_RATIO))
    table = [
        (float(ai), float(ei), float(pi), float(yp / ye - 1.0), float(pi / ei - 1.0),
         float(yr / ye - 1.0))
        for ai, ei, pi, ye, yp, yr in zip(ta, te, tp, tye, typ, tyr)
    ]

    fig, axes = new_figure(1, 2, size=(11.0, 4.4))
    ax = axes[0, 0]
    lin = a >= 0.01
    ax.plot(a[lin], y_exact[lin], color=COLORS[0], lw=2.0, label=r"$x_{i+1}\sigma/F_c$, exact (Lambert $W_0$)")
    ax.plot(a[lin], y_approx[lin], color=COLORS[1], ls="--", lw=1.6, label=r"$x_{i+1}\sigma/F_c$, corrected (3.13)")
    ax.plot(a[lin], a_exact[lin], color=COLORS[2], lw=1.6, label=r"$|F_{i+1}|/F_c$, exact")
    ax.plot(a[lin], a_approx[lin], color=COLORS[3], ls="--", lw=1.3, label=r"$|F_{i+1}|/F_c$, from (3.13)")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel(r"reversal amplitude $a = |F_i|/F_c$ [-]")
    ax.set_ylabel(r"next reversal: distance $x_{i+1}\sigma/F_c$, force $|F_{i+1}|/F_c$ [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=9)
    ax.set_title("next reversal: exact map and approximation")

    ax = axes[0, 1]
    ax.semilogx(a, 100 * err_x, color=COLORS[1], lw=1.8, label=r"error of $x_{i+1}$")
    ax.semilogx(a, 100 * err_f, color=COLORS[2], lw=1.4, ls="-.", label=r"error of $|F_{i+1}|$")
    ax.axhline(100 * (5.0 / 6.0 - 1.0), color="0.4", lw=0.8, ls="--", label="limit 5/6 - 1 = -16.7 %")
    for row in (r for r in table if r[0] in (1.0, 0.6, 0.2)):
        ax.annotate(f"a = {row[0]:g}: {100 * row[3]:+.2f} %", xy=(row[0], 100 * row[3]), xytext=(-95, -4),
                    textcoords="offset points", fontsize=8, arrowprops=dict(arrowstyle="-", color="0.5"))
        ax.plot(row[0], 100 * row[3], "o", color=COLORS[1], ms=4)
    ax.set_ylim(-20, 3)
    ax.set_xlabel(r"reversal amplitude $a = |F_i|/F_c$ [-]")
    ax.set_ylabel("relative error of the approximation [%]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("relative error of (3.13)")
    add_note(fig, "Universal in normalised units (independent of sigma, Fc, m). (3.13) as printed carries "
                  f"an extra factor Fc/sigma: at sigma/Fc = {PRINTED_RATIO:g} 1/m its x_(i+1) is off by "
                  f"{100 * table[0][5]:+.0f} % at a = 1 (not drawn).")
    png = save(fig, outdir, "beyond_map_vs_approximation.png")
    return {
        "a": a, "y_exact": y_exact, "y_approx": y_approx, "rel_error_x": err_x, "rel_error_F": err_f,
        "table": table, "limit": 5.0 / 6.0 - 1.0, "png": png,
    }


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
