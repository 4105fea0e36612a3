"""The result of :func:`prefriction.identify.fit`: estimates, uncertainty, residuals, report, plot."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.identify.statistics import Statistics
from prefriction.models.base import FrictionModel

__all__ = ["FitResult"]


@dataclass(frozen=True, eq=False)
class FitResult:
    """Fitted friction model with Gauss-Newton uncertainty (:func:`prefriction.identify.fit`).

    Attributes
    ----------
    model : FrictionModel
        The fitted model (the start model's class; fixed parameters at their start values).
    mass : float or None
        The mass [kg] of a :class:`Motion` fit (fitted or given); ``None`` for force-displacement data.
    names : tuple of str
        The fitted parameters (``"stiffness[0]"`` for an array entry, ``"mass"``).
    units : tuple of str
        Their units.
    estimates, stderr, low, high : numpy.ndarray
        Estimates, standard errors and 95 % confidence intervals (t quantile), physical units.
    correlation : numpy.ndarray
        Correlation matrix of the estimates.
    residuals : numpy.ndarray
        Data minus fit at every sample [N for forces, m for positions].
    fitted : numpy.ndarray
        The fitted signal at the samples (force [N] or position [m]).
    data : ForceDisplacement or Motion
        The data.
    statistics : Statistics
        Residual standard deviation, degrees of freedom, condition number, unidentifiable parameters.
    nuisance : dict
        Other fitted quantities (initial state, reversal times), by name.
    message : str
        The solver's message.
    """

    model: FrictionModel
    mass: float | None
    names: tuple[str, ...]
    units: tuple[str, ...]
    estimates: np.ndarray
    stderr: np.ndarray
    low: np.ndarray
    high: np.ndarray
    correlation: np.ndarray
    residuals: np.ndarray
    fitted: np.ndarray
    data: ForceDisplacement | Motion
    statistics: Statistics
    nuisance: dict = field(default_factory=dict)
    message: str = ""

    @property
    def unidentifiable(self) -> tuple[str, ...]:
        """Names of the parameters the data cannot identify (an :class:`IdentifiabilityWarning` named them)."""
        return tuple(n for n, _ in self.statistics.unidentifiable)

    def estimate(self, name: str) -> float:
        """The estimate of parameter ``name``.

        Parameters
        ----------
        name : str
            One of :attr:`names`.
        """
        return float(self.estimates[self._index(name)])

    def interval(self, name: str) -> tuple[float, float]:
        """The 95 % confidence interval of parameter ``name``.

        Parameters
        ----------
        name : str
            One of :attr:`names`.
        """
        i = self._index(name)
        return float(self.low[i]), float(self.high[i])

    def _index(self, name: str) -> int:
        if name not in self.names:
            raise ValueError(f"name must be one of the fitted parameters {list(self.names)}, got {name!r}")
        return self.names.index(name)

    @property
    def rms(self) -> float:
        """Root mean square of the residuals."""
        return float(np.sqrt(np.mean(self.residuals**2)))

    def __repr__(self) -> str:
        est = ", ".join(f"{n}={v:.4g}+-{s:.2g}" for n, v, s in zip(self.names, self.estimates, self.stderr))
        return f"FitResult({type(self.model).__name__}: {est}; rms {self.rms:.3g}, {len(self.residuals)} samples)"

    def summary(self) -> str:
        """A few lines: the fitted model, the residual level and any unidentifiable parameter."""
        st = self.statistics
        unit = "N" if isinstance(self.data, ForceDisplacement) else "m"
        lines = [f"{type(self.model).__name__} fitted to {len(self.residuals)} samples of "
                 f"{type(self.data).__name__}: residual sd {st.sigma_hat:.4g} {unit}, {st.dof} dof"]
        for n, u, v, lo, hi in zip(self.names, self.units, self.estimates, self.low, self.high):
            lines.append(f"  {n:<14} {v:< 12.6g} [{lo:.6g}, {hi:.6g}] {u}")
        for n, why in st.unidentifiable:
            lines.append(f"  not identifiable: {n} ({why})")
        return "\n".join(lines)

    def report(self) -> str:
        """A table of estimates, standard errors, 95 % intervals and relative errors, the
        correlation matrix, the residual level and the identifiability diagnosis."""
        st = self.statistics
        head = f"{'parameter':<14} {'unit':<6} {'estimate':>13} {'std err':>11} {'rel':>8}   95 % interval"
        rows = [head, "-" * len(head)]
        for n, u, v, s, lo, hi in zip(self.names, self.units, self.estimates, self.stderr, self.low, self.high):
            rel = s / abs(v) if v else np.inf
            rows.append(f"{n:<14} {u:<6} {v:>13.6g} {s:>11.3g} {100 * rel:>7.3g}%   [{lo:.6g}, {hi:.6g}]")
        rows.append("")
        rows.append("correlation:")
        width = max(len(n) for n in self.names)
        for n, row in zip(self.names, self.correlation):
            rows.append(f"  {n:<{width}} " + " ".join(f"{c:>6.3f}" for c in row))
        rows.append("")
        unit = "N" if isinstance(self.data, ForceDisplacement) else "m"
        rows.append(f"residual sd {st.sigma_hat:.4g} {unit} ({st.dof} degrees of freedom), "
                    f"condition number {st.condition:.3g} (Jacobi-scaled)")
        for key, val in self.nuisance.items():
            if np.ndim(val) == 0:
                rows.append(f"{key}: {float(val):.6g}")
            else:
                rows.append(f"{key}: {np.size(val)} values")
        if st.unidentifiable:
            for n, why in st.unidentifiable:
                rows.append(f"NOT IDENTIFIABLE from these data: {n} ({why})")
        else:
            rows.append("every fitted parameter is identifiable from these data")
        rows.append(f"solver: {self.message}")
        return "\n".join(rows)

    def plot(self, path: str | Path = "fit.png", *, show: bool = False) -> Path:
        """Data against fit and the residuals, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "fit.png"
            Image file to write (the format from the suffix).
        show : bool, default False
            Also open a window (``matplotlib.pyplot.show``).

        Returns
        -------
        Path
            The file written.
        """
        import matplotlib.pyplot as plt

        if not Path(path).parent.is_dir():
            raise ValueError(f"path must be in an existing directory: {Path(path).parent} does not exist "
                             f"(create it first), got path = {str(path)!r}")
        d = self.data
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 6.5), height_ratios=[2.2, 1.0], layout="constrained")
        name = type(self.model).__name__
        if isinstance(d, ForceDisplacement):
            k, unit = _length_unit(d.x)
            ax1.plot(d.x * k, d.F, ".", ms=3, color="0.55", label="data")
            ax1.plot(d.x * k, self.fitted, "-", lw=1.2, color="C0", label=f"fitted {name}")
            ax1.set_xlabel(f"displacement $x$ [{unit}]")
            ax1.set_ylabel("friction force F [N]")
            ax2.set_ylabel("residual F - fit [N]")
            ax2.plot(d.t, self.residuals, ".", ms=3, color="C3")
        else:
            k, unit = _length_unit(d.x)
            ax1.plot(d.t, d.x * k, ".", ms=3, color="0.55", label="data")
            ax1.plot(d.t, self.fitted * k, "-", lw=1.2, color="C0", label=f"fitted {name}")
            ax1.set_xlabel("time t [s]")
            ax1.set_ylabel(f"position $x$ [{unit}]")
            ax2.set_ylabel(f"residual $x$ - fit [{unit}]")
            ax2.plot(d.t, self.residuals * k, ".", ms=3, color="C3")
        ax1.legend(loc="best", frameon=True)
        ax1.grid(alpha=0.3)
        ax2.axhline(0.0, color="0.3", lw=0.8)
        ax2.set_xlabel("time t [s]")
        ax2.grid(alpha=0.3)
        est = ", ".join(f"{n} = {v:.4g}" for n, v in zip(self.names, self.estimates))
        ax1.set_title(f"{name} fit: {est}", fontsize=9)
        out = Path(path)
        fig.savefig(out, dpi=120)
        if show:
            plt.show()
        plt.close(fig)
        return out


def _length_unit(x: np.ndarray) -> tuple[float, str]:
    """Factor and label that bring lengths [m] of the size of ``x`` to mm, µm or nm."""
    peak = float(np.max(np.abs(x))) if np.size(x) else 0.0
    return (1e3, "mm") if peak >= 1e-3 else (1e6, "µm") if peak >= 1e-6 else (1e9, "nm")
