"""Beyond the paper: the unforced oscillator with Maxwell-slip friction, beside Dahl.

Two Maxwell-slip models with three elements each and a Dahl model (gamma = 1) share the rest
stiffness ``sigma = sum k_i = 1e5 N/m`` and the sliding force ``Fc = sum W_i = 1 N``; the mass is
1 kg and every run starts at ``x = 0``, ``F = 0`` with ``v0 = 2.2 Fc / sqrt(m sigma)`` (the
Maxwell-slip models reach gross sliding in the first excursion).

- ``maxwell_slip_loops.png``: force-displacement curves from ``prefriction.simulate(...,
  dense=True)`` with the virgin curve, reversals marked. Maxwell-slip branches are the virgin
  curve stretched by 2 (Masing rule), piecewise linear.
- ``maxwell_slip_decay.png``: reversal amplitudes over the reversals and the potential energy
  at the reversals over time, from the exact references (``maxwell_slip_reversals``,
  ``prefriction.exact_reversals``), and the distance of the amplitude from its limit.
  ``kappa_1 = 0.6 > 1/2`` (stiff weakest elements): dissipation stops after 3 half-cycles, then
  an undamped oscillation; ``kappa_1 = 0.3 < 1/2``: the weakest element slips in every
  half-cycle and ``a_n - a_inf`` falls by ``1 - 2 kappa_1 = 0.4`` per half-cycle; Dahl:
  ``a_n ~ 3 / (2 n)``, ``E_p ~ t^-2`` (docs/mathematics.md#convergence).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import prefriction as pf
from prefriction.analysis.maxwell_slip_exact import dissipation_limit, maxwell_slip_reversals
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 1.0  # [kg]
MODELS = {
    "stiff weakest elements": ([6e4, 3e4, 1e4], [0.3, 0.4, 0.3]),  # kappa_1 = 0.6
    "soft weakest element": ([3e4, 2e4, 5e4], [0.3 / 1.8, 0.5 / 1.8, 1.0 / 1.8]),  # kappa_1 = 0.3
}
V0N = 2.2  # initial speed in units of Fc / sqrt(m sigma): both Maxwell-slip models reach Fc


def _systems() -> dict:
    out = {name: pf.Oscillator(pf.MaxwellSlip(k, W), mass=MASS) for name, (k, W) in MODELS.items()}
    out["Dahl"] = pf.Oscillator(pf.Dahl(1e5, 1.0), mass=MASS)
    return out


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/maxwell_slip_loops.png`` and ``outdir/maxwell_slip_decay.png``.

    Parameters
    ----------
    outdir : str or Path
        Output directory (created if needed).
    quick : bool, default False
        Fewer reversals (for tests).

    Returns
    -------
    dict
        ``tables[name]`` (reversal tables of the exact references, SI), ``loops[name]``
        (``x``, ``F`` samples [m, N] of the simulated loops), ``limits[name]``
        (:class:`~prefriction.analysis.maxwell_slip_exact.DissipationLimit`), ``png`` (the decay
        figure) and ``pngs`` (both).
    """
    systems = _systems()
    sc = pf.Scales.of(systems["Dahl"])  # the same units for all three
    v0 = V0N * sc.v
    n_loop = 8
    n_decay = 60 if quick else 400
    colors = {name: c for name, c in zip(systems, (COLORS[0], COLORS[2], COLORS[3]))}

    # ------------------------------------------------------------------ loops (simulated)
    loops = {}
    fig, axes = new_figure(1, 3, size=(13.0, 4.4), sharey=True)
    for ax, (name, sys_) in zip(axes[0], systems.items()):
        res = pf.simulate(sys_, v0, reversals=n_loop, rtol=1e-10, dense=True)
        x, F = res.x * 1e6, res.F
        loops[name] = {"x": res.x, "F": res.F}
        ax.plot(x, F, color=colors[name], lw=1.3, label="trajectory (simulate)")
        tab = res.reversals
        ax.plot(tab.x * 1e6, tab.F, "o", color="k", ms=3.5, label=f"first {n_loop} reversals")
        xv = np.linspace(-1.2, 1.2, 400) * max(np.max(np.abs(res.x)), 1e-12)
        if isinstance(sys_.friction, pf.MaxwellSlip):
            Fv = sys_.friction.virgin_curve(xv)
            lim = dissipation_limit(sys_.friction)
            title = f"Maxwell-slip, {name}\n" + rf"$\kappa_1$ = {lim.kappa_1:.1f}, slip deflections " + \
                ", ".join(f"{d * 1e6:.3g}" for d in np.sort(sys_.friction.slip_deflections)) + r" $\mu$m"
        else:
            Fv = np.sign(xv) * sys_.friction.Fc * -np.expm1(-np.abs(xv) * sys_.friction.sigma / sys_.friction.Fc)
            title = "Dahl (gamma = 1)\n" + r"$\sigma$ = 1e5 N/m, $F_c$ = 1 N"
        ax.plot(xv * 1e6, Fv, color="0.35", ls="--", lw=1.0, label="virgin curve")
        ax.axhline(1.0, color="0.6", lw=0.7, ls=":")
        ax.axhline(-1.0, color="0.6", lw=0.7, ls=":")
        ax.set_xlabel(r"displacement $x$ [$\mu$m]")
        ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    axes[0, 0].set_ylabel("friction force $F$ [N]")
    axes[0, 0].set_ylim(-1.25, 1.25)
    add_note(fig, f"m = {MASS:g} kg, sigma = sum k_i = 1e5 N/m, Fc = sum W_i = 1 N for all three; "
                  f"start at x = 0, F = 0 with v0 = {v0 * 1e3:.3g} mm/s. Dotted: +-Fc.")
    png_loops = save(fig, outdir, "maxwell_slip_loops.png")

    # ------------------------------------------------------------------ decay (exact references)
    tables, limits = {}, {}
    for name, sys_ in systems.items():
        if isinstance(sys_.friction, pf.MaxwellSlip):
            tables[name] = maxwell_slip_reversals(sys_, v0, n_decay)
            limits[name] = dissipation_limit(sys_.friction)
        else:
            tables[name] = pf.exact_reversals(sys_, v0, n_decay)
    fig, axes = new_figure(1, 3, size=(14.0, 4.6))
    n = np.arange(1, n_decay + 1)
    ax = axes[0, 0]
    for name, tab in tables.items():
        ax.loglog(n, np.abs(tab.F), color=colors[name], lw=1.6, label=name if name == "Dahl" else f"Maxwell-slip, {name}")
        if name in limits:
            ax.axhline(limits[name].force, color=colors[name], lw=0.9, ls=":")
    ax.loglog(n, 1.5 / n, color="0.3", ls="--", lw=1.0, label=r"Dahl law $3/(2n)$")
    ax.set_xlabel("reversal number $n$ [-]")
    ax.set_ylabel(r"reversal amplitude $|F_n|$ [N]")
    ax.set_title("amplitudes over reversals\n" + r"(dotted: $\sigma\,\mathrm{min}(W_i/k_i)$, undamped below)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)

    ax = axes[0, 1]
    for name, tab in tables.items():
        ax.loglog(tab.t, tab.E_p * 1e6, color=colors[name], lw=1.6,
                  label=name if name == "Dahl" else f"Maxwell-slip, {name}")
    t = tables["Dahl"].t
    law = 9.0 * np.pi**2 / 8.0 * sc.E * sc.t**2 / t**2  # E ~ (9 pi^2/8) (Fc^2/sigma)(m/sigma)/t^2
    ax.loglog(t, law * 1e6, color="0.3", ls="--", lw=1.0, label=r"Dahl law $\propto t^{-2}$")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel(r"potential energy at reversals $E_p$ [$\mu$J]")
    ax.set_title("energy over time", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)

    ax = axes[0, 2]
    m_show = min(40, n_decay)
    for name, tab in tables.items():
        if name not in limits:
            continue
        a = np.abs(tab.F[:m_show])
        excess = a - limits[name].force
        pos = excess > 0
        ax.semilogy(n[:m_show][pos], excess[pos], "o-", color=colors[name], ms=3, lw=1.2,
                    label=f"Maxwell-slip, {name}: " + rf"$\kappa_1$ = {limits[name].kappa_1:.1f}")
        if not np.all(pos):
            k = int(np.argmin(pos))
            ax.annotate(f"{name}: below the limit from\nreversal {k + 1} on: no slip, undamped",
                        xy=(n[k - 1], excess[k - 1]), xytext=(14, 1e-3), color=colors[name],
                        fontsize=8, arrowprops=dict(arrowstyle="-|>", color="0.45", lw=0.6, ls=":",
                                                    shrinkA=2, shrinkB=4, mutation_scale=8))
        else:
            ratio = 1.0 - 2.0 * limits[name].kappa_1
            ref = excess[10] * ratio ** (n[:m_show] - n[10])
            ax.semilogy(n[:m_show], ref, color="0.3", ls="--", lw=1.0,
                        label=rf"ratio $1 - 2\kappa_1$ = {ratio:.1f} per half-cycle")
    ax.set_xlabel("reversal number $n$ [-]")
    ax.set_ylabel(r"$|F_n| - \sigma\,\mathrm{min}(W_i/k_i)$ [N]")
    ax.set_title("approach to the undamped limit", fontsize=10)
    ax.set_ylim(1e-17, 5.0)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    add_note(fig, "Exact references: maxwell_slip_reversals (event-by-event closed form) and exact_reversals (Dahl). "
                  "Maxwell-slip dissipates only while elements slip; a reversal at |F| <= sigma min W_i/k_i is followed "
                  "by an undamped oscillation of stiffness sigma.", lines=1)
    png = save(fig, outdir, "maxwell_slip_decay.png")
    return {"tables": tables, "loops": loops, "limits": limits, "png": png, "pngs": [png_loops, png]}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print("\n".join(str(p) for p in main(outdir, quick=quick)["pngs"]))
