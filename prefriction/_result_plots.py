"""The figures of the result classes' ``plot(path)``: labelled axes with units, saved to a file.

One function per result kind; the classes call them lazily (matplotlib loads on the first plot).
Figures are :class:`matplotlib.figure.Figure` objects (no pyplot, no window, no global state).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from prefriction.plotting import length_unit, new_figure


def _save(fig: Any, path: "str | Path") -> Path:
    out = Path(path)
    fig.savefig(out, dpi=120)
    return out


def _grid(*axes: Any) -> None:
    for ax in axes:
        ax.grid(alpha=0.3)


def plot_simulation(res: Any, path: "str | Path") -> Path:
    """Samples ``x(t)`` and the friction loop ``F(x)`` if the run was dense; always the force at
    the reversals against their number (the ring-down of an unforced oscillator)."""
    tab = res.reversals
    dense = res.t is not None
    fig, axes = new_figure(1, 3 if dense else 2, size=(12.0 if dense else 8.5, 3.8))
    axes = list(axes[0])
    if dense:
        scale, unit = length_unit(res.x)
        ax_t, ax_loop = axes[0], axes[1]
        ax_t.plot(res.t, res.x * scale, lw=1.0, label="position x")
        if len(tab) and len(tab) <= 500:
            ax_t.plot(tab.t, tab.x * scale, "o", ms=3, color="C3", label="reversals")
        ax_t.set_xlabel("time t [s]")
        ax_t.set_ylabel(f"position x [{unit}]")
        ax_t.legend(loc="best", fontsize=8)
        ax_loop.plot(res.x * scale, res.F, lw=1.0)
        ax_loop.set_xlabel(f"position x [{unit}]")
        ax_loop.set_ylabel("friction force F [N]")
        axes = axes[2:]
    ax_r, ax_x = (axes[0], axes[1]) if not dense else (axes[0], None)
    k = np.arange(1, len(tab) + 1)
    F = np.abs(tab.F)
    ax_r.semilogy(k[F > 0], F[F > 0], ".-", ms=3)
    ax_r.set_xlabel("reversal number i")
    ax_r.set_ylabel("|F_i| at the reversal [N]")
    if ax_x is not None:
        scale, unit = length_unit(tab.x) if len(tab) else (1.0, "m")
        ax_x.plot(tab.t, tab.x * scale, ".-", ms=3)
        ax_x.set_xlabel("reversal time t_i [s]")
        ax_x.set_ylabel(f"position x_i [{unit}]")
    _grid(*fig.axes)
    fig.suptitle(f"simulation: {len(tab)} reversals, {res.message}", fontsize=10)
    return _save(fig, path)


def plot_sweep(res: Any, path: "str | Path") -> Path:
    """Each run's reversal amplitudes ``|F_i|`` against ``i`` (at most 20 runs drawn) and every
    run's last ``|F|`` against its index; failed runs marked."""
    fig, axes = new_figure(1, 2, size=(10.0, 3.8))
    ax_runs, ax_last = axes[0]
    F = np.abs(res.reversal_array("F"))
    shown = np.unique(np.linspace(0, len(res) - 1, min(len(res), 20)).astype(int)) if len(res) else []
    for i in shown:
        row = F[i][np.isfinite(F[i]) & (F[i] > 0)]
        if row.size:
            ax_runs.semilogy(np.arange(1, row.size + 1), row, lw=0.9, label=f"run {i}" if len(shown) <= 6 else None)
    ax_runs.set_xlabel("reversal number i")
    ax_runs.set_ylabel("|F_i| [N]")
    if 0 < len(shown) <= 6:
        ax_runs.legend(loc="best", fontsize=8)
    n = res.n_reversals
    last = np.array([F[i, n[i] - 1] if n[i] > 0 else np.nan for i in range(len(res))])
    ax_last.plot(np.arange(len(res)), last, ".", ms=4, label="last reversal")
    if res.failed:
        ax_last.plot(res.failed, np.full(len(res.failed), np.nanmin(last) if np.any(np.isfinite(last)) else 0.0),
                     "x", color="C3", label="failed")
        ax_last.legend(loc="best", fontsize=8)
    ax_last.set_xlabel("run index")
    ax_last.set_ylabel("|F| at the last reversal [N]")
    _grid(ax_runs, ax_last)
    fig.suptitle(f"sweep: {len(res)} runs, {len(res.failed)} failed", fontsize=10)
    return _save(fig, path)


def plot_loop(res: Any, path: "str | Path") -> Path:
    """Reference and position, the tracking error, and the forces, against time."""
    fig, axes = new_figure(3, 1, size=(8.0, 7.0), sharex=True)
    ax_x, ax_e, ax_u = axes[:, 0]
    scale, unit = length_unit(np.concatenate([res.reference, res.x]))
    ax_x.plot(res.t, res.reference * scale, color="k", lw=1.0, label="reference r")
    ax_x.plot(res.t, res.x * scale, lw=1.0, ls="--", label="position x")
    ax_x.set_ylabel(f"position [{unit}]")
    ax_x.legend(loc="best", fontsize=8)
    escale, eunit = length_unit(res.error)
    ax_e.plot(res.t, res.error * escale, lw=0.9, color="C3")
    ax_e.set_ylabel(f"error r - x [{eunit}]")
    drawstyle = "steps-post" if res.Ts is not None else "default"
    ax_u.plot(res.t, res.u, lw=0.9, drawstyle=drawstyle, label="applied force u")
    ax_u.plot(res.t, res.F, lw=0.9, label="friction force F")
    if res.compensation is not None and np.any(res.compensation != 0.0):
        ax_u.plot(res.t, res.compensation, lw=0.9, drawstyle=drawstyle, label="compensation")
    ax_u.set_ylabel("force [N]")
    ax_u.set_xlabel("time t [s]")
    ax_u.legend(loc="best", fontsize=8)
    _grid(ax_x, ax_e, ax_u)
    kind = f"sampled at {1.0 / res.Ts:.4g} Hz" if res.Ts is not None else "continuous"
    fig.suptitle(f"closed loop ({kind}), {len(res.reversals)} reversals", fontsize=10)
    return _save(fig, path)


def plot_move(res: Any, path: "str | Path") -> Path:
    """The planned position and velocity (and the replay through the simulator), and the force."""
    fig, axes = new_figure(3, 1, size=(8.0, 7.0), sharex=True)
    ax_x, ax_v, ax_u = axes[:, 0]
    scale, unit = length_unit(np.array([res.distance, *res.x]))
    ax_x.plot(res.t * 1e3, res.x * scale, ".-", ms=3, label="plan (solver nodes)")
    if res.replay is not None and res.replay.run.t is not None:
        ax_x.plot(res.replay.run.t * 1e3, res.replay.run.x * scale, "--", lw=1.0, label="replayed by simulate")
    ax_x.axhline(res.distance * scale, color="k", lw=0.6, ls=":", label="target")
    ax_x.set_ylabel(f"position [{unit}]")
    ax_x.legend(loc="best", fontsize=8)
    ax_v.plot(res.t * 1e3, res.v * 1e3, ".-", ms=3)
    ax_v.set_ylabel("velocity [mm/s]")
    tu = np.linspace(0.0, res.t_final, 2000)
    ax_u.plot(tu * 1e3, res.u(tu), lw=1.0, label="force u")
    ax_u.plot(res.t * 1e3, res.F, lw=1.0, label="friction force F")
    ax_u.set_ylabel("force [N]")
    ax_u.set_xlabel("time t [ms]")
    ax_u.legend(loc="best", fontsize=8)
    _grid(ax_x, ax_v, ax_u)
    fig.suptitle(f"{res.method} {res.objective}-optimal move: {res.t_final * 1e3:.4g} ms", fontsize=10)
    return _save(fig, path)
