"""Beyond the paper: hysteresis loops of the oscillator for gamma in {0, 0.5, 1, 2}.

The paper analyses gamma = 1 only. The same oscillator (2.1) with the Dahl model (3.2) is
simulated for four shape factors from the same initial state, deep enough to slide first:
``m = 1 kg``, ``sigma = 1 N/m``, ``Fc = 1 N``, ``x(0) = 0``, ``F(0) = 0``, ``v(0) = 1.5 m/s``
(first excursion energy ``1.125 Fc^2/sigma``). gamma = 0 is the Prandtl stop: after the first
saturation it oscillates between ``-Fc`` and ``+Fc`` along a straight line for ever (no loop,
no dissipation: the equality case of the bound (2.12), ``E_p = Fc^2/(2 sigma)``). gamma < 1
saturates at a finite distance, gamma >= 1 only asymptotically; the larger gamma, the faster
the branch bends and the more each half-cycle dissipates.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import Dahl, Oscillator, simulate
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 1.0  # [kg]
SIGMA = 1.0  # [N/m]
FC = 1.0  # [N]
V0 = 1.5  # [m/s]
GAMMAS = (0.0, 0.5, 1.0, 2.0)
N_REVERSALS = 12


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Simulate and draw ``outdir/beyond_gamma_loops.png``.

    Returns
    -------
    dict
        ``runs[gamma]`` with dense ``t`` [s], ``x`` [m], ``F`` [N], ``v`` [m/s] and the reversal
        table's ``t_rev``, ``x_rev``, ``F_rev``, ``E_p`` [J], ``E_d`` [J]; ``png``.
    """
    n_rev = 6 if quick else N_REVERSALS
    fig, axes = new_figure(2, 2, size=(10.0, 7.5), sharex=True, sharey=True)
    runs: dict[float, dict] = {}
    for ax, color, gamma in zip(axes.flat, COLORS, GAMMAS):
        system = Oscillator(Dahl(sigma=SIGMA, Fc=FC, gamma=gamma), mass=MASS)
        t_rev = simulate(system, V0, reversals=n_rev).reversals.t
        grid = np.union1d(np.linspace(0.0, t_rev[-1], 600 if quick else 3000), t_rev)
        res = simulate(system, V0, reversals=n_rev, dense=grid)
        rev = res.reversals
        runs[gamma] = {
            "t": res.t, "x": res.x, "F": res.F, "v": res.v, "t_rev": np.asarray(rev.t),
            "x_rev": np.asarray(rev.x), "F_rev": np.asarray(rev.F), "E_p": np.asarray(rev.E_p),
            "E_d": np.asarray(rev.E_d),
        }
        ax.plot(res.x, res.F, color=color, lw=1.3, label=rf"$\gamma$ = {gamma:g}, simulated")
        ax.plot(rev.x, rev.F, "o", color="k", ms=3, label="reversals")
        ax.axhline(FC, color="0.6", lw=0.8, ls=":", label=r"$\pm F_c$")
        ax.axhline(-FC, color="0.6", lw=0.8, ls=":")
        ax.set_title(rf"$\gamma$ = {gamma:g}: $E_p$ = {rev.E_p[-1]:.2e} J after {n_rev} reversals", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("displacement $x$ [m]")
    for ax in axes[:, 0]:
        ax.set_ylabel("friction force $F$ [N]")
    axes[0, 0].set_ylim(-1.2 * FC, 1.65 * FC)  # room for the legends above +Fc
    fig.suptitle(r"Force-displacement loops of the oscillator (2.1), Dahl model (3.2), shape factor $\gamma$")
    add_note(fig, f"m = {MASS:g} kg, sigma = {SIGMA:g} N/m, Fc = {FC:g} N, x(0) = 0, F(0) = 0, v(0) = {V0:g} m/s; "
                  f"{n_rev} reversals each (simulated).")
    png = save(fig, outdir, "beyond_gamma_loops.png")
    return {"runs": runs, "mass": MASS, "sigma": SIGMA, "Fc": FC, "v0": V0, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
