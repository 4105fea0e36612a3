"""Beyond the paper: reversal amplitudes over 1e4 reversals against the law ``3/(2n)``.

The exact map satisfies ``a' = a - (2/3) a^2 + O(a^3)``, so ``1/a_{n+1} - 1/a_n -> 2/3`` and
``a_n ~ 3/(2n)`` (docs/mathematics.md#convergence): the amplitudes, and with them the displacement
amplitudes ``~ a_n Fc/sigma``, decay algebraically in the number of reversals, not
geometrically, and the potential energy at the reversals like ``9 Fc^2/(8 sigma n^2)``.
Starting point ``a_0 = 1`` (reversal from sliding). Universal: no sigma, Fc or m enters.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

A0 = 1.0  # |F|/Fc at the first reversal
N_REVERSALS = 10_000


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/beyond_convergence.png``.

    Returns
    -------
    dict
        ``n`` (1..N), ``a`` (``a_n = |F_n|/Fc`` after n reversals of the map from ``a_0``),
        ``law`` (``3/(2n)``), ``offset`` (``1/a_n - 2n/3``, bounded if the law holds),
        ``rel_dev`` (``a_n / (3/(2n)) - 1``), ``refined`` (the law with its corrections,
        :func:`prefriction.analysis.dahl.asymptotic_amplitude`, ``15 k/(10 k^2 - 1)`` with
        ``k = n + n0``), ``n0`` (its offset, fitted to the exact map); ``png``.
    """
    n_rev = 2_000 if quick else N_REVERSALS
    seq = np.asarray(dahl.amplitude_sequence(A0, n_rev), dtype=float)
    a = seq[1 : n_rev + 1] if seq.size > n_rev else seq
    n = np.arange(1, a.size + 1, dtype=float)
    law = 1.5 / n
    refined = np.asarray(dahl.asymptotic_amplitude(n, A0), dtype=float)
    # the refined law is a_n = 15 k/(10 k^2 - 1), k = n + n0: recover the offset n0 from its last value
    k_last = (15.0 + np.sqrt(225.0 + 40.0 * refined[-1] ** 2)) / (20.0 * refined[-1])
    n0 = float(k_last - n[-1])
    offset = 1.0 / a - 2.0 * n / 3.0
    rel_dev = a / law - 1.0

    fig, axes = new_figure(1, 2, size=(11.5, 4.4), sharex=True)
    ax = axes[0, 0]
    ax.loglog(n, a, color=COLORS[0], lw=2.0, label=r"exact map: $a_n = |F_n|/F_c$")
    ax.loglog(n, law, color=COLORS[3], ls="--", lw=1.3, label=r"asymptotic law $3/(2n)$")
    ax.loglog(n, refined, color=COLORS[1], ls=":", lw=1.6,
              label=r"with corrections: $15k/(10k^2 - 1)$," "\n"
                    rf"$k = n + n_0$, $n_0$ = {n0:.3f} (fitted where $a_n < 0.005$)")
    ax.set_xlabel("number of reversals $n$ [-]")
    ax.set_ylabel(r"reversal amplitude $|F_n|/F_c$ [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=9)
    ax.set_title(f"amplitudes over {a.size:,} reversals")

    ax = axes[0, 1]
    ax.semilogx(n, offset, color=COLORS[0], lw=1.8, label="exact map")
    ax.semilogx(n, 1.0 / refined - 2.0 * n / 3.0, color=COLORS[1], ls=":", lw=1.6,
                label=r"with corrections, $15k/(10k^2 - 1)$")
    ax.legend(loc="lower right", fontsize=9)
    ax.set_xlabel("number of reversals $n$ [-]")
    ax.set_ylabel(r"$1/a_n - 2n/3$ [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(r"offset from the law: $a_n = 1/(2n/3 + C_n)$, $C_n$ bounded")
    ax.annotate(f"n = {a.size:,}: C = {offset[-1]:.5f},\n"
                rf"$a_n/(3/(2n)) - 1$ = {rel_dev[-1]:.2e}",
                xy=(n[-1], offset[-1]), xytext=(0.35, 0.35), textcoords="axes fraction", fontsize=9,
                arrowprops=dict(arrowstyle="->", color="0.4"))
    add_note(fig, f"a_0 = {A0:g} (reversal from sliding). Universal in normalised units: "
                  "no sigma, Fc or m enters the map.")
    png = save(fig, outdir, "beyond_convergence.png")
    return {"n": n, "a": a, "law": law, "refined": refined, "offset": offset, "rel_dev": rel_dev,
            "n0": n0, "a0": A0, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
