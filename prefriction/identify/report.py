"""Text report and figure of a :class:`prefriction.identify.FitResult` (which imports this module:
``res`` is annotated ``Any`` here, so no import runs back up to it)."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from prefriction.identify.data import ForceDisplacement, ForceVelocity, Motion
from prefriction.identify.validation import check_directory, model_name

__all__ = ["plot_fit", "plot_residuals", "report_text", "summary_text"]


def _flag(res: Any, i: int) -> str:
    return f"  ({res.flags[i]})" if i < len(res.flags) and res.flags[i] else ""


def summary_text(res: Any) -> str:
    """The text of :meth:`FitResult.summary`."""
    st = res.statistics
    unit = "m" if isinstance(res.data, Motion) else "N"
    lines = [f"{model_name(res.model)} fitted to {len(res.residuals)} samples of "
             f"{type(res.data).__name__}: residual sd {st.sigma_hat:.4g} {unit}, {st.dof} dof"]
    for i, (n, u, v, lo, hi) in enumerate(zip(res.names, res.units, res.estimates, res.low, res.high)):
        lines.append(f"  {n:<14} {v:< 12.6g} [{lo:.6g}, {hi:.6g}] {u}" + _flag(res, i))
    for n, why in st.unidentifiable:
        lines.append(f"  not identifiable: {n} ({why})")
    lines.extend(f"  start: {step}" for step in res.start)
    if isinstance(res.data, (ForceDisplacement, Motion)):
        diag = res.diagnostics
        lines.extend(f"  residual structure: {f}" for f in diag.findings)
        lines.extend(f"  distrust {n}: {why}" for n, why in diag.distrust)
    lines.extend(f"  {note}" for note in res.notes)
    if not res.success:
        lines.append(f"  NOT CONVERGED: {res.message}")
    return "\n".join(lines)


def report_text(res: Any, held_out: Any = None) -> str:
    """The text of :meth:`FitResult.report`.

    Parameters
    ----------
    res : FitResult
        A fit.
    held_out : ForceDisplacement, Motion, Validation or None
        A held-out record or its validation.

    Returns
    -------
    str
        The start pipeline's steps; estimates with standard errors (HAC and white-residual),
        95 % intervals and bound notes; correlation; residual level; the data's treatment of
        position noise; identifiability; the residual diagnostics and the estimates to
        distrust; the held-out validation; what was compared; the solver's message.
    """
    st = res.statistics
    rows = []
    steps = getattr(res, "start", ())
    if steps:
        rows.append("start pipeline:")
        rows.extend(f"  {i}. {step}" for i, step in enumerate(steps, 1))
        rows.append("")
    iid = st.stderr_iid if st.stderr_iid is not None else res.stderr
    head = (f"{'parameter':<14} {'unit':<6} {'estimate':>13} {'std err':>11} {'white':>10} {'rel':>8}   "
            f"95 % interval")
    rows += [head, "-" * len(head)]
    for i, (n, u, v, s, lo, hi) in enumerate(zip(res.names, res.units, res.estimates, res.stderr, res.low, res.high)):
        rel = s / abs(v) if v else np.inf
        rows.append(f"{n:<14} {u:<6} {v:>13.6g} {s:>11.3g} {iid[i]:>10.3g} {100 * rel:>7.3g}%   "
                    f"[{lo:.6g}, {hi:.6g}]" + _flag(res, i))
    if st.covariance == "hac":
        rows.append(f"std err: HAC (Newey-West, bandwidth {st.bandwidth} samples), never below the white-residual "
                    f"one ('white', Gauss-Newton)")
    rows.append("")
    rows.append("correlation:")
    width = max(len(n) for n in res.names)
    for n, row in zip(res.names, res.correlation):
        rows.append(f"  {n:<{width}} " + " ".join(f"{c:>6.3f}" for c in row))
    rows.append("")
    unit = "m" if isinstance(res.data, Motion) else "N"
    rows.append(f"residual sd {st.sigma_hat:.4g} {unit} ({st.dof} degrees of freedom), "
                f"condition number {st.condition:.3g} (Jacobi-scaled)")
    for key, val in res.nuisance.items():
        if np.ndim(val) == 0:
            rows.append(f"{key}: {float(val):.6g}")
        else:
            rows.append(f"{key}: {np.size(val)} values")
    d = res.data
    if isinstance(d, ForceDisplacement) and d.noisy_positions:
        rows.append(f"positions: x_noise {d.x_noise:.3g} m, quantum {d.quantum:.3g} m declared; the model follows the "
                    f"estimated path (window {d.path_window} samples, rms change {np.std(d.path - d.x):.3g} m), its "
                    f"error is in the intervals")
    if isinstance(d, Motion) and (d.x_noise or d.quantum):
        from prefriction.identify.positions import noise_sd

        rows.append(f"positions: x_noise {d.x_noise:.3g} m, quantum {d.quantum:.3g} m declared (measurement sd "
                    f"{noise_sd(d.x_noise, d.quantum):.3g} m; the residual sd above)")
    if st.unidentifiable:
        for n, why in st.unidentifiable:
            rows.append(f"NOT IDENTIFIABLE from these data: {n} ({why})")
    else:
        rows.append("every fitted parameter is identifiable from these data")
    if isinstance(d, (ForceDisplacement, Motion)):
        rows.append("")
        rows.append("residual diagnostics:")
        rows.extend(f"  {line}" for line in res.diagnostics.summary().splitlines())
    if held_out is not None:
        from prefriction.identify.validation import Validation

        val = held_out if isinstance(held_out, Validation) else res.validate(held_out)
        rows.append("")
        rows.append("held-out validation:")
        rows.extend(f"  {line}" for line in val.summary().splitlines())
    rows.append("")
    rows.extend(res.notes)
    rows.append(f"solver: {res.message}" if res.success else f"NOT CONVERGED: {res.message}")
    return "\n".join(rows)


def plot_fit(res: Any, path: str | Path, show: bool) -> Path:
    """The figure of :meth:`FitResult.plot`.

    Parameters
    ----------
    res : FitResult
        A fit.
    path : str or Path
        Image file to write.
    show : bool
        Also open a window.

    Returns
    -------
    Path
        The file written.
    """
    import matplotlib.pyplot as plt

    from prefriction.plotting import length_unit

    check_directory(path)
    d = res.data
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 6.5), height_ratios=[2.2, 1.0], layout="constrained")
    name = model_name(res.model)
    if isinstance(d, ForceVelocity):
        order = np.argsort(d.v)
        ax1.plot(d.v, d.F, ".", ms=4, color="0.55", label="data")
        ax1.plot(d.v[order], res.fitted[order], "-", lw=1.2, color="C0", label=f"fitted {name}")
        ax1.set_xlabel("velocity v [m/s]")
        ax1.set_ylabel("friction force F [N]")
        ax2.set_ylabel("residual F - fit [N]")
        ax2.plot(d.v, res.residuals, ".", ms=3, color="C3")
        small = float(np.min(np.abs(d.v[d.v != 0.0]))) if np.any(d.v != 0.0) else 1.0
        for ax in (ax1, ax2):  # the Stribeck region lives at small speeds
            ax.set_xscale("symlog", linthresh=small)
    elif isinstance(d, ForceDisplacement):
        k, unit = length_unit(d.x)
        ax1.plot(d.x * k, d.F, ".", ms=3, color="0.55", label="data")
        ax1.plot(d.x * k, res.fitted, "-", lw=1.2, color="C0", label=f"fitted {name}")
        ax1.set_xlabel(f"displacement x [{unit}]")
        ax1.set_ylabel("friction force F [N]")
        ax2.set_ylabel("residual F - fit [N]")
        ax2.plot(d.t, res.residuals, ".", ms=3, color="C3")
    else:
        k, unit = length_unit(d.x)
        kr, unit_r = length_unit(res.residuals)
        ax1.plot(d.t, d.x * k, ".", ms=3, color="0.55", label="data")
        ax1.plot(d.t, res.fitted * k, "-", lw=1.2, color="C0", label=f"fitted {name}")
        ax1.set_xlabel("time t [s]")
        ax1.set_ylabel(f"position x [{unit}]")
        ax2.set_ylabel(f"residual x - fit [{unit_r}]")
        ax2.plot(d.t, res.residuals * kr, ".", ms=3, color="C3")
    ax1.legend(loc="best", frameon=True)
    ax1.grid(alpha=0.3)
    ax2.axhline(0.0, color="0.3", lw=0.8)
    ax2.set_xlabel("velocity v [m/s]" if isinstance(d, ForceVelocity) else "time t [s]")
    ax2.grid(alpha=0.3)
    est = ", ".join(f"{n} = {v:.4g}" + ("" if u in ("", "-") else f" {u}")  # dimensionless: no unit
                     for n, v, u in zip(res.names, res.estimates, res.units))
    ax1.set_title("\n".join(textwrap.wrap(f"{name} fit: {est}", 100)), fontsize=9)  # long sums wrap
    from prefriction.plotting import write_figure

    out = write_figure(fig, path)
    if show:
        plt.show()
    plt.close(fig)
    return out


def _headroom(ax: Any, y: np.ndarray) -> None:
    """Room above the data for a one-line legend."""
    lo, hi = float(np.min(y)), float(np.max(y))
    span = hi - lo or 1.0
    ax.set_ylim(lo - 0.05 * span, hi + 0.3 * span)


def plot_residuals(res: Any, path: str | Path, show: bool) -> Path:
    """The figure of :meth:`FitResult.plot_residuals`: residuals against time with the reversals
    marked, their autocorrelation with the band of independent residuals, the residuals against
    the samples since the last reversal (spikes there are a reversal transient the model
    misses), and a normal quantile plot.

    Parameters
    ----------
    res : FitResult
        A fit of :class:`ForceDisplacement` or :class:`Motion` data.
    path : str or Path
        Image file to write.
    show : bool
        Also open a window.

    Returns
    -------
    Path
        The file written.
    """
    import matplotlib.pyplot as plt
    from scipy.stats import norm

    from prefriction.plotting import length_unit

    if not isinstance(res.data, (ForceDisplacement, Motion)):
        raise TypeError(f"plot_residuals needs a fit of ForceDisplacement or Motion data, got "
                        f"{type(res.data).__name__}")
    check_directory(path)
    diag = res.diagnostics
    d = res.data
    if isinstance(d, Motion):
        k, unit = length_unit(res.residuals)
    else:
        k, unit = 1.0, "N"
    r = res.residuals * k
    fig, axes = plt.subplots(2, 2, figsize=(9.0, 6.5), layout="constrained")
    ax = axes[0, 0]
    ax.plot(d.t, r, ".", ms=2, color="C3", label="residual")
    for j, i in enumerate(diag.reversals):
        ax.axvline(d.t[i], color="0.6", lw=0.6, label="reversal" if j == 0 else None)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"residual [{unit}]")
    _headroom(ax, r)
    ax.legend(loc="upper right", fontsize=8, ncols=2)
    ax = axes[0, 1]
    lags = np.arange(diag.acf.size)
    band = 2.0 / np.sqrt(r.size)
    ax.axhspan(-band, band, color="0.85", zorder=0, label="independent (2 / sqrt(n))")
    ax.bar(lags[1:], diag.acf[1:], width=0.8, color="C0", zorder=2, label="autocorrelation")
    _headroom(ax, np.r_[diag.acf[1:], band, -band])
    ax.set_xlabel("lag [samples]")
    ax.set_ylabel("autocorrelation [-]")
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[1, 0]
    since = np.full(r.size, -1)
    for i in diag.reversals:
        since[i:] = np.arange(r.size - i)
    if diag.reversals.size:
        keep = since >= 0
        ax.plot(since[keep], r[keep], ".", ms=2, color="C3", label="residual")
        ax.axvline(diag.window, color="0.3", lw=0.8, ls="--", label=f"checked window ({diag.window})")
        _headroom(ax, r)
        ax.legend(loc="upper right", fontsize=8, ncols=2)
    else:
        ax.text(0.5, 0.5, "no reversals", transform=ax.transAxes, ha="center")
    ax.set_xlabel("samples since the last reversal [-]")
    ax.set_ylabel(f"residual [{unit}]")
    ax = axes[1, 1]
    q = norm.ppf((np.arange(1, r.size + 1) - 0.5) / r.size)
    sd = float(np.std(r)) or 1.0
    ax.plot(q, np.sort(r) / sd, ".", ms=2, color="C3", label="residual / sd")
    ax.plot([q[0], q[-1]], [q[0], q[-1]], "-", color="0.3", lw=0.8, label="normal")
    ax.set_xlabel("normal quantile [-]")
    ax.set_ylabel("sorted residual / sd [-]")
    ax.legend(loc="upper left", fontsize=8)
    state = "; ".join(diag.findings) if diag.findings else "no unexplained structure"
    fig.suptitle("\n".join(textwrap.wrap(f"{model_name(res.model)} residuals: {state}", 110)), fontsize=9)
    from prefriction.plotting import write_figure

    out = write_figure(fig, path)   # atomic, a link at path replaced, never followed
    if show:
        plt.show()
    plt.close(fig)
    return out
