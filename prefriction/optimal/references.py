"""The moves a user gets without the pre-sliding model: tanh-smoothed Coulomb friction in the
optimiser (:func:`smoothed_point_to_point`) and the Coulomb bang-bang profile (:func:`bang_bang`)."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Optional

import casadi as ca
import numpy as np

from prefriction._validation import check_count, check_positive
from prefriction.models import Oscillator
from prefriction.optimal.guess import bang_bang_signal, coulomb_times, guess_forces
from prefriction.optimal.problem import MAX_ITER, check_move
from prefriction.optimal.replay import replay
from prefriction.optimal.result import PointToPointResult
from prefriction.optimal.solve import Setup, optimise
from prefriction.optimal.transcription import Phase, Transcription
from prefriction.units import Scales

__all__ = ["bang_bang", "smoothed_point_to_point"]


def smoothed_point_to_point(system: Oscillator, distance: float, *, u_max: float, v_smooth: float,
                            objective: str = "time", t_final: Optional[float] = None, intervals: int = 24,
                            substeps: int = 8, max_iter: int = 500) -> PointToPointResult:
    """The move of :func:`point_to_point` with the friction replaced by ``Fc tanh(v / v_smooth)``.

    The common shortcut of optimal control with friction: a smooth static curve, one phase, no
    state. The optimiser's stage ends at ``x = distance``, ``v = 0`` (where the smoothed friction
    vanishes); ``result.replay`` drives the real stage (``system.friction``) with the force
    through :func:`prefriction.simulate` and shows where it ends.

    Parameters
    ----------
    system : Oscillator
        The stage; its friction model gives ``Fc`` [N] here and the replay.
    distance : float
        Displacement [m], nonzero.
    u_max : float
        Force limit [N], above the model's ``max_hysteretic_force``.
    v_smooth : float
        Velocity scale of the smoothing [m/s], ``> 0`` (``tanh`` reaches 0.76 at ``v_smooth``).
    objective, t_final, intervals, substeps, max_iter
        As for :func:`point_to_point`.

    Returns
    -------
    PointToPointResult
        ``method = "tanh"``; ``F`` is the smoothed friction at the nodes [N].

    Examples
    --------
    >>> import prefriction as pf
    >>> stage = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)
    >>> move = pf.optimal.smoothed_point_to_point(stage, 1e-3, u_max=5.0, v_smooth=1e-3)
    >>> abs(move.replay.x_error) > 1e-7        # misses by more than 100 nm
    True
    """
    distance, u_max, objective, t_final, intervals, substeps = check_move(
        system, distance, u_max, objective, t_final, intervals, substeps)
    v_smooth = check_positive("v_smooth", v_smooth)
    max_iter = check_count("max_iter", max_iter, 1, MAX_ITER)
    sc = Scales.of(system)
    vs, d = v_smooth / sc.v, distance / sc.x

    def rhs(y: ca.SX, u: ca.SX) -> ca.SX:
        return ca.vertcat(y[1], u - ca.tanh(y[1] / vs))

    modes = (math.copysign(1.0, distance),)
    T0, U0 = guess_forces(modes, distance, u_max, system.friction.Fc, system.mass, intervals, t_final, sc.t)
    t_total = None if t_final is None else t_final / sc.t

    def build(m: int) -> Transcription:
        return Transcription([Phase(rhs=rhs)], 2, intervals=intervals, substeps=m, y0=[0.0, 0.0],
                             jump=lambda y, k: y, final=lambda y: ca.vertcat(y[0] - d, y[1]),
                             u_max=u_max / sc.F, objective=objective, t_total=t_total, t_min=1e-6)

    setup = Setup("tanh", objective, system, distance, modes, lambda y, k: math.tanh(y[1] / vs), T0, U0)
    return optimise(setup, build, substeps=substeps, tol=None, max_iter=max_iter)


def bang_bang(system: Oscillator, distance: float, *, u_max: float) -> PointToPointResult:
    """The minimum-time force against Coulomb friction ``Fc``, no pre-sliding: ``+-u_max``, one switch.

    Accelerate with ``u_max`` for ``t1``, brake with ``-u_max`` for ``t2 = t1 (u_max - Fc) / (u_max + Fc)``,
    ``t1 = sqrt(2 m |distance| / ((u_max - Fc) (1 + (u_max - Fc) / (u_max + Fc))))``, then no force.
    ``result.replay`` drives the real stage with it through :func:`prefriction.simulate`.

    Parameters
    ----------
    system : Oscillator
        The stage; its friction model gives ``Fc`` [N] here and the replay.
    distance : float
        Displacement [m], nonzero.
    u_max : float
        Force limit [N], above the model's ``max_hysteretic_force``.

    Returns
    -------
    PointToPointResult
        ``method = "bang-bang"``, nodes at the start, the switch and the stop (Coulomb model;
        ``F`` the sliding friction ``sign(distance) Fc`` [N]); no IPOPT.

    Examples
    --------
    >>> import prefriction as pf
    >>> stage = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)
    >>> move = pf.optimal.bang_bang(stage, 1e-3, u_max=5.0)
    >>> round(move.t_final * 1e3, 3)                                  # ms
    28.868
    """
    distance, u_max, *_ = check_move(system, distance, u_max, "time", None, 4, 1)
    Fc, m = system.friction.Fc, system.mass
    s = math.copysign(1.0, distance)
    t1, t2 = coulomb_times(distance, u_max, Fc, m)
    u, t_final = bang_bang_signal(distance, u_max, Fc, m)
    a1 = (u_max - Fc) / m
    x1 = s * 0.5 * a1 * t1 * t1
    result = PointToPointResult(
        method="bang-bang", objective="time", distance=distance, u=u, t_final=t_final,
        t=np.array([0.0, t1, t_final]), x=np.array([0.0, x1, distance]), v=np.array([0.0, s * a1 * t1, 0.0]),
        F=np.full(3, s * Fc), modes=(s,), durations=np.array([t_final]),
        effort=u_max * u_max * t_final, iterations=0, solve_time=0.0,
    )
    return replace(result, replay=replay(system, u, t_final, distance))
