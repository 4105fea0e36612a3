"""Validation of a fit on held-out data: prediction, rms, NRMSE and the fit % of system identification.

:func:`predict` evaluates a :class:`FitResult`'s model on another record of the kind fitted;
:func:`validate` scores it. For :class:`ForceDisplacement` the force along the record's ``x`` is
stepped by the same compiled recursion as the fit (:mod:`prefriction.identify.prescribed`) and
the fitted offset is added.

The initial state (``docs/identify.md#validate``): a held-out record usually starts mid-cycle,
in a state the record does not give. The prediction starts on a virgin curve, reached by a
virtual monotone displacement ``d0`` (either direction). By default ``d0`` makes the first force
equal ``F0`` minus the fitted offset (``F0`` defaults to the first measured force); with
``warmup`` (``validate``'s ``skip``) ``d0`` is the one whose prediction fits the first
``warmup`` seconds best, and those seconds are not scored. For Dahl the first choice is exact:
every Dahl state is a force on a virgin-like branch. For models with more states (Maxwell-slip,
GMS, LuGre) a virgin state is an assumption; the error it leaves dies out at the first
gross-sliding stroke for elements that slip, and never for an element that does not (it acts as
a spring whose preload only the warm-up fit can find).
:class:`Motion` records are predicted by ``prefriction.identify.motion_predict.predict_motion``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from prefriction._validation import check_finite
from prefriction.identify.data import ForceDisplacement, ForceVelocity, Motion


__all__ = ["Validation", "check_directory", "model_name", "predict", "predict_force", "validate"]


def check_directory(path: str | Path) -> None:
    """Raise ``ValueError`` if the directory of the file ``path`` does not exist.

    Parameters
    ----------
    path : str or Path
        A file to write.
    """
    if not Path(path).parent.is_dir():
        raise ValueError(f"path must be in an existing directory: {Path(path).parent} does not exist "
                         f"(create it first), got path = {str(path)!r}")


def model_name(model: Any) -> str:
    """``"Dahl"``, or ``"Dahl + Viscous"`` for a sum of models.

    Parameters
    ----------
    model : FrictionModel
        A model.
    """
    return " + ".join(type(m).__name__ for m in getattr(model, "models", (model,)))

_D0 = 30.0
"""Largest virtual virgin distance (normalised) tried for the initial state."""


def predict_force(model: Any, data: ForceDisplacement, *, offset: float = 0.0, F0: float | None = None,
                  warmup: float = 0.0, substeps: int | None = None) -> np.ndarray:
    """Friction force [N] of ``model`` along ``data.x`` plus ``offset``, started at force ``F0``.

    Parameters
    ----------
    model : FrictionModel
        The model (its parameter values).
    data : ForceDisplacement
        The record (``t`` [s], ``x`` [m]; ``F`` [N] gives the default ``F0``).
    offset : float, default 0.0
        Force offset [N] added to the model's force.
    F0 : float, optional
        Force [N] at the first sample (offset included) that sets the initial state; default
        ``data.F[0]``. A force the model cannot reach (beyond its sliding level) starts fully
        loaded in its direction.
    warmup : float, default 0.0
        If > 0 (and ``F0`` not given): choose the initial state instead so that the prediction
        fits ``data.F`` best (least squares) over the first ``warmup`` seconds [s].
    substeps : int, optional
        Runge-Kutta sub-steps per sample interval (default as in :func:`prefriction.identify.fit`).

    Returns
    -------
    numpy.ndarray
        The force [N] at every sample.
    """
    from prefriction.identify.parameters import ParameterSpace
    from prefriction.identify.prescribed import PrescribedProblem, _inputs, _Series, substeps_for

    target = (float(data.F[0]) if F0 is None else check_finite("F0", F0)) - offset
    every = ParameterSpace(model, None, None, None)      # every parameter fixed but one non-zero one
    one = next(e.name for e in every.entries if e.value != 0.0)
    space = ParameterSpace(model, [one], [e.name for e in every.entries if e.name != one], None)
    n_sub = substeps_for(model, data, substeps)
    problem = PrescribedProblem.get(model, space, len(data), n_sub)
    args = _inputs(space, _Series.of(data), data)

    def force(d0: float) -> np.ndarray:
        return np.asarray(problem.force(np.append(space.theta0, d0), *args)).ravel()

    if warmup > 0.0 and F0 is None:
        return force(_best_start(force, data, offset, warmup)) + offset
    lo, hi = force(-_D0)[0] - target, force(_D0)[0] - target
    d0 = -_D0 if lo > 0.0 else _D0 if hi < 0.0 else brentq(lambda d: force(d)[0] - target, -_D0, _D0, xtol=1e-12)
    return force(d0) + offset


def _best_start(force: Any, data: ForceDisplacement, offset: float, warmup: float) -> float:
    """The virgin distance whose prediction fits the first ``warmup`` seconds best: a grid over
    ``[-_D0, _D0]``, then a bounded scalar search around the best grid point."""
    keep = data.t <= data.t[0] + warmup
    F = data.F[keep] - offset

    def cost(d: float) -> float:
        return float(np.sum((force(d)[keep] - F) ** 2))

    grid = np.linspace(-_D0, _D0, 121)
    i = int(np.argmin([cost(d) for d in grid]))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    return float(minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-9}).x)


def predict(result: Any, data: ForceDisplacement | Motion, **kwargs: Any) -> np.ndarray:
    """The output of ``result``'s fitted model on ``data``: force [N] or position [m].

    Parameters
    ----------
    result : FitResult
        A fit (:func:`prefriction.identify.fit`).
    data : ForceDisplacement or Motion
        A record of the kind fitted.
    **kwargs
        For :class:`ForceDisplacement`: ``F0`` [N] or ``warmup`` [s] (see :func:`predict_force`). For
        :class:`Motion`: passed to ``prefriction.identify.motion_predict.predict_motion``.

    Returns
    -------
    numpy.ndarray
        Force [N] (fitted offset included) or position [m] at the record's samples.

    Raises
    ------
    TypeError
        If ``data`` is not of the kind fitted.
    """
    if type(data) is not type(result.data):
        raise TypeError(f"data must be {type(result.data).__name__} like the fitted record, got {type(data).__name__}")
    if isinstance(data, Motion):
        try:
            from prefriction.identify.motion_predict import predict_motion
        except ImportError as exc:  # the Motion predictor ships with the Motion fits
            raise NotImplementedError("predicting Motion data needs prefriction.identify.motion_predict, which this "
                                      "installation lacks; ForceDisplacement records are supported") from exc

        return predict_motion(result, data, **kwargs)
    offset = result.estimate("offset") if "offset" in result.names else 0.0
    if isinstance(data, ForceVelocity):  # a static map: its force at the record's velocities
        return result.model.force(data.v) + offset
    return predict_force(result.model, data, offset=offset, **kwargs)


@dataclass(frozen=True, eq=False)
class Validation:
    """Prediction errors of a fitted model on a record (:func:`validate`).

    Attributes
    ----------
    t : numpy.ndarray
        Scored sample times [s].
    measured, predicted : numpy.ndarray
        Measured and predicted signal there (force [N] or position [m]).
    unit : str
        ``"N"`` or ``"m"``.
    model : str
        Name of the fitted model.
    """

    t: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    unit: str
    model: str

    @property
    def rms(self) -> float:
        """Root mean square prediction error ``sqrt(mean((y - y_hat)^2))`` [N or m]."""
        return float(np.sqrt(np.mean((self.measured - self.predicted) ** 2)))

    @property
    def nrmse(self) -> float:
        """Normalised error ``||y - y_hat|| / ||y - mean(y)||`` (0 perfect, 1 no better than the mean)."""
        y = self.measured
        return float(np.linalg.norm(y - self.predicted) / np.linalg.norm(y - y.mean()))

    @property
    def fit_percent(self) -> float:
        """System-identification fit ``100 (1 - ||y - y_hat|| / ||y - mean(y)||)`` [%]."""
        return 100.0 * (1.0 - self.nrmse)

    def __repr__(self) -> str:
        return (f"Validation({self.model}: rms {self.rms:.4g} {self.unit}, nrmse {self.nrmse:.4g}, "
                f"fit {self.fit_percent:.2f} %, {self.t.size} samples)")

    def summary(self) -> str:
        """One line per measure, with the scored time span."""
        return "\n".join([f"{self.model} on {self.t.size} samples, t in [{self.t[0]:.6g}, {self.t[-1]:.6g}] s:",
                          f"  rms error  {self.rms:.4g} {self.unit}",
                          f"  NRMSE      {self.nrmse:.4g}",
                          f"  fit        {self.fit_percent:.2f} %"])

    def plot(self, path: str | Path = "validation.png") -> Path:
        """Measured against predicted over time, and the error, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "validation.png"
            Image file to write (the format from the suffix), in an existing directory.

        Returns
        -------
        Path
            The file written.

        Raises
        ------
        ValueError
            If the directory of ``path`` does not exist.
        """
        import matplotlib.pyplot as plt

        from prefriction.plotting import length_unit

        check_directory(path)
        k, unit = length_unit(self.measured) if self.unit == "m" else (1.0, "N")
        what = "position x" if self.unit == "m" else "friction force F"
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True, height_ratios=[2.0, 1.0],
                                       layout="constrained")
        ax1.plot(self.t, self.measured * k, "-", lw=1.0, color="0.55", label="measured")
        ax1.plot(self.t, self.predicted * k, "-", lw=1.0, color="C0", label=f"predicted ({self.model})")
        ax1.set_ylabel(f"{what} [{unit}]")
        ax1.legend(loc="upper center", bbox_to_anchor=(0.5, 1.16), ncol=2, frameon=False)
        ax2.plot(self.t, (self.measured - self.predicted) * k, "-", lw=0.8, color="C3")
        ax2.axhline(0.0, color="0.3", lw=0.8)
        ax2.set_ylabel(f"error [{unit}]")
        ax2.set_xlabel("time t [s]")
        for ax in (ax1, ax2):
            ax.grid(alpha=0.3)
        ax2.set_title(f"rms {self.rms * k:.3g} {unit}, fit {self.fit_percent:.1f} %", fontsize=9)
        from prefriction.plotting import write_figure

        out = write_figure(fig, path)
        plt.close(fig)
        return out


def validate(result: Any, data: ForceDisplacement | Motion, *, skip: float = 0.0,
             **kwargs: Any) -> Validation:
    """Score ``result``'s prediction on ``data``: rms, NRMSE, fit %.

    Parameters
    ----------
    result : FitResult
        A fit (:func:`prefriction.identify.fit`).
    data : ForceDisplacement or Motion
        A record of the kind fitted (held out from the fit).
    skip : float, default 0.0
        Time [s] at the start of the record not scored, ``0 <= skip`` leaving at least 2
        samples. For :class:`ForceDisplacement` without ``F0`` these seconds also set the
        initial state (``warmup`` of :func:`predict_force`): the state whose prediction fits
        them best, as system identification estimates initial conditions.
    **kwargs
        Passed to :func:`predict` (``F0``: start at this force instead).

    Returns
    -------
    Validation

    Raises
    ------
    ValueError
        If ``skip`` is negative or leaves fewer than 2 samples.

    Examples
    --------
    >>> import prefriction as pf
    >>> from prefriction.data import tribometer
    >>> rec = tribometer()
    >>> res = pf.identify.fit(pf.Dahl(sigma=4e4, Fc=2.4, gamma=0.5), rec.window(12.0, 60.0, step=4), offset=True)
    >>> val = res.validate(rec.window(150.0, 198.0, step=4))
    >>> val.rms < 0.15
    True
    """
    skip = check_finite("skip", skip)
    if isinstance(data, ForceDisplacement) and "F0" not in kwargs:
        kwargs["warmup"] = skip
    if isinstance(data, ForceVelocity):
        raise TypeError("validate scores records in time; ForceVelocity data have none: compare "
                        "result.predict(data) [N] with data.F")
    y_hat = predict(result, data, **kwargs)
    keep = data.t >= data.t[0] + skip
    if skip < 0.0 or keep.sum() < 2:
        raise ValueError(f"skip must be >= 0 and leave at least 2 samples, got {skip!r} s for a record of "
                         f"{data.t[-1] - data.t[0]:.6g} s")
    y = data.F if isinstance(data, ForceDisplacement) else data.x
    unit = "N" if isinstance(data, ForceDisplacement) else "m"
    return Validation(data.t[keep], np.asarray(y)[keep], y_hat[keep], unit, model_name(result.model))
