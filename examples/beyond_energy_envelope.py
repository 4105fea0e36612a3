"""Beyond the paper: the energy envelope of Figure 7 against the ``t^-2`` law.

After ``n`` reversals the amplitude is ``a_n ~ 3/(2n)``, so the energy at the reversals is
``E_p ~ 9 Fc^2 / (8 sigma n^2)``, and small half-cycles last ``pi sqrt(m/sigma)`` (the linear
pre-sliding spring). Hence ``t_n ~ n pi sqrt(m/sigma)`` and the envelope decays like
``E ~ 9 pi^2 m Fc^2 / (8 sigma^2 t^2)``: algebraically in time, neither exponential (viscous)
nor finite-time (Coulomb). The figure shows the reversal energies of the Figure 7 simulations
(markers) and of the exact reference :func:`prefriction.exact_reversals` over many more
reversals (lines) against this law, and the two ingredients of the law separately.
Parameters as in Figure 7: ``m = 1 kg``, ``Fc = 1 N``, ``v(0) = 0.1 m/s``, ``x(0) = F(0) = 0``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import Dahl, Oscillator, exact_reversals, simulate
from prefriction.plotting import COLORS, add_note, new_mosaic, save

MASS = 1.0  # [kg]
FC = 1.0  # [N]
V0 = 0.1  # [m/s]
RATIOS = (10.0, 100.0, 1000.0)  # sigma/Fc [1/m], as in Figure 7
T_SIM = 10.0  # simulated time [s], as in Figure 7
N_EXACT = 3000  # reversals of the exact reference


def law(t: np.ndarray, sigma: float) -> np.ndarray:
    """Asymptotic envelope ``9 pi^2 m Fc^2 / (8 sigma^2 t^2)`` [J] at time ``t`` [s]."""
    return 9.0 * np.pi**2 * MASS * FC**2 / (8.0 * sigma**2 * np.asarray(t, dtype=float) ** 2)


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/beyond_energy_envelope.png``.

    Returns
    -------
    dict
        ``exact[ratio]`` and ``sim[ratio]`` with reversal times ``t`` [s] and energies ``E_p`` [J];
        ``exact[ratio]`` also ``n2E`` (``n^2 E_p sigma/Fc^2``, -> 9/8) and ``half`` (half-cycle
        durations over ``pi sqrt(m/sigma)``, -> 1); ``law_product`` (``9 pi^2 m Fc^2/8`` [kg N^2],
        the limit of ``sigma^2 t_n^2 E_p``); ``png``.
    """
    n_exact = 300 if quick else N_EXACT
    t_sim = 2.0 if quick else T_SIM
    fig, axes = new_mosaic("AB;AC", size=(12.0, 6.0))
    ax_e, ax_n, ax_h = axes["A"], axes["B"], axes["C"]
    ax_h.sharex(ax_n)
    exact, sim = {}, {}
    for color, ratio in zip(COLORS, RATIOS):
        sigma = ratio * FC
        system = Oscillator(Dahl(sigma=sigma, Fc=FC), mass=MASS)
        ref = exact_reversals(system, V0, n_exact)
        run = simulate(system, V0, t_end=t_sim).reversals
        n = np.arange(1, len(ref.t) + 1, dtype=float)
        half = np.diff(np.asarray(ref.t)) / (np.pi * np.sqrt(MASS / sigma))
        exact[ratio] = {"t": np.asarray(ref.t), "E_p": np.asarray(ref.E_p),
                        "n2E": n**2 * np.asarray(ref.E_p) * sigma / FC**2, "half": half}
        sim[ratio] = {"t": np.asarray(run.t), "E_p": np.asarray(run.E_p)}
        label = rf"$\sigma/F_c$ = {ratio:g} m$^{{-1}}$"
        ax_e.loglog(ref.t, ref.E_p, color=color, lw=1.5, label=f"exact, {label}")
        ax_e.loglog(run.t, run.E_p, "o", color=color, ms=3, mfc="none")
        tt = np.geomspace(ref.t[0], ref.t[-1], 50)
        ax_e.loglog(tt, law(tt, sigma), "--", color="k", lw=1.0)
        ax_n.semilogx(n, exact[ratio]["n2E"], color=color, lw=1.5, label=label)
        ax_h.loglog(n[1:], half - 1.0, color=color, lw=1.5, label=label)
    ax_e.plot([], [], "ko", ms=3, mfc="none", label="simulated (the runs of Fig. 7)")
    ax_e.plot([], [], "k--", lw=1.0, label=r"$9\pi^2 m F_c^2/(8\sigma^2 t^2)$")
    ax_e.set_xlabel("time of the reversal $t_n$ [s]")
    ax_e.set_ylabel(r"potential energy at the reversal $E_p$ [J]")
    ax_e.grid(True, which="both", alpha=0.3)
    ax_e.legend(loc="lower left", fontsize=8)
    ax_e.set_title(r"(a) reversal energies against the $t^{-2}$ law", fontsize=11)
    ax_n.axhline(9.0 / 8.0, color="k", ls="--", lw=1.0, label="limit 9/8")
    ax_n.set_ylim(0.0, 1.25)
    ax_n.set_ylabel(r"$n^2 E_p\,\sigma/F_c^2$ [-]")
    ax_n.grid(True, which="both", alpha=0.3)
    ax_n.legend(loc="lower right", fontsize=8)
    ax_n.set_title(r"(b) energy against reversal number: $E_p \to 9F_c^2/(8\sigma n^2)$", fontsize=11)
    ax_n.tick_params(labelbottom=False)
    ax_h.set_xlabel("reversal number $n$ [-]")
    ax_h.set_ylabel(r"$T_n/(\pi\sqrt{m/\sigma}) - 1$ [-]")
    ax_h.grid(True, which="both", alpha=0.3)
    ax_h.legend(loc="lower left", fontsize=8)
    ax_h.set_title(r"(c) half-cycle duration $T_n \to \pi\sqrt{m/\sigma}$ (linear spring)", fontsize=11)
    add_note(fig, f"m = {MASS:g} kg, Fc = {FC:g} N, x(0) = 0, F(0) = 0, v(0) = {V0:g} m/s (as in Fig. 7); "
                  f"exact reference over {n_exact:,} reversals.")
    png = save(fig, outdir, "beyond_energy_envelope.png")
    return {"exact": exact, "sim": sim, "law_product": 9.0 * np.pi**2 * MASS * FC**2 / 8.0,
            "mass": MASS, "Fc": FC, "v0": V0, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
