"""Optimal point-to-point motion through pre-sliding friction: :func:`point_to_point`."""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import casadi as ca
import numpy as np

from prefriction._validation import check_choice, check_count, check_finite, check_positive
from prefriction.models import Oscillator
from prefriction.models.oscillator import check_oscillator
from prefriction.optimal.guess import MAX_PHASES, guess_forces, modes_from_simulation
from prefriction.optimal.result import PointToPointResult
from prefriction.optimal.solve import MAX_SUBSTEPS, Setup, optimise
from prefriction.optimal.transcription import Phase, Transcription
from prefriction.symbolic import branch_functions
from prefriction.units import Scales

__all__ = ["point_to_point", "check_move", "MAX_INTERVALS", "MAX_ITER"]

MAX_INTERVALS = 200
"""Most control intervals per phase."""
MAX_ITER = 10_000
"""Largest IPOPT iteration limit."""


def check_move(system: Any, distance: Any, u_max: Any, objective: Any, t_final: Any, intervals: Any,
               substeps: Any) -> tuple:
    """Validated ``(distance, u_max, objective, t_final, intervals, substeps)`` of a move."""
    friction = check_oscillator(system, "point_to_point")
    if system.forced:
        raise ValueError(f"system.u must be None (the optimal force is the input), got {system.u!r}")
    distance = check_finite("distance", distance)
    if distance == 0.0:
        raise ValueError("distance must be a nonzero finite number [m], got 0.0")
    u_max = check_positive("u_max", u_max)
    if not u_max > friction.max_hysteretic_force:
        raise ValueError(
            f"u_max must exceed the largest friction force of {type(friction).__name__}, "
            f"{friction.max_hysteretic_force!r} N (else the stage cannot break away), got {u_max!r}"
        )
    objective = check_choice("objective", objective, ("time", "effort"))
    if objective == "effort":
        if t_final is None:
            raise ValueError("objective='effort' needs t_final [s] (the duration of the move), got None")
        t_final = check_positive("t_final", t_final)
    elif t_final is not None:
        raise ValueError(f"t_final is the result of objective='time'; pass t_final=None, got {t_final!r}")
    intervals = check_count("intervals", intervals, 4, MAX_INTERVALS, "the NLP grows with it")
    substeps = check_count("substeps", substeps, 1, MAX_SUBSTEPS, "the NLP grows with it")
    return distance, u_max, objective, t_final, intervals, substeps


def check_modes(modes: Any, distance: float) -> tuple:
    """Validated mode sequence: alternating signs +-1.0, 2 to :data:`MAX_PHASES` phases, the last
    one away from the target (the friction force unloads on it)."""
    if isinstance(modes, (str, bytes)) or not isinstance(modes, Sequence):
        raise TypeError(f"modes must be a sequence of velocity signs +1/-1, got {modes!r}")
    out = tuple(float(s) for s in modes)
    if not 2 <= len(out) <= MAX_PHASES or any(s not in (1.0, -1.0) for s in out):
        raise ValueError(f"modes must hold 2 to {MAX_PHASES} signs, each +1 or -1, got {modes!r}")
    if any(a == b for a, b in zip(out, out[1:])):
        raise ValueError(f"modes must alternate in sign (each phase ends at a reversal), got {modes!r}")
    if out[-1] == math.copysign(1.0, distance):
        raise ValueError(
            f"the last of modes must point away from the target (sign {-math.copysign(1.0, distance):+.0f}): the "
            f"stage ends unloaded, with zero friction force, only after a reversal; got {modes!r}"
        )
    return out


def point_to_point(system: Oscillator, distance: float, *, u_max: float, objective: str = "time",
                   t_final: Optional[float] = None, modes: Optional[Sequence[float]] = None,
                   intervals: int = 24, substeps: int = 8, tol: Optional[float] = 1e-9,
                   max_iter: int = 500) -> PointToPointResult:
    """Minimum-time or minimum-effort move of a stage through pre-sliding friction, with IPOPT.

    The stage ``m x'' = u - F`` (2.1) starts at rest at ``x = 0`` with no friction force and must
    end at rest at ``x = distance`` with no friction force (so that ``u = 0`` holds it there),
    under ``|u| <= u_max``. The friction model keeps its branch structure: the move is split into
    phases of one velocity sign each (``modes``), joined at reversals where the velocity is zero
    and the model resets its state (the ``reset`` of :func:`prefriction.symbolic.branch_functions`); the phase
    durations (the switching times) are decision variables. Each phase is transcribed by multiple
    shooting with ``intervals`` control intervals of constant force and ``substeps`` RK4 steps
    each, in the normalised units of :class:`prefriction.Scales`.

    The force is then replayed through :func:`prefriction.simulate` (``result.replay``); while it
    misses the target by more than ``tol`` or ends with a speed above ``1e-8`` of the peak speed
    (simulate's default ``rtol``), the problem is solved again with twice the substeps.

    Parameters
    ----------
    system : Oscillator
        The stage: mass [kg] and friction model, without input ``u``. The model must have no
        flags or in-branch events: :class:`prefriction.Dahl` with ``gamma >= 1`` or
        :class:`prefriction.LuGre`.
    distance : float
        Displacement [m], nonzero.
    u_max : float
        Force limit [N], above the model's ``max_hysteretic_force`` (Dahl: ``Fc``, LuGre: ``Fs``).
    objective : {"time", "effort"}
        Minimise the duration, or ``int u^2 dt`` [N^2 s] over the duration ``t_final``.
    t_final : float, optional
        Duration [s] of a minimum-effort move (required for ``objective="effort"``, else None).
    modes : sequence of {+1, -1}, optional
        Velocity sign of each phase, alternating, the last away from the target. Default: the
        branches of the Coulomb bang-bang force simulated with the model, plus the unloading phase.
    intervals : int, default 24
        Control intervals per phase (4 to :data:`MAX_INTERVALS`).
    substeps : int, default 8
        RK4 steps per interval at the first solve (1 to 64).
    tol : float or None, default 1e-9
        Largest accepted miss of the replayed force [m] (1 nm); None: accept the first solution.
    max_iter : int, default 500
        IPOPT iteration limit (1 to :data:`MAX_ITER`).

    Returns
    -------
    PointToPointResult
        ``u`` (a :class:`prefriction.signals.ZeroOrderHold` [N]), ``t_final`` [s], the nodes
        ``t, x, v, F``, IPOPT's iterations and time, and the replay.

    Raises
    ------
    TypeError, ValueError
        On bad input (the message names the argument, its value and the allowed range).
    prefriction.SolverError
        If IPOPT fails or the replay misses by more than ``tol`` at the finest integration.

    Examples
    --------
    >>> import prefriction as pf
    >>> stage = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)      # N/m, N, kg
    >>> move = pf.optimal.point_to_point(stage, 1e-3, u_max=5.0)          # 1 mm, 5 N
    >>> abs(move.replay.x_error) < 1e-9
    True
    """
    distance, u_max, objective, t_final, intervals, substeps = check_move(
        system, distance, u_max, objective, t_final, intervals, substeps)
    tol = None if tol is None else check_positive("tol", tol)
    max_iter = check_count("max_iter", max_iter, 1, MAX_ITER)
    model = system.friction
    if model.n_flags or model.n_events:
        raise ValueError(
            f"point_to_point needs a friction model without flags or in-branch events (Dahl with gamma >= 1, "
            f"LuGre), got {model!r} with {model.n_flags} flags and {model.n_events} events"
        )
    modes = modes_from_simulation(system, distance, u_max) if modes is None else check_modes(modes, distance)
    sc = Scales.of(system)
    branches = {s: branch_functions(system, s) for s in (1.0, -1.0)}  # the model's CasADi Functions
    q, nz, d = branches[1.0].q, model.n_states, distance / sc.x
    no_flags = ca.DM(0, 1)

    def rhs(s: float):
        b = branches[s]

        def f(y: ca.SX, u: ca.SX) -> ca.SX:
            z = y[2:]
            return ca.vertcat(y[1], u - b.force(z, no_flags, y[1], q), b.rate(z, no_flags, y[1], q))
        return f

    phases = [Phase(rhs=rhs(s), path=lambda y, s=s: s * y[1]) for s in modes]

    def jump(y: ca.MX, k: int) -> ca.MX:  # the reversal that ends phase k - 1
        return ca.vertcat(y[0], y[1], branches[modes[k - 1]].reset(y[2:], no_flags, q, 1e-12)[0])

    def final(y: ca.MX) -> ca.MX:
        return ca.vertcat(y[0] - d, y[1], branches[modes[-1]].force(y[2:], no_flags, 0.0, q))

    z0, _ = model.initial_state(0.0, modes[0])
    t_total = None if t_final is None else t_final / sc.t
    T0, U0 = guess_forces(modes, distance, u_max, model.Fc, system.mass, intervals, t_final, sc.t)

    def build(m: int) -> Transcription:
        return Transcription(phases, 2 + nz, intervals=intervals, substeps=m, y0=[0.0, 0.0, *z0], jump=jump,
                             final=final, u_max=u_max / sc.F, objective=objective, t_total=t_total, t_min=1e-6)

    def force(y: np.ndarray, k: int) -> float:
        return float(branches[modes[k]].force(y[2:], no_flags, y[1], q))

    setup = Setup("pre-sliding", objective, system, distance, modes, force, T0, U0)
    return optimise(setup, build, substeps=substeps, tol=tol, max_iter=max_iter)
