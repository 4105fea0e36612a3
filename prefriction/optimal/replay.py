"""Replay of a force through :func:`prefriction.simulate`: where the stage really ends."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from prefriction.models import Oscillator
from prefriction.signals import Signal
from prefriction.simulation.simulate import SimulationResult, simulate

__all__ = ["Replay", "replay"]


@dataclass(frozen=True, repr=False)
class Replay:
    """The stage driven by a force through :func:`prefriction.simulate`, compared with a target.

    Attributes
    ----------
    t_final : float
        Time of the comparison [s].
    x_error : float
        Position at ``t_final`` minus the target [m].
    v_final : float
        Velocity at ``t_final`` [m/s].
    F_final : float
        Friction force at ``t_final`` [N].
    run : SimulationResult
        The simulation, with dense samples ``t, x, v, F`` on ``[0, t_final]`` (for plots).
    """

    t_final: float
    x_error: float
    v_final: float
    F_final: float
    run: SimulationResult

    def summary(self) -> str:
        """One line: the miss in position [nm], the final velocity [m/s] and force [N]."""
        return (f"replay at t = {self.t_final:.6g} s: position error {self.x_error * 1e9:.3g} nm, "
                f"velocity {self.v_final:.3g} m/s, friction {self.F_final:.3g} N")

    def __repr__(self) -> str:
        return f"Replay(x_error={self.x_error:.3g} m, v_final={self.v_final:.3g} m/s, F_final={self.F_final:.3g} N)"


def replay(system: Oscillator, u: Signal, t_final: float, distance: float, *, rtol: float = 1e-10,
           samples: int = 400) -> Replay:
    """Drive the resting stage ``system`` with the force ``u`` through :func:`prefriction.simulate`.

    Parameters
    ----------
    system : Oscillator
        The stage (its own input ``u`` is replaced), at rest at ``x = 0`` with no friction force.
    u : Signal
        Force [N], e.g. the ``u`` of a :class:`PointToPointResult`.
    t_final : float
        End of the comparison [s], ``> 0``.
    distance : float
        Target position [m].
    rtol : float, default 1e-10
        Tolerance of the simulation (see :func:`prefriction.simulate`).
    samples : int, default 400
        Number of dense samples on ``[0, t_final]`` (the last one at ``t_final``).

    Returns
    -------
    Replay
    """
    stage = Oscillator(system.friction, mass=system.mass, u=u)
    times = np.linspace(0.0, t_final, samples)
    run = simulate(stage, 0.0, t_end=t_final, rtol=rtol, dense=times)
    return Replay(t_final=float(t_final), x_error=float(run.x[-1] - distance), v_final=float(run.v[-1]),
                  F_final=float(run.F[-1]), run=run)
