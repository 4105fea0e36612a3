"""Minimum-time move of a stage through pre-sliding friction, against the usual shortcuts.

A 1 kg stage with Dahl friction (sigma = 1e5 N/m, Fc = 1 N, pre-sliding range Fc/sigma = 10 µm)
must move by 1 mm under |u| <= 5 N and stop at rest with no friction force, so that no force
is needed to hold it there. ``prefriction.optimal.point_to_point`` solves the multi-phase
problem (one velocity sign per phase, the switching times free) with IPOPT; its force is
replayed through ``prefriction.simulate``. The same move planned with tanh-smoothed Coulomb
friction, and the Coulomb bang-bang profile, replayed through the same simulator, miss. A LuGre
stage (sigma1 = 300 N s/m, sigma2 = 0.4 N s/m, Fs = 1.5 N, vs = 1 mm/s) gets the same treatment.

Run: ``python examples/optimal_move.py [outdir]``; writes ``optimal_move.png`` and prints the table.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import prefriction as pf
from prefriction import optimal
from prefriction.plotting import COLORS, add_note, new_figure, save

DISTANCE, U_MAX = 1e-3, 5.0  # [m], [N]
DAHL = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)
LUGRE = pf.Oscillator(pf.LuGre(sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3), mass=1.0)
V_SMOOTH = (1e-3, 1e-4)  # [m/s] tanh smoothing velocities


def moves(stage: pf.Oscillator, *, effort: bool, smoothing: tuple = V_SMOOTH) -> dict:
    """The optimal, smoothed and bang-bang moves of ``stage`` (name -> PointToPointResult)."""
    out = {"pre-sliding, min time": optimal.point_to_point(stage, DISTANCE, u_max=U_MAX)}
    if effort:
        T = 1.3 * out["pre-sliding, min time"].t_final
        out["pre-sliding, min effort (1.3 T)"] = optimal.point_to_point(
            stage, DISTANCE, u_max=U_MAX, objective="effort", t_final=T)
    for vs in smoothing:
        out[f"tanh, v_s = {vs * 1e3:g} mm/s"] = optimal.smoothed_point_to_point(stage, DISTANCE, u_max=U_MAX, v_smooth=vs)
    out["Coulomb bang-bang"] = optimal.bang_bang(stage, DISTANCE, u_max=U_MAX)
    return out


def table(rows: dict) -> str:
    """The OCP table (markdown): duration, replayed miss, IPOPT iterations and time."""
    lines = ["| stage | force planned with | t_final [ms] | miss at t_final [nm] | speed at t_final [m/s] | "
             "IPOPT iterations | IPOPT time [s] |", "|---|---|---|---|---|---|---|"]
    for (stage, name), r in rows.items():
        lines.append(f"| {stage} | {name} | {r.t_final * 1e3:.4f} | {r.replay.x_error * 1e9:.3g} | "
                     f"{r.replay.v_final:.2g} | {r.iterations or '-'} | "
                     f"{f'{r.solve_time:.3f}' if r.iterations else '-'} |")
    return "\n".join(lines)


def after(stage: pf.Oscillator, r: optimal.PointToPointResult, t_end: float, samples: int) -> pf.SimulationResult:
    """The stage driven by ``r.u`` (no force after ``r.t_final``) up to ``t_end`` [s], dense."""
    return pf.simulate(pf.Oscillator(stage.friction, mass=stage.mass, u=r.u), 0.0, t_end=t_end,
                       rtol=1e-10, dense=np.linspace(0.0, t_end, samples))


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Solve, print the table and draw ``outdir/optimal_move.png``.

    Returns
    -------
    dict
        ``dahl`` and ``lugre`` (name -> :class:`prefriction.optimal.PointToPointResult`; quick:
        no LuGre, no minimum-effort move, one smoothing), ``table`` (markdown), ``png``.
    """
    dahl = moves(DAHL, effort=not quick, smoothing=V_SMOOTH[:1] if quick else V_SMOOTH)
    lugre = {} if quick else moves(LUGRE, effort=False)
    rows = {("Dahl", k): r for k, r in dahl.items()}
    rows.update({("LuGre", k): r for k, r in lugre.items()})
    text = table(rows)

    fig, axes = new_figure(2, 2, size=(12.0, 8.0))
    best = dahl["pre-sliding, min time"]
    t_end = 1.6 * best.t_final
    shown = ["pre-sliding, min time", "pre-sliding, min effort (1.3 T)", f"tanh, v_s = {V_SMOOTH[0] * 1e3:g} mm/s",
             "Coulomb bang-bang"]
    for c, name in zip(COLORS, shown):
        if name not in dahl:  # quick: no minimum-effort move
            continue
        r = dahl[name]
        run = after(DAHL, r, t_end, 300 if quick else 1500)
        t_ms = run.t * 1e3
        axes[0, 0].step(np.r_[r.u.t, t_end] * 1e3, np.r_[r.u.u, 0.0], where="post", color=c, lw=1.4, label=name)
        axes[0, 1].plot(t_ms, (run.x - DISTANCE) * 1e6, color=c, lw=1.4, label=name)
        axes[1, 0].plot(t_ms, run.v * 1e3, color=c, lw=1.4, label=name)
        near = run.x > DISTANCE - 60e-6
        axes[1, 1].plot((run.x[near] - DISTANCE) * 1e6, run.F[near], color=c, lw=1.4, label=name)
        axes[0, 1].plot(r.t_final * 1e3, r.replay.x_error * 1e6, "o", color=c, ms=5)
    ax = axes[0, 0]
    ax.set(xlabel="time [ms]", ylabel="applied force u [N]", title="forces (held constant on each interval)")
    ax.legend(loc="lower left", fontsize=8)
    ax = axes[0, 1]
    ax.set(xlabel="time [ms]", ylabel="x - target [µm]", ylim=(-60, 80), xlim=(0.5 * t_end * 1e3, t_end * 1e3),
           title="replayed through simulate (dots: at each t_final)")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.legend(loc="lower right", fontsize=8)
    ax = axes[1, 0]
    ax.set(xlabel="time [ms]", ylabel="velocity [mm/s]", title="velocity (replay)")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[1, 1]
    ax.set(xlabel="x - target [µm]", ylabel="friction force F [N]",
           title="friction near the target: the optimum unloads to F = 0")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.axvline(0.0, color="0.5", lw=0.8)
    ax.legend(loc="lower left", fontsize=8)
    for ax in axes.ravel():
        ax.grid(True, alpha=0.3)
    add_note(fig, f"Dahl stage: m = 1 kg, sigma = 1e5 N/m, Fc = 1 N; move {DISTANCE * 1e3:g} mm, |u| <= {U_MAX:g} N; "
                  f"all forces replayed through pf.simulate (rtol 1e-10) with the Dahl model, no force after t_final.")
    png = save(fig, outdir, "optimal_move.png")
    return {"dahl": dahl, "lugre": lugre, "table": text, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    result = main(outdir, quick=quick)
    print(result["table"])
    print(result["png"])
