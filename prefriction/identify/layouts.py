"""The layouts of one multiple-shooting fit of a record: the chain whole, the chain cut after the
long hovers (:mod:`prefriction.identify.hovers`), and the record's moves alone
(:func:`prefriction.identify.pieces.moves_of`), each started from the estimates of the one before
where that one did not converge (:func:`solve_layouts`)."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from prefriction.identify.data import Motion
from prefriction.identify.derivatives import derivatives as filtered_derivatives
from prefriction.identify.hovers import long_hovers
from prefriction.identify.motion_start import derivatives_of
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.pieces import breaks_of, describe_moves, moves_of
from prefriction.identify.shooting import (_NODE_WINDOW, SEGMENT, MotionSolution, _solve_record, _substeps,
                                           node_starts)
from prefriction.models.base import FrictionModel

__all__ = ["MISFIT", "solve_layouts"]


def solve_layouts(model: FrictionModel, data: Motion, space: ParameterSpace, theta0: np.ndarray, n_sub: int | None,
                  max_iter: int, tol: float, reversals: Any, progress: Any, weight: float,
                  steps: list[str], least_sub: int = 1, moves_first: bool = False) -> MotionSolution:
    """:func:`_solve_record` with the chain whole; if that does not converge and the record has
    long hovers (:func:`prefriction.identify.hovers.hover_nodes`), again from its estimates with
    the chain cut there (the continuity through a long hover is piecewise smooth on the scale of
    the defects; a chain kept whole where it converges keeps the information the rests carry); if
    that does not converge either, or converges to a misfit above :data:`MISFIT` times the
    record's noise (a local minimum), the record's moves alone, every rest left out
    (:func:`_without_hovers`; an ordinary record only, not a window of pieces). Notes go to
    ``steps``; ``least_sub``: fewest automatic sub-steps (those a window's fit found necessary).
    ``moves_first``: the stage before (a window, or the record with parameters held) converged on
    its moves (:attr:`MotionSolution.moves_converged`), so the moves are fitted first, from
    ``theta0``, and the chains only if that fit does not explain the record (a chain through rests
    that did not close for the stage before costs most of a fit's time and closes rarely from its
    estimates)."""
    pieces = breaks_of(data).size > 0   # a window of pieces keeps its layout: no moves step
    _x, v, _a = derivatives_of(data, _NODE_WINDOW)
    K = min(SEGMENT, len(data) - 1)
    nodes = node_starts(len(data), K)
    rests = long_hovers(np.abs(v), nodes, K, least=1)   # every rest left out: see _without_hovers
    if moves_first and not pieces and (moves := moves_of(data, rests, K)) is not None:
        first = _moves_fit(data, moves, space, theta0, n_sub, max_iter, tol, reversals, progress, least_sub)
        if first[1]:
            steps.append(f"samples {len(data)}: the stage before converged on its moves; the "
                         f"{len(data) - len(moves)} samples of rests left out, {describe_moves(moves)}, "
                         f"from its estimates: {first[2]}")
            return first[0]
        steps.append(f"samples {len(data)}: the stage before converged on its moves; this record's moves from "
                     f"its estimates {first[2]}: the chains then")
    sol = _solve_record(model, data, space, theta0, n_sub, max_iter, tol, reversals, progress, weight, False,
                        least_sub)
    if n_sub is None and model.n_events:
        sol = _event_substeps(data, space, sol, max_iter, tol, reversals, progress, steps)
    if sol.success:
        return sol
    long = long_hovers(np.abs(v), nodes, K)
    cut = int(long[:-1].sum())     # the nodes after them (hover_nodes)
    theta = sol.w[: space.n_free]
    if not cut or not np.all(np.isfinite(theta)):
        return sol
    again = _solve_record(space.build(space.values(theta)), data, space, theta, n_sub, max_iter, tol, reversals,
                          progress, 10.0, True, max(least_sub, sol.n_sub))
    rms, noise = _misfit(again, data)
    explains = again.success and (pieces or rms <= MISFIT * noise)
    steps.append(f"samples {len(data)}: the whole chain did not converge ({sol.message[-160:]}); the {cut} nodes after "
                 f"the segments of long hovers then started pieces of the chain, from its estimates: "
                 + ("converged" if explains else f"converged to a misfit of {rms:.3g} m rms, more than {MISFIT:g} "
                    f"times the record's position noise ({noise:.3g} m): a local minimum" if again.success
                    else "did not converge either"))
    best = again if again.success else sol
    if explains or pieces:
        return best
    return _without_hovers(data, moves_of(data, rests, K), space, best, n_sub, max_iter, tol, reversals, progress,
                           steps, least_sub)


def _misfit(sol: MotionSolution, data: Motion) -> tuple[float, float]:
    """The rms residual [m] of ``sol`` and the position noise [m] of ``data``
    (:func:`prefriction.identify.derivatives.derivatives`), compared through :data:`MISFIT`."""
    return float(np.sqrt(np.mean(np.square(sol.residuals)))), filtered_derivatives(data.t, data.x).noise


def _without_hovers(data: Motion, moves: Motion | None, space: ParameterSpace, sol: MotionSolution,
                    n_sub: int | None, max_iter: int, tol: float, reversals: Any, progress: Any, steps: list[str],
                    least_sub: int) -> MotionSolution:
    """The fit of the record's ``moves`` alone, every rest left out (:func:`prefriction.identify.pieces.moves_of`;
    ``None``: ``sol``), from the estimates of ``sol``: where the chain cut at the long hovers stopped, or where it
    converged to a misfit above :data:`MISFIT` times the noise; kept if it converges within that misfit (its
    :attr:`MotionSolution.data` the moves), else ``sol``.

    In a long hover a stage with a stiff reversal branch (Dahl ``gamma > 1``: ``2^gamma sigma``)
    swings back on it and then creeps at a fraction of ``Fc``, its velocity changing sign many
    times below the encoder step, so each hovering segment's positions depend on its start state
    steeply and not monotonically: with free states at its nodes (the cut chain) every such
    segment still adds residuals with many local minima. Left out, the hovers add nothing (their
    positions stay within the encoder step) and each move starts a piece of the chain with its own
    free position, velocity and state. A short rest kept inside a move's piece traps the whole
    piece the same way (a fit of a move, a 60-sample rest and the next move from the truth ends at
    1.6 times the measurement error, with the rest left out at 1.0 times), so every rest is left
    out, not only the long hovers. Measured on the 2.5 kg, 2 kHz, 10 nm closed-loop Dahl
    ``gamma = 2`` stage at 2,500 samples (docs/identify_motion.md#how-the-fit-works)."""
    if moves is None:
        return sol
    third, explains, said = _moves_fit(data, moves, space, sol.w[: space.n_free], n_sub, max_iter, tol, reversals,
                                       progress, max(least_sub, sol.n_sub))
    kept = "the cut chain's" if sol.success else "the whole chain's"
    steps.append(f"samples {len(data)}: the {len(data) - len(moves)} samples of rests then left out, "
                 f"{describe_moves(moves)}, from the estimates: {said}"
                 + ("" if explains else f", {kept} result kept"))
    return third if explains else dataclasses.replace(sol, moves_converged=third.success)


def _moves_fit(data: Motion, moves: Motion, space: ParameterSpace, theta: np.ndarray, n_sub: int | None,
               max_iter: int, tol: float, reversals: Any, progress: Any,
               least_sub: int) -> tuple[MotionSolution, bool, str]:
    """The fit of ``data``'s ``moves`` from the scaled parameters ``theta``: ``(solution, explains, note)``,
    ``explains`` when it converged within :data:`MISFIT` times the record's noise (the solution's
    :attr:`MotionSolution.data` then the moves)."""
    given = None if reversals is None else moves.to_piece_times(reversals)
    # the constraint weight of a fresh start: the moves' nodes start from the data, not from a converged chain
    # (measured from the whole chain's estimates at 2,500 samples: 0.01 converges in 119 evaluations, 10 does not)
    sol = _solve_record(space.build(space.values(theta)), moves, space, theta, n_sub, max_iter, tol, given,
                        progress, 0.01, False, least_sub)
    rms, noise = _misfit(sol, data)
    explains = sol.success and rms <= MISFIT * noise
    said = ("converged, FitResult.data holds the moves" if explains
            else f"converged to a misfit of {rms:.3g} m rms, more than {MISFIT:g} times the record's position "
                 f"noise ({noise:.3g} m): a local minimum" if sol.success else "did not converge")
    return (dataclasses.replace(sol, data=moves, moves_converged=True) if explains else sol), explains, said


MISFIT = 4.0
"""Largest rms residual of a fit of the chain cut at the long hovers or of the record's moves
(:func:`solve_layouts`, :func:`_without_hovers`), in units of the record's position noise
(:func:`prefriction.identify.derivatives.derivatives`: the standard deviation of the positions
about their low-pass), for the fit to be the result. Measured on the 2.5 kg, 2 kHz, 10 nm
closed-loop Dahl ``gamma = 2`` stage at 2,500 samples (noise 3.2e-9 m): the fit of the moves with
``gamma`` held at the truth ends within 0.074 % of every true value at 7.8e-9 m; a fit of the
moves with ``gamma`` free from the second start's estimates (at a constraint weight of 10) ended
with every parameter up to 10 % off at 2.1e-7 m, and a cut chain of the seed-2 record converged
with ``sigma`` and ``b`` 4.4 % off at 2.2e-7 m."""


def _event_substeps(data: Motion, space: ParameterSpace, sol: MotionSolution, max_iter: int, tol: float,
                    reversals: Any, progress: Any, steps: list[str]) -> MotionSolution:
    """A model with in-branch events keeps the sub-steps of its start (no doubling check,
    :func:`_refine_substeps`); where :func:`_substeps` at the estimates asks for more (a start's
    softer stiffness had chosen too few), the fit is solved again from the estimates with that many,
    kept if it converges or the first did not. Notes go to ``steps``."""
    theta = sol.w[: space.n_free]
    if not np.all(np.isfinite(theta)):
        return sol
    vals = space.values(theta)
    fitted = space.build(vals)
    _x, v, _a = derivatives_of(data, _NODE_WINDOW)
    need = _substeps(fitted, data, vals["mass"] if "mass" in space.free else float(data.mass), v, None)
    if need <= sol.n_sub:
        return sol
    again = _solve_record(fitted, data, space, theta, None, max_iter, tol, reversals, progress, 10.0, False, need)
    keep = again.success or not sol.success
    steps.append(f"samples {len(data)}: {sol.n_sub} RK4 sub-steps per sample from the start values, {need} from the "
                 f"estimates ({'converged' if sol.success else 'not converged'}); solved again from them with "
                 f"{again.n_sub}: {'converged' if again.success else 'did not converge'}, "
                 f"{'its result kept' if keep else 'the first result kept'}")
    return again if keep else sol
