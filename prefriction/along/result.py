"""The result of :func:`prefriction.friction_along`: force, states and events at every sample."""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Callable, Union

import numpy as np

from prefriction.models.base import FrictionModel

__all__ = ["AlongResult"]

Detail = tuple[np.ndarray, np.ndarray]
"""The states ``[z, m]`` at every sample (``n x (n_states + n_flags)``) and the events per interval."""


class AlongResult:
    """Friction force of a model along a prescribed motion (:func:`prefriction.friction_along`).

    The force, the reversals and the number of events come with the run. The velocities, the
    states, the flags and the events per sample are made on first access (the states by the
    same deterministic pass run again with its states written, ``docs/along.md#states-on-access``), so a
    run that needs only the force does not pay for them. ``t`` and ``x`` are read-only.

    Attributes
    ----------
    model : FrictionModel
        The model.
    t, x : numpy.ndarray
        Sample times [s] and positions [m] of the motion.
    F : numpy.ndarray
        Friction force [N] at every sample.
    v : numpy.ndarray
        Velocity [m/s] at every sample that the rate-dependent part of the force used.
    states : numpy.ndarray
        The model's continuous states ``z`` at every sample, shape ``(n, n_states)``, in the
        model's normalised units (``docs/models.md``; Dahl: branch distance or log-gap).
    flags : numpy.ndarray
        The model's flags ``m`` (0 or 1) at every sample, shape ``(n, n_flags)``.
    events : numpy.ndarray
        Number of model events (saturations, element slips) in the interval that ends at each
        sample (0 at the first).
    n_events : int
        Total number of model events along the motion.
    reversals : numpy.ndarray
        Indices of the samples where the motion reverses.
    F0 : float
        The initial force [N] (``docs/along.md#initial-state``).
    step : str
        ``"exact"`` (the model's closed-form step) or ``"rk4 x N"`` (``N`` Runge-Kutta sub-steps).
    seconds : float
        Wall time of the run [s] (without the one-off build and compilation, and without the
        states made on first access).
    """

    def __init__(self, model: FrictionModel, t: np.ndarray, x: np.ndarray, F: np.ndarray,
                 v: Union[np.ndarray, Callable[[], np.ndarray]], detail: Union[Detail, Callable[[], Detail]],
                 n_events: int, reversals: np.ndarray, F0: float, step: str, seconds: float) -> None:
        self.model, self.t, self.x, self.F, self.reversals = model, t, x, F, reversals
        self.n_events, self.F0, self.step, self.seconds = int(n_events), float(F0), step, float(seconds)
        for a in (t, x):  # the motion that the states made on first access follow
            a.flags.writeable = False
        self._made: dict[str, object] = {}
        self._makers = {"v": v, "detail": detail}
        self._lock = threading.Lock()

    def _get(self, key: str) -> object:
        """The value ``key`` (``"v"``, or ``"detail"``: states, flags, events), made once on first
        access (thread-safe)."""
        with self._lock:
            if key not in self._made:
                maker = self._makers[key]
                made = maker() if callable(maker) else maker
                if key == "detail":
                    X, ev = made
                    nz = self.model.n_states
                    made = (X[:, :nz], X[:, nz:], ev)
                self._made[key] = made
            return self._made[key]

    def __reduce__(self) -> tuple:
        """Pickled with its states made (a result travels to and from worker processes)."""
        states, flags, events = self._split()
        return (AlongResult, (self.model, self.t, self.x, self.F, self.v, (np.hstack((states, flags)), events),
                              self.n_events, self.reversals, self.F0, self.step, self.seconds))

    @property
    def v(self) -> np.ndarray:
        """Velocity [m/s] at every sample that the rate-dependent part of the force used."""
        return self._get("v")  # type: ignore[return-value]

    def _split(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self._get("detail")  # type: ignore[return-value]

    @property
    def states(self) -> np.ndarray:
        """The model's continuous states ``z`` at every sample, shape ``(n, n_states)`` (normalised)."""
        return self._split()[0]

    @property
    def flags(self) -> np.ndarray:
        """The model's flags ``m`` (0 or 1) at every sample, shape ``(n, n_flags)``."""
        return self._split()[1]

    @property
    def events(self) -> np.ndarray:
        """Number of model events in the interval that ends at each sample (0 at the first)."""
        return self._split()[2]

    def __repr__(self) -> str:
        return (f"AlongResult({type(self.model).__name__}: {self.t.size} samples over {self.t[-1] - self.t[0]:.4g} s, "
                f"F in [{self.F.min():.4g}, {self.F.max():.4g}] N, {self.reversals.size} reversals, "
                f"{self.n_events} events, {self.step} steps)")

    def summary(self) -> str:
        """A few lines: the model, the motion, the force range, reversals, events and run time."""
        span = np.ptp(self.x)
        return "\n".join([
            f"friction along a prescribed motion: {self.model!r}",
            f"  motion: {self.t.size} samples, t in [{self.t[0]:.6g}, {self.t[-1]:.6g}] s, "
            f"x span {span:.4g} m, {self.reversals.size} reversals",
            f"  force: F in [{self.F.min():.6g}, {self.F.max():.6g}] N from F0 = {self.F0:.6g} N",
            f"  model events: {self.n_events}; step: {self.step}; run {self.seconds * 1e3:.3g} ms",
        ])

    def plot(self, path: str | Path = "along.png") -> Path:
        """The force against the position (hysteresis) and against time, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "along.png"
            Image file to write (the format from the suffix).

        Returns
        -------
        Path
            The file written.
        """
        from prefriction.plotting import length_unit, new_figure

        fig, axes = new_figure(1, 2, size=(9.0, 3.8))
        ax1, ax2 = axes[0]
        scale, unit = length_unit(self.x)
        ax1.plot(self.x * scale, self.F, lw=1.0, color="C0")
        ax1.set_xlabel(f"position x [{unit}]")
        ax1.set_ylabel("friction force F [N]")
        ax2.plot(self.t, self.F, lw=1.0, color="C0")
        if self.reversals.size and self.reversals.size <= 200:
            ax2.plot(self.t[self.reversals], self.F[self.reversals], "o", ms=3, color="C3", label="reversals")
            ax2.legend(loc="best", frameon=True)
        ax2.set_xlabel("time t [s]")
        ax2.set_ylabel("friction force F [N]")
        for ax in (ax1, ax2):
            ax.grid(alpha=0.3)
        fig.suptitle(f"{type(self.model).__name__} along the motion ({self.t.size} samples)", fontsize=10)
        from prefriction.plotting import write_figure

        out = write_figure(fig, path)
        return out
