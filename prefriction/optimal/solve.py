"""The solve-and-check loop shared by the point-to-point problems: IPOPT, then a replay through
:func:`prefriction.simulate`, with finer integration until the replay lands within ``tol``."""

from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from typing import Callable, Optional

import numpy as np

from prefriction.errors import SolverError
from prefriction.models import Oscillator
from prefriction.optimal.replay import replay
from prefriction.optimal.result import PointToPointResult
from prefriction.optimal.transcription import Transcription
from prefriction.signals import ZeroOrderHold
from prefriction.units import Scales

__all__ = ["Setup", "optimise", "MAX_SUBSTEPS"]

MAX_SUBSTEPS = 64
"""Finest integration: RK4 substeps per control interval."""
V_RTOL = 1e-8
"""Largest accepted final velocity of the replay, relative to the peak velocity (simulate's default rtol)."""


@dataclass(frozen=True)
class Setup:
    """What :func:`optimise` needs besides the transcription: names, units, the friction force of
    a node (normalised state and phase index -> normalised force) and the first guess."""

    method: str
    objective: str
    system: Oscillator
    distance: float
    modes: tuple
    force: Callable[[np.ndarray, int], float]
    T0: np.ndarray
    U0: list


def _first_guess(tr: Transcription, setup: Setup) -> np.ndarray:
    """The first guess integrated from the start; while it is not finite (a phase of the wrong
    velocity sign drove the friction force past its bound and the next reversal's reset to NaN,
    e.g. Dahl gamma = 2 with 8 phases), the phases other than the main one (the longest) are
    shortened tenfold, at most 8 times."""
    T = np.array(setup.T0, dtype=float)
    w = tr.forward(T, setup.U0)
    main = int(np.argmax(T))
    for _ in range(8):
        if np.all(np.isfinite(w)):
            break
        T = np.where(np.arange(T.size) == main, T, 0.1 * T)
        w = tr.forward(T, setup.U0)
    return w


def optimise(setup: Setup, build: Callable[[int], Transcription], *, substeps: int, tol: Optional[float],
             max_iter: int) -> PointToPointResult:
    """Solve the transcription ``build(substeps)`` and replay the force; while the replay misses the
    target by more than ``tol`` [m] or ends faster than :data:`V_RTOL` of the peak speed
    (``tol = None``: no check), double the substeps and solve again from the solution."""
    sc = Scales.of(setup.system)
    tr = build(substeps)
    w = _first_guess(tr, setup)
    wall, iterations, lam = 0.0, 0, None
    while True:
        w, lam, stats, t_ipopt = tr.solve(w, max_iter=max_iter, tol=1e-10, lam=lam)
        wall, iterations = wall + t_ipopt, iterations + int(stats["iter_count"])
        if not stats["success"]:
            raise SolverError(
                f"IPOPT found no {setup.objective}-optimal {setup.method} move of {setup.distance!r} m "
                f"(phases {setup.modes}, {tr.N} intervals of {substeps} RK4 steps): {stats['return_status']} after "
                f"{stats['iter_count']} iterations. Try other modes, more intervals, a larger u_max or, "
                f"for objective='effort', a longer t_final"
            )
        result = _with_replay(_result(setup, tr, w, sc, iterations, wall), setup.system)
        if tol is None:
            return result
        if _lands(result, tol) or 2 * substeps > MAX_SUBSTEPS:
            break
        print(f"prefriction.optimal: replay ends {result.replay.x_error:.3g} m from the target at "
              f"{result.replay.v_final:.3g} m/s; solving again with {2 * substeps} RK4 steps per interval", file=sys.stderr)
        substeps *= 2
        tr = build(substeps)  # same variables: w and lam carry over
    if not _lands(result, tol):
        raise SolverError(
            f"the optimal force replayed through simulate ends {result.replay.x_error!r} m from the target "
            f"(tol = {tol!r} m) at {result.replay.v_final!r} m/s (allowed {V_RTOL} of the peak velocity) even with "
            f"{substeps} RK4 steps per interval: try more intervals or a larger tol"
        )
    return result


def _lands(result: PointToPointResult, tol: float) -> bool:
    """True if the replay ends within ``tol`` [m] of the target and at a speed below
    :data:`V_RTOL` of the peak speed."""
    return (abs(result.replay.x_error) <= tol
            and abs(result.replay.v_final) <= V_RTOL * float(np.max(np.abs(result.v))))


def _with_replay(result: PointToPointResult, system: Oscillator) -> PointToPointResult:
    return replace(result, replay=replay(system, result.u, result.t_final, result.distance))


def _result(setup: Setup, tr: Transcription, w: np.ndarray, sc: Scales, iterations: int,
            wall: float) -> PointToPointResult:
    """The result in SI units from the decision vector ``w``."""
    T, Y, U = tr.unpack(w)
    N = tr.N
    t, x, v, F, starts, forces = [], [], [], [], [], []
    offset = 0.0
    for k in range(tr.n_ph):
        nodes = offset + T[k] * np.arange(N + 1) / N
        first = 0 if k == 0 else 1  # a join's node is the previous phase's last
        t.extend(nodes[first:])
        x.extend(Y[k][0, first:])
        v.extend(Y[k][1, first:])
        F.extend(setup.force(Y[k][:, j], k) for j in range(first, N + 1))
        starts.extend(nodes[:-1])
        forces.extend(U[k])
        offset += T[k]
    u = ZeroOrderHold(np.array(starts + [offset]) * sc.t, np.array(forces + [0.0]) * sc.F, name="u", unit="N")
    effort = float(sum(T[k] / N * np.sum(U[k] ** 2) for k in range(tr.n_ph))) * sc.F ** 2 * sc.t
    return PointToPointResult(
        method=setup.method, objective=setup.objective, distance=setup.distance, u=u, t_final=offset * sc.t,
        t=np.array(t) * sc.t, x=np.array(x) * sc.x, v=np.array(v) * sc.v, F=np.array(F) * sc.F,
        modes=setup.modes, durations=np.asarray(T) * sc.t, effort=effort, iterations=iterations, solve_time=wall,
    )
