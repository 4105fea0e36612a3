"""Beyond the paper: the figure set of the paper for every model, beside Dahl.

Four friction models share the rest stiffness ``sigma = 1e5 N/m`` and the Coulomb force
``Fc = 1 N``; the mass is 1 kg. Every run releases the mass from rest at ``x = 0`` with the
friction force ``F0 = 0.9 Fc`` (so the first sample is exact for the rate-dependent models too).

- Dahl, gamma = 1 (paper (3.2));
- Maxwell-slip, three elements ``k = (6, 3, 1) 1e4 N/m``, ``W = (0.3, 0.4, 0.3) N``;
- GMS (Al-Bender et al. 2005) with the same elements (``alpha = W / Fc``), Stribeck force
  ``Fs = 1.5 N``, ``vs = 1 mm/s``, ``C = 2e3 N/s``: rate-dependent;
- LuGre (Canudas de Wit et al. 1995, Table I): ``sigma1 = sqrt(1e5) N s/m``, ``sigma2 = 0.4 N s/m``,
  ``Fs = 1.5 N``, ``vs = 1 mm/s``.

Figures:

- ``model_loops.png``: force-displacement loops (``prefriction.simulate(..., dense=True)``);
- ``model_decay.png``: reversal amplitudes ``|F_n|`` over the reversals and over time, with
  Dahl's laws ``3/(2n)`` and ``t^-1`` (docs/mathematics.md#convergence);
- ``model_lugre_energy.png``: LuGre's energy per half-cycle, viscous and hysteretic dissipation
  apart, and the balance over time (``prefriction.energy.analyze_samples``,
  docs/mathematics.md#lugre-energy).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

import prefriction as pf
from prefriction import energy
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 1.0  # [kg]
F0 = 0.9  # [N], released from rest
K = [6e4, 3e4, 1e4]  # [N/m]
W = [0.3, 0.4, 0.3]  # [N]


def systems() -> dict[str, pf.Oscillator]:
    """The four oscillators (name -> Oscillator)."""
    models = {
        "Dahl": pf.Dahl(1e5, 1.0),
        "Maxwell-slip": pf.MaxwellSlip(K, W),
        "GMS": pf.GMS(k=K, alpha=W, Fc=1.0, Fs=1.5, vs=1e-3, C=2e3),
        "LuGre": pf.LuGre(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3),
    }
    return {name: pf.Oscillator(m, mass=MASS) for name, m in models.items()}


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``model_loops.png``, ``model_decay.png`` and ``model_lugre_energy.png`` in ``outdir``.

    Parameters
    ----------
    outdir : str or Path
        Output directory (created if needed).
    quick : bool, default False
        Fewer reversals and samples, figures at 50 dpi instead of 130 (for tests).

    Returns
    -------
    dict
        ``tables[name]`` (reversal tables of ``simulate``, SI), ``loops[name]`` (``x``, ``F``
        samples), ``lugre`` (the :class:`prefriction.energy.LuGreEnergyReport`), ``png`` (the
        decay figure) and ``pngs`` (all three).
    """
    sys_ = systems()
    sc = pf.Scales.of(sys_["Dahl"])  # the same units for all four
    colors = dict(zip(sys_, (COLORS[0], COLORS[2], COLORS[1], COLORS[3])))
    n_rev = {"Dahl": 40 if quick else 300, "Maxwell-slip": 12, "GMS": 12, "LuGre": 12}
    dpi = 50 if quick else 130
    print("model_figures: simulating 4 models", file=sys.stderr)

    # ------------------------------------------------------------------ loops
    loops = {}
    fig, axes = new_figure(1, 4, size=(15.0, 4.3), sharey=True)
    for ax, (name, s) in zip(axes[0], sys_.items()):
        res = pf.simulate(s, 0.0, F0=F0, reversals=8, rtol=1e-10, dense=True)
        loops[name] = {"x": res.x, "F": res.F}
        ax.plot(res.x * 1e6, res.F, color=colors[name], lw=1.2, label="trajectory")
        ax.plot(res.reversals.x * 1e6, res.reversals.F, "o", color="k", ms=3, label="reversals")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel(r"displacement $x$ [$\mu$m]")
        ax.set_title(name + ("" if s.friction.rate_independent else " (rate-dependent)"), fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    axes[0, 0].set_ylabel("friction force $F$ [N]")
    add_note(fig, f"m = {MASS:g} kg, sigma = 1e5 N/m, Fc = 1 N for all; released from rest at x = 0, F0 = {F0:g} N; "
                  "first 8 reversals.")
    png_loops = save(fig, outdir, "model_loops.png", dpi=dpi)

    # ------------------------------------------------------------------ decay over reversals and time
    tables = {name: pf.simulate(s, 0.0, F0=F0, reversals=n_rev[name], rtol=1e-10).reversals for name, s in sys_.items()}
    fig, axes = new_figure(1, 2, size=(12.0, 4.6))
    for name, tab in tables.items():
        n = np.arange(1, len(tab) + 1)
        axes[0, 0].loglog(n, np.abs(tab.F), "o-", color=colors[name], ms=2.5, lw=1.2, label=name)
        axes[0, 1].loglog(tab.t, np.abs(tab.F), "o-", color=colors[name], ms=2.5, lw=1.2, label=name)
    n = np.arange(1, n_rev["Dahl"] + 1)
    axes[0, 0].loglog(n, 1.5 / n, color="0.3", ls="--", lw=1.0, label=r"Dahl law $3/(2n)$")
    t = tables["Dahl"].t
    axes[0, 1].loglog(t, 1.5 * math.pi * sc.t / t, color="0.3", ls="--", lw=1.0,
                      label=r"Dahl law $(3\pi/2)\sqrt{m/\sigma}/t$")
    for ax, xlabel, title in ((axes[0, 0], "reversal number $n$ [-]", "amplitudes over reversals"),
                              (axes[0, 1], "time $t$ [s]", "amplitudes over time")):
        ax.set_xlabel(xlabel)
        ax.set_ylabel(r"reversal amplitude $|F_n|$ [N]")
        ax.set_title(title, fontsize=10)
        ax.set_ylim(1e-14, 2.0)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="lower left", fontsize=8)
    add_note(fig, "Dahl decays algebraically; Maxwell-slip and GMS stop dissipating once no element slips "
                  "(undamped); LuGre's bristle damping (damping ratio 0.5 here) decays geometrically.")
    png = save(fig, outdir, "model_decay.png", dpi=dpi)

    # ------------------------------------------------------------------ LuGre energy split
    lugre = sys_["LuGre"]
    T = 4 * 2 * math.pi * sc.t
    res = pf.simulate(lugre, 0.0, F0=F0, t_end=T, dense=np.linspace(0.0, T, 800 if quick else 4000), rtol=1e-10)
    rep = energy.analyze_samples(res.t, res.x, res.v, res.F, system=lugre, method="simpson")
    fig, axes = new_figure(1, 2, size=(12.0, 4.6))
    ax = axes[0, 0]
    k = np.arange(0, len(rep))  # 0: first excursion, k: half-cycle from reversal k (ending at k + 1)
    vis, hys = rep.D_viscous, rep.D_hysteretic
    ax.semilogy(k, vis, "s-", color=COLORS[0], ms=4, label=r"viscous $\int(\sigma_1 z' + \sigma_2 v)\,v\,dt$")
    ax.semilogy(k, hys, "o-", color=COLORS[3], ms=4, label=r"hysteretic $\int \sigma_0^2 |v| z^2/g(v)\,dt$")
    ax.semilogy(k, np.concatenate(([rep.E_0], rep.E_p[:-1])), "--", color="0.3", lw=1.0,
                label=r"stored at the start, $E_0$ / $E_p(n)$")
    ax.set_xlabel("half-cycle $n$ (0: release to reversal 1) [-]")
    ax.set_ylabel("energy [J]")
    ax.set_title("LuGre: dissipation per half-cycle", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    ax = axes[0, 1]
    # cumulative dissipation along the samples: the powers of (1)-(3) with z from the samples
    f = lugre.friction
    z = energy.bristle_deflection(res.t, res.v, res.F, friction=f)
    g = f.Fc + (f.Fs - f.Fc) * np.exp(-(res.v / f.vs) ** 2)
    zd = res.v - f.sigma0 * np.abs(res.v) * z / g
    p_vis = (f.sigma1 * zd + f.sigma2 * res.v) * res.v
    p_hys = f.sigma0 ** 2 * np.abs(res.v) * z * z / g
    t_ms = res.t * 1e3
    ax.plot(t_ms, cumulative_trapezoid(p_vis, res.t, initial=0.0) * 1e6, color=COLORS[0], label="viscous, cumulative")
    ax.plot(t_ms, cumulative_trapezoid(p_hys, res.t, initial=0.0) * 1e6, color=COLORS[3], label="hysteretic, cumulative")
    ax.plot(t_ms, 0.5 * f.sigma0 * z * z * 1e6, color="0.55", lw=0.8, label=r"stored bristle energy $\sigma_0 z^2/2$")
    ends = np.concatenate(([res.t[0]], rep.t))
    ax.plot(ends * 1e3, np.concatenate(([0.0], np.cumsum(vis))) * 1e6, "s", color=COLORS[0], ms=4,
            label="viscous, at reversals (report)")
    ax.plot(ends * 1e3, np.concatenate(([0.0], np.cumsum(hys))) * 1e6, "o", color=COLORS[3], ms=4,
            label="hysteretic, at reversals (report)")
    ax.set_xlabel("time $t$ [ms]")
    ax.set_ylabel(r"energy [$\mu$J]")
    ax.set_title("LuGre: where the released energy goes", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="center right", fontsize=8)
    add_note(fig, f"E_0 = {rep.E_0 * 1e6:.4g} µJ; viscous {rep.total_viscous / rep.E_0:.1%}, hysteretic "
                  f"{rep.total_hysteretic / rep.E_0:.1%} of E_0; balance residual {rep.residual:.1e} (Simpson on "
                  f"{res.t.size} samples).")
    png_energy = save(fig, outdir, "model_lugre_energy.png", dpi=dpi)
    return {"tables": tables, "loops": loops, "lugre": rep, "png": png, "pngs": [png_loops, png, png_energy]}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print("\n".join(str(p) for p in main(outdir, quick=quick)["pngs"]))
