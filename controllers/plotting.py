"""Figures of closed-loop step responses, saved to PNG files.

Uses ``matplotlib.figure.Figure`` directly (Agg canvas, no pyplot state, no backend change).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping

import numpy as np
from matplotlib.figure import Figure

from ._loop import LoopResult


def _scale(values: np.ndarray) -> tuple[float, str]:
    """Factor and unit label that bring a displacement [m] to µm or nm."""
    peak = float(np.max(np.abs(values))) if values.size else 0.0
    return (1e6, "µm") if peak >= 1e-7 else (1e9, "nm")


def _headroom(ax, values: np.ndarray, level: "float | None") -> bool:
    """Log y-limits of the data with about a decade free above it for the legend; the ``level``
    line is included if it lies within two decades of the data. Returns whether it is."""
    pos = values[values > 0]
    if pos.size == 0:
        return False
    lo = math.log10(float(np.min(pos)))
    hi = math.log10(float(np.max(pos)))
    shown = level is not None and level > 0 and math.log10(level) <= hi + 2.0
    if shown:
        hi = max(hi, math.log10(level))
    span = max(hi - lo, 1.0)
    ax.set_ylim(10 ** (lo - 0.05 * span), 10 ** (hi + min(0.4 * span, 1.5)))
    return shown


def plot_steps(
    results: Mapping[str, LoopResult], path: "str | Path", *, title: str, bound: "float | None" = None
) -> Path:
    """One row per loop: position, control force, friction loop ``F(x)``, and ``|e|`` against ``error_bound``.

    Parameters
    ----------
    results : mapping of str to LoopResult
        Row label (e.g. ``"step 1 um"``) and its loop result.
    path : str or Path
        PNG file to write.
    title : str
        Figure title.
    bound : float, optional
        Error level [m] drawn as ``Fc/kp`` in the error panels; default each result's
        ``error_bound`` (PD loops; ``None`` for loops with an integrator).

    Returns
    -------
    Path
        The written file.
    """
    n = len(results)
    fig = Figure(figsize=(17, 3.6 * n + 0.6))
    axes = fig.subplots(n, 4, squeeze=False)
    for row, (label, res) in zip(axes, results.items()):
        k, unit = _scale(res.reference)
        t_ms = res.t * 1e3
        ax = row[0]
        ax.plot(t_ms, res.reference * k, "k--", lw=1, label="reference r")
        ax.plot(t_ms, res.x * k, lw=1.2, label="position x")
        ax.set(xlabel="time t [ms]", ylabel=f"position [{unit}]", title=f"{label}: position")
        ax.legend(loc="lower right")
        ax = row[1]
        ax.step(t_ms, res.u, where="post" if res.Ts else "pre", lw=1, label="control force u (ZOH)" if res.Ts else "control force u")
        ax.plot(t_ms, res.F, lw=1, label="friction force F")
        ax.set(xlabel="time t [ms]", ylabel="force [N]", title=f"{label}: forces")
        fmax = max(float(np.max(np.abs(res.F))), 1e-12)
        umax = float(np.max(np.abs(res.u)))
        if umax > 20 * fmax:  # a derivative kick dwarfs the friction force: keep the axis on F, say where u goes
            ax.set_ylim(-4.0 * fmax, 6.0 * fmax)
            ax.text(0.98, 0.04, f"u reaches {umax:.3g} N in the first samples (off scale)", transform=ax.transAxes,
                    ha="right", va="bottom", fontsize="small", color="C0")
        ax.legend(loc="upper right")
        ax = row[2]
        lx, lF = res.friction_loop()
        ax.plot(lx * k, lF, lw=1.2, label="Dahl branches (3.4)")
        ax.plot(res.x * k, res.F, ".", ms=3, color="0.3", label="output samples")
        rv = res.reversals
        if len(rv):
            ax.plot(rv.x * k, rv.F, "o", ms=4, mfc="none", label=f"reversals ({len(rv)})")
        lo, hi = float(np.min(lF)), float(np.max(lF))
        for level in (res.Fc, -res.Fc):  # drawn where the data come near them, not stretching the axis
            if lo - 0.3 * (hi - lo) <= level <= hi + 0.3 * (hi - lo):
                ax.axhline(level, color="0.5", lw=0.8, ls=":", label=r"$\pm F_c$" if level > 0 else None)
                lo, hi = min(lo, level), max(hi, level)
        span = max(hi - lo, 1e-300)
        ax.set_ylim(lo - 0.05 * span, hi + 0.6 * span)  # the top third free for the legend
        ax.set(xlabel=f"position x [{unit}]", ylabel="friction force F [N]", title=f"{label}: friction loop")
        ax.legend(loc="upper left", ncol=2, fontsize="small")
        ax = row[3]
        err = np.abs(res.error) * k
        ax.semilogy(t_ms, np.where(err > 0, err, np.nan), lw=1, label="$|e| = |r - x|$")
        level = res.error_bound if bound is None else bound
        shown = _headroom(ax, err, None if level is None else level * k)
        if level is not None:
            note = "" if res.error_bound is not None else ", a PD's bound (a PID has none)"
            where = "" if shown else ", above the axis"
            ax.axhline(level * k, color="C3", ls="--", label=f"Fc/kp = {level * k:.3g} {unit}{note}{where}")
        ax.set(xlabel="time t [ms]", ylabel=f"|error| [{unit}]", title=f"{label}: error")
        ax.legend(loc="upper right", fontsize="small")
        for a in row:
            a.grid(True, alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path
