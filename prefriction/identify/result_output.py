"""The text and figures of a :class:`~prefriction.identify.FitResult`: the summary, the report and
the plots (the mixin :class:`FitOutput`; the work is done in :mod:`prefriction.identify.report`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from prefriction.identify.data import ForceDisplacement, Motion
    from prefriction.identify.validation import Validation

__all__ = ["FitOutput"]


class FitOutput:
    """Summary, report and figures of a fit (mixin of :class:`~prefriction.identify.FitResult`)."""

    def summary(self) -> str:
        """A few lines: the fitted model, the residual level, estimates with intervals and bound
        flags, any unidentifiable parameter, the start pipeline's steps (Motion fits), residual
        structure and the estimates to distrust, what was compared, and non-convergence."""
        from prefriction.identify.report import summary_text

        return summary_text(self)

    def report(self, held_out: "ForceDisplacement | Motion | Validation | None" = None) -> str:
        """What the fit did and how sure it is: the start pipeline's steps, a table of estimates,
        standard errors (HAC and white-residual), 95 % intervals and relative errors, the
        correlation matrix, the parameters the data cannot pin down, the residual diagnostics
        and the estimates to distrust, and the held-out validation.

        Parameters
        ----------
        held_out : ForceDisplacement, Motion or Validation, optional
            A held-out record (validated with :meth:`validate` and its defaults) or the
            :class:`Validation` of one.
        """
        from prefriction.identify.report import report_text

        return report_text(self, held_out)

    def plot_residuals(self, path: str | Path = "residuals.png", *, show: bool = False) -> Path:
        """The residual diagnostics figure: residuals against time with the reversals, their
        autocorrelation, residuals against the samples since the last reversal, and a normal
        quantile plot (``docs/identify.md#diagnostics``).

        Parameters
        ----------
        path : str or Path, default "residuals.png"
            Image file to write (the format from the suffix).
        show : bool, default False
            Also open a window.

        Returns
        -------
        Path
            The file written.
        """
        from prefriction.identify.report import plot_residuals

        return plot_residuals(self, path, show)

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
        from prefriction.identify.report import plot_fit

        return plot_fit(self, path, show)
