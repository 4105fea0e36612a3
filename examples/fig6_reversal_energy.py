"""Figure 6 of the paper: potential energy at consecutive reversals, sigma/Fc in {10, 100, 1000}.

(a) The paper's figure: starting from the reversal of largest energy, ``F_i = -Fc``
(``E_p = 0.3069 Fc^2/sigma``; the paper does not state its starting point), the exact reversal
map gives ``|F_{i+n}|/Fc`` and (3.14) the potential energy ``E_p(i+n)``; ``Fc = 1 N`` (not
stated). Dashed: the asymptotic law ``9 Fc^2 / (8 sigma n^2)`` (docs/mathematics.md#convergence).

(b) The same in normalised units ``E_p sigma/Fc^2``, where the exact sequence is one curve for
every sigma/Fc, against the recursion the paper proposes, (3.13) then (3.14): with (3.13)
corrected it decays geometrically (ratio of amplitudes -> 5/6), with (3.13) as printed it
collapses hyperexponentially and depends on sigma/Fc. The paper reads an exponential drop; the
exact drop is algebraic, ``~ n^-2``, and the ratio of consecutive energies tends to 1.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

FC = 1.0  # Coulomb force [N]; not stated in the paper
RATIOS = (10.0, 100.0, 1000.0)  # sigma/Fc [1/m], as in the paper
A0 = 1.0  # |F_i|/Fc at the first reversal; not stated in the paper
N_REVERSALS = 20  # reversals after the first; not stated in the paper
Y_MIN = 1e-12  # lower limit of panel (b)


def iterate(step, a0: float, n: int) -> np.ndarray:
    """``[a0, step(a0), step(step(a0)), ...]``, ``n + 1`` amplitudes."""
    out = np.empty(n + 1)
    out[0] = a0
    for k in range(n):
        out[k + 1] = float(step(out[k]))
    return out


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw Figure 6 into ``outdir/fig6_reversal_energy.png``.

    Returns
    -------
    dict
        ``n`` (0..N, reversal index after ``i``), ``amplitudes`` (``|F_{i+n}|/Fc``, exact map),
        ``E_p`` (dict ratio -> energies [J]), ``law`` (dict ratio -> ``9 Fc^2/(8 sigma n^2)``
        [J], n >= 1), ``ratio_consecutive`` (``E_p(n+1)/E_p(n)``, the same for every sigma),
        ``amplitudes_corrected_313`` and ``amplitudes_printed_313`` (dict ratio -> sequence) of
        the paper's recursion; ``png``.
    """
    n_rev = 8 if quick else N_REVERSALS
    amplitudes = np.asarray(dahl.amplitude_sequence(A0, n_rev), dtype=float)[: n_rev + 1]
    n = np.arange(amplitudes.size)
    fig, axes = new_figure(1, 2, size=(11.5, 4.6), sharex=True)
    ax = axes[0, 0]
    energies, laws = {}, {}
    for color, ratio in zip(COLORS, RATIOS):
        sigma = ratio * FC
        e_p = np.asarray(dahl.potential_energy(-amplitudes * FC, sigma, FC), dtype=float)
        law = 9.0 * FC**2 / (8.0 * sigma * n[1:] ** 2.0)
        energies[ratio], laws[ratio] = e_p, law
        ax.semilogy(n, e_p, "o-", color=color, ms=4, label=rf"$\sigma/F_c$ = {ratio:g} m$^{{-1}}$")
        ax.semilogy(n[1:], law, "--", color=color, lw=1.0)
    ax.plot([], [], "k--", lw=1.0, label=r"$9F_c^2/(8\sigma n^2)$ (asymptotic)")
    ax.set_xlabel(r"reversal number $n$ after reversal $i$ [-]")
    ax.set_ylabel(r"potential energy $E_p(i+n)$ (3.14) [J]")
    ax.set_xticks(n[:: 2 if n_rev > 10 else 1])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper right", fontsize=9)
    ax.set_title("(a) exact reversal map")

    ax = axes[0, 1]
    normalised = amplitudes - np.log1p(amplitudes)  # E_p sigma/Fc^2, (3.9)
    corrected = iterate(dahl.next_amplitude_paper, A0, n.size - 1)
    ax.semilogy(n, normalised, "ko-", ms=4, lw=2.0, label="exact map (every $\\sigma/F_c$)")
    with np.errstate(divide="ignore"):
        ax.semilogy(n, corrected - np.log1p(corrected), "s--", color="0.45", ms=3,
                    label="paper's recursion, corrected (3.13)")
        printed = {ratio: iterate(lambda a, r=ratio: dahl.next_amplitude_paper(a, sigma_over_Fc=r), A0, n.size - 1)
                   for ratio in RATIOS}
        e_printed = {ratio: seq - np.log1p(seq) for ratio, seq in printed.items()}
    # (3.13) as printed, one line per sigma/Fc, drawn while it stays on the axis; an arrow where it leaves
    for (ratio, e), color, mark in zip(e_printed.items(), ("#d62728", "#8c1d40", "#ff7f0e"), ("^", "v", "D")):
        on = np.flatnonzero(e >= Y_MIN)
        last = int(on[-1]) if on.size else 0
        ax.semilogy(n[: last + 1], e[: last + 1], "-", marker=mark, color=color, lw=1.0, ms=5, mfc="white",
                    label=rf"(3.13) as printed, $\sigma/F_c$ = {ratio:g} m$^{{-1}}$")
        if last + 1 < n.size:  # falls below the axis after reversal n[last]
            ax.annotate("", xy=(n[last] + 0.35, Y_MIN), xytext=(n[last], e[last]),
                        arrowprops=dict(arrowstyle="->", color=color, lw=1.0))
    ax.set_ylim(Y_MIN, 1.0)
    ax.set_xticks(n[:: 2 if n_rev > 10 else 1])
    ax.set_xlabel(r"reversal number $n$ after reversal $i$ [-]")
    ax.set_ylabel(r"normalised potential energy $E_p\,\sigma/F_c^2$ [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right", fontsize=8, title=r"arrows: below $10^{-12}$ next", title_fontsize=8)
    ax.set_title("(b) exact map against the paper's recursion")
    fig.suptitle("Fig. 6: potential energy at consecutive reversals")
    add_note(fig, rf"$F_c$ = {FC:g} N, first reversal at $F_i = -F_c$ (both not stated in the paper).")
    png = save(fig, outdir, "fig6_reversal_energy.png")
    first = energies[RATIOS[0]]
    return {
        "n": n, "amplitudes": amplitudes, "E_p": energies, "law": laws,
        "ratio_consecutive": first[1:] / first[:-1], "amplitudes_corrected_313": corrected,
        "amplitudes_printed_313": printed, "Fc": FC, "png": png,
    }


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
