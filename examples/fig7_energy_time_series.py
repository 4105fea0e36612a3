"""Figure 7 of the paper: energy time series of the simulated oscillator (2.1) with (3.4).

The unforced oscillator ``m x'' + F = 0`` with Dahl friction (gamma = 1) is simulated by
:func:`prefriction.simulate` for sigma/Fc in {10, 100, 1000} 1/m. The paper states neither the
mass nor the initial state; we take ``m = 1 kg`` (the paper's unity mass), ``Fc = 1 N``,
``x(0) = 0``, ``F(0) = 0`` and ``v(0) = 0.1 m/s`` (so the first excursion reaches
``sigma m v0^2/(2 Fc^2)`` = 0.05, 0.5 and 5 in units of ``Fc^2/sigma``: the larger sigma/Fc, the
deeper the first excursion slides). ``E_f`` is the work of the restoring force by integrated
power (2.8), counted from the last reversal as in (2.8)-(2.9); between two reversals
``E_k + E_f`` is constant. Markers: the potential energy (3.9) of each reversal, which the
kinetic energy must reach at the next force zero crossing.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from matplotlib.lines import Line2D

from prefriction import Dahl, Oscillator, dahl, simulate
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 1.0  # [kg], the paper's unity mass
FC = 1.0  # [N]; not stated in the paper
V0 = 0.1  # initial velocity [m/s]; not stated in the paper
RATIOS = (10.0, 100.0, 1000.0)  # sigma/Fc [1/m]; the paper shows "different" ratios
T_END = 10.0  # [s]


def energy_since_reversal(t: np.ndarray, E_f: np.ndarray, t_rev: np.ndarray) -> np.ndarray:
    """Restoring-force work (2.8) counted from the most recent reversal before each sample.

    ``E_f`` at a reversal is interpolated linearly; exact when the reversal times are samples.
    """
    idx = np.searchsorted(t_rev, t, side="right") - 1
    base = np.where(idx >= 0, np.interp(t_rev[np.maximum(idx, 0)], t, E_f), 0.0)
    return E_f - base


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Simulate and draw Figure 7 into ``outdir/fig7_energy_time_series.png``.

    Returns
    -------
    dict
        ``runs[ratio]`` with dense ``t`` [s], ``E_k``, ``E_f`` (since t = 0), ``E_f_half``
        (since the last reversal) [J], ``t_rev``, ``F_rev`` (reversal times [s] and forces [N]),
        ``E_p_rev`` ((3.9) at each reversal [J]), ``E_k_peak`` (largest sampled ``E_k`` between
        reversal k and k+1 [J], one fewer than the reversals), ``balance`` (max ``|E_k + E_f - E_k(0)| / E_k(0)``);
        ``mass``, ``v0``, ``t_end``; ``png``.
    """
    t_end = 3.0 if quick else T_END
    fig, axes = new_figure(len(RATIOS), 1, size=(8.0, 7.5), sharex=True)
    runs: dict[float, dict] = {}
    for ax, color, ratio in zip(axes[:, 0], COLORS, RATIOS):
        system = Oscillator(Dahl(sigma=ratio * FC, Fc=FC), mass=MASS)
        t_rev = simulate(system, V0, t_end=t_end).reversals.t  # sample the reversals exactly
        grid = np.union1d(np.linspace(0.0, t_end, int(t_end * (1000 if quick else 4000)) + 1), t_rev)
        res = simulate(system, V0, t_end=t_end, dense=grid)
        t, E_k, E_f = res.t, res.E_k, res.E_f
        rev = res.reversals
        E_f_half = energy_since_reversal(t, E_f, rev.t)
        E_p_rev = np.asarray(dahl.potential_energy(-np.abs(rev.F), ratio * FC, FC), dtype=float)
        peaks, t_peak = [], []  # largest sampled E_k in each complete half-cycle
        for t0, t1 in zip(rev.t[:-1], rev.t[1:]):
            inside = np.flatnonzero((t > t0) & (t < t1))
            j = inside[np.argmax(E_k[inside])]
            peaks.append(float(E_k[j]))
            t_peak.append(float(t[j]))
        E_k0 = 0.5 * MASS * V0**2
        runs[ratio] = {
            "t": t, "E_k": E_k, "E_f": E_f, "E_f_half": E_f_half, "t_rev": np.asarray(rev.t),
            "F_rev": np.asarray(rev.F), "E_p_rev": E_p_rev, "E_k_peak": np.asarray(peaks),
            "balance": float(np.max(np.abs(E_k + E_f - E_k0)) / E_k0),
        }
        floor = 1e-7 * E_k0
        ax.semilogy(t, np.maximum(E_k, floor), color=color, lw=1.2, label=r"kinetic $E_k = m\dot x^2/2$")
        ax.semilogy(t, np.maximum(np.abs(E_f_half), floor), color="k", lw=0.7, ls="--",
                    label=r"$|E_f|$: restoring-force work (2.8) since the last reversal")
        ax.plot(t_peak, E_p_rev[: len(t_peak)], "o", color="k", ms=4, mfc="none",
                label=r"$E_p$ (3.9) of the preceding reversal")
        ax.set_ylim(0.5 * floor, 2.0 * E_k0)  # the data's range
        ax.set_ylabel("energy [J]")
        ax.set_title(rf"$\sigma/F_c$ = {ratio:g} m$^{{-1}}$: {len(rev.t)} reversals in {t_end:g} s", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    handles[0] = Line2D([], [], color="0.35", lw=1.2)
    labels[0] = r"kinetic $E_k = m\dot x^2/2$ (colour of the panel)"
    axes[0, 0].set_ylim(0.5 * floor, 5e3 * E_k0)  # one legend, in the top panel only
    axes[0, 0].legend(handles, labels, loc="upper right", ncol=2, fontsize=7.5)
    axes[-1, 0].set_xlabel("time $t$ [s]")
    axes[-1, 0].set_xlim(0.0, t_end)
    fig.suptitle("Fig. 7: energy time series of the simulated oscillator (2.1) with (3.4)")
    add_note(fig, rf"$m$ = {MASS:g} kg, $F_c$ = {FC:g} N, $x(0) = 0$, $F(0) = 0$, $v(0)$ = {V0:g} m/s "
                  r"(mass and initial state not stated in the paper); $\gamma = 1$.")
    png = save(fig, outdir, "fig7_energy_time_series.png")
    return {"runs": runs, "mass": MASS, "v0": V0, "Fc": FC, "t_end": t_end, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
