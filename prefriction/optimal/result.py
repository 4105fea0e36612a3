"""Result of an optimal point-to-point motion: :class:`PointToPointResult`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from prefriction.optimal.replay import Replay
from prefriction.signals import ZeroOrderHold

__all__ = ["PointToPointResult"]


@dataclass(frozen=True, repr=False)
class PointToPointResult:
    """An optimal (or reference) force that moves a stage by ``distance`` and its trajectory.

    Attributes
    ----------
    method : str
        ``"pre-sliding"`` (the friction model, phases of one velocity sign),
        ``"tanh"`` (tanh-smoothed Coulomb friction) or ``"bang-bang"`` (Coulomb friction,
        no pre-sliding, closed form).
    objective : str
        ``"time"`` or ``"effort"``.
    distance : float
        Target displacement [m].
    u : ZeroOrderHold
        The force [N] as a signal that :func:`prefriction.simulate` accepts; 0 from ``t_final`` on.
    t_final : float
        Duration of the move [s].
    t, x, v, F : numpy.ndarray
        Times [s], positions [m], velocities [m/s] and friction forces [N] at the nodes of the
        solution (as the optimiser's model sees them).
    modes : tuple of float
        Velocity sign of each phase.
    durations : numpy.ndarray
        Duration of each phase [s].
    effort : float
        ``int u^2 dt`` over the move [N^2 s].
    iterations : int
        IPOPT iterations (all solves; 0 for the closed form).
    solve_time : float
        IPOPT wall time [s] (all solves).
    replay : Replay or None
        The force replayed through :func:`prefriction.simulate` with the stage's friction model.
    """

    method: str
    objective: str
    distance: float
    u: ZeroOrderHold
    t_final: float
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    modes: tuple
    durations: np.ndarray
    effort: float
    iterations: int
    solve_time: float
    replay: Optional[Replay] = None

    def summary(self) -> str:
        """A few lines: method, duration, effort, solver work and the replayed miss."""
        lines = [
            f"{self.method} {self.objective}-optimal move of {self.distance * 1e3:.6g} mm: "
            f"t_final = {self.t_final * 1e3:.6g} ms, effort {self.effort:.6g} N^2 s",
            f"phases {''.join('+' if s > 0 else '-' for s in self.modes)} of "
            + ", ".join(f"{d * 1e3:.4g}" for d in self.durations) + " ms; "
            f"IPOPT {self.iterations} iterations, {self.solve_time:.3g} s",
        ]
        if self.replay is not None:
            lines.append(self.replay.summary())
        return "\n".join(lines)

    def plot(self, path: "str | Path" = "move.png") -> "Path":
        """The planned position, velocity and force (and the replay through the simulator), saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "move.png"
            Image file to write (the format from the suffix).

        Returns
        -------
        Path
            The file written.
        """
        from prefriction._result_plots import plot_move

        return plot_move(self, path)

    def __repr__(self) -> str:
        miss = "" if self.replay is None else f", miss={self.replay.x_error:.3g} m"
        return (f"PointToPointResult({self.method}, {self.objective}, t_final={self.t_final:.6g} s, "
                f"{len(self.modes)} phases{miss})")
