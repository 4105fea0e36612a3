"""The result of :func:`prefriction.identify.fit`: estimates, uncertainty, residuals, report, plot."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.identify.result_output import FitOutput
from prefriction.identify.statistics import Statistics
from prefriction.identify.validation import model_name
from prefriction.models.base import FrictionModel

if TYPE_CHECKING:
    from prefriction.identify.diagnostics import ResidualDiagnostics
    from prefriction.identify.validation import Validation

__all__ = ["FitResult"]


@dataclass(frozen=True, eq=False)
class FitResult(FitOutput):
    """Fitted friction model with its uncertainty and residual diagnostics (:func:`prefriction.identify.fit`).

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
        Estimates, standard errors and 95 % confidence intervals (t quantile), physical units,
        from the HAC covariance (correlated residuals, ``docs/identify.md#statistics``);
        an interval is cut where it would leave the allowed range (see :attr:`flags`).
    correlation : numpy.ndarray
        Correlation matrix of the estimates.
    residuals : numpy.ndarray
        Data minus fit at every sample [N for forces, m for positions].
    fitted : numpy.ndarray
        The fitted signal at the samples (force [N] or position [m]).
    data : ForceDisplacement or Motion
        The data.
    statistics : Statistics
        Residual standard deviation, degrees of freedom, condition number, unidentifiable
        parameters, the covariance kind (``"hac"``), its bandwidth and the white-residual
        standard errors.
    nuisance : dict
        Other fitted quantities (initial state, reversal times), by name.
    message : str
        The solver's message.
    success : bool
        False if the solver stopped without converging (a :class:`ConvergenceWarning` said so).
    flags : tuple of str
        Per parameter: ``""``, or which bound it ends on (interval one-sided) or where its
        interval was cut.
    notes : tuple of str
        What the fit compared (both Dahl structures) and other remarks.
    start : tuple of str
        What the start pipeline of a :class:`Motion` fit did, one line per step: what was set and
        from what (the user's value, a static least-squares estimate, a continuation stage).
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
    success: bool = True
    flags: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    start: tuple[str, ...] = ()

    @cached_property
    def diagnostics(self) -> "ResidualDiagnostics":
        """Residual diagnostics: runs, autocorrelation, spikes at reversals and the estimates to
        distrust (:mod:`prefriction.identify.diagnostics`, ``docs/identify.md#diagnostics``)."""
        from prefriction.identify.diagnostics import diagnose_fit

        return diagnose_fit(self)

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

    def predict(self, data: ForceDisplacement | Motion, **kwargs: Any) -> np.ndarray:
        """The fitted model's output on another record of the data's kind (validation).

        Parameters
        ----------
        data : ForceDisplacement or Motion
            The record: force [N] along its ``x`` for :class:`ForceDisplacement` (the fitted
            offset added), position [m] for :class:`Motion`.
        **kwargs
            For :class:`ForceDisplacement`: ``F0`` [N], the force at the first sample that sets
            the initial state (default: the first measured force), or ``warmup`` [s], the
            initial state fitted to the first seconds instead; see
            :func:`prefriction.identify.validation.predict_force` (``docs/identify.md#validate``).

        Returns
        -------
        numpy.ndarray
            The prediction at the record's samples.
        """
        from prefriction.identify.validation import predict

        return predict(self, data, **kwargs)

    def validate(self, data: ForceDisplacement | Motion, **kwargs: Any) -> "Validation":
        """Prediction errors on another record: rms, NRMSE and fit % (``docs/identify.md#validate``).

        Parameters
        ----------
        data : ForceDisplacement or Motion
            A held-out record of the kind fitted.
        **kwargs
            ``F0`` and ``skip`` [s] (the first seconds not scored);
            see :func:`prefriction.identify.validation.validate`.

        Returns
        -------
        Validation
            ``rms``, ``nrmse``, ``fit_percent``, ``summary()``, ``plot(path)``.
        """
        from prefriction.identify.validation import validate

        return validate(self, data, **kwargs)

    def __repr__(self) -> str:
        est = ", ".join(f"{n}={v:.4g}+-{s:.2g}" for n, v, s in zip(self.names, self.estimates, self.stderr))
        tail = "" if self.success else ", NOT CONVERGED"
        return f"FitResult({model_name(self.model)}: {est}; rms {self.rms:.3g}, {len(self.residuals)} samples{tail})"
