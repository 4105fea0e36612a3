"""Text report and figure of a :class:`prefriction.identify.FitResult` (which imports this module:
``res`` is annotated ``Any`` here, so no import runs back up to it)."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from prefriction.identify.data import ForceDisplacement, ForceVelocity, Motion
from prefriction.identify.validation import check_directory, model_name

__all__ = ["plot_fit", "report_text"]


def _flag(res: Any, i: int) -> str:
    return f"  ({res.flags[i]})" if i < len(res.flags) and res.flags[i] else ""


def report_text(res: Any) -> str:
    """The text of :meth:`FitResult.report`.

    Parameters
    ----------
    res : FitResult
        A fit.

    Returns
    -------
    str
        Estimates with standard errors, 95 % intervals and bound notes; correlation; residual
        level; identifiability; what was compared; the solver's message.
    """
    st = res.statistics
    head = f"{'parameter':<14} {'unit':<6} {'estimate':>13} {'std err':>11} {'rel':>8}   95 % interval"
    rows = [head, "-" * len(head)]
    for n, u, v, s, lo, hi in zip(res.names, res.units, res.estimates, res.stderr, res.low, res.high):
        rel = s / abs(v) if v else np.inf
        rows.append(f"{n:<14} {u:<6} {v:>13.6g} {s:>11.3g} {100 * rel:>7.3g}%   [{lo:.6g}, {hi:.6g}]"
                    + _flag(res, len(rows) - 2))
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
    if st.unidentifiable:
        for n, why in st.unidentifiable:
            rows.append(f"NOT IDENTIFIABLE from these data: {n} ({why})")
    else:
        rows.append("every fitted parameter is identifiable from these data")
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
