"""Continuation of a multiple-shooting fit (:mod:`prefriction.identify.shooting`): a long record's
first window, then the record; parameters the record pins only together with another
(:mod:`prefriction.identify.held_first`) held in the first stages and freed in the last.

A record longer than ``2 WINDOW`` samples fits its :data:`WINDOW` samples with the most reversals
first and starts the full record from their estimates (where that window holds fewer than two
reversals each way and the record turns while sliding, a window cut from pieces of the record
around its reversals first, :mod:`prefriction.identify.pieces`, :func:`_first_window`); held
parameters are held at their start values in the window and in a first fit of the full record,
and freed in the last. Each stage runs the layouts of :func:`prefriction.identify.layouts.solve_layouts`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from prefriction._blas_threads import with_one_blas_thread
from prefriction.errors import SolverError
from prefriction.identify.data import Motion
from prefriction.identify.layouts import solve_layouts
from prefriction.identify.motion_start import derivatives
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.pieces import PIECE_TOL, describe, moving_flips, piece_window
from prefriction.identify.polish import valley_secant
from prefriction.identify.shooting import (SEGMENT, MotionSolution, _at, _nuisance, _Problem, _progress, _tag,
                                           start_error)
from prefriction.models.base import FrictionModel

__all__ = ["LONG", "WINDOW", "fit_motion"]

WINDOW = 2_000
"""Samples of the window a longer record fits first (continuation): the full record starts from
its estimates, so it needs few iterations and its cost stays linear in the samples."""


LONG = 5_000
"""Records of at least this many samples report each iteration on stderr (long work)."""


_WINDOW = object()
"""Stands for the first window in the list of stages (known once it is fitted): with a held
start of the force balance (:mod:`prefriction.identify.balance_start`) a long record's window is
fitted again with every parameter free, and the record once, from those estimates. The record
with the parameters held (the short records' second stage) cost about half of a long fit: on the
25,000-sample closed-loop ``gamma = 2`` record (moves at the 2,500-sample pace, seeds 0 and 1)
the fits took 515 and 442 s of CPU with it and 302 and 196 s without (interpreted steps), to the
same largest errors and intervals (docs/identify_motion.md#time-and-memory-against-the-record-length)."""


@with_one_blas_thread
def fit_motion(model: FrictionModel, data: Motion, space: ParameterSpace, *, n_sub: int | None, max_iter: int,
               tol: float, reversals: Any = None, verbose: bool = False,
               held: ParameterSpace | None = None, held_iter: int | None = None) -> MotionSolution:
    """Multiple-shooting least-squares fit of ``space``'s free parameters to ``data``.

    Parameters
    ----------
    verbose : bool, default False
        One line per outer iteration of the solver on stderr (always for records of :data:`LONG`
        samples or more).
    held : ParameterSpace, optional
        ``space`` with some free parameters held at their start values
        (:func:`prefriction.identify.held_first.held_first`): the first stages (the window of a
        long record, then the whole record) fit this space, and the record is then fitted with
        every parameter of ``space`` free from their estimates. With ``held_iter`` (a held start of
        the force balance) and no given reversals, a long record's second stage is its window
        again with every parameter free (:data:`_WINDOW`), not the record held.
    held_iter : int, optional
        Most Jacobian evaluations of each layout of those first stages (default ``max_iter``): a
        stage that only settles the other parameters (:mod:`prefriction.identify.balance_start`)
        hands on its estimates where they follow the record more closely (:func:`closer_estimates`).

    Raises
    ------
    ValueError
        If given reversal times are invalid.
    prefriction.SolverError
        If the motion is not finite at the start values (a fit that does not converge returns
        with ``success = False`` instead).
    """
    steps: list[str] = []
    progress, t0 = (_progress if verbose or len(data) >= LONG else None), time.perf_counter()
    stages: list[tuple[Any, ParameterSpace, Any, str]] = []   # None: the first window; _WINDOW: it again
    long = len(data) > 2 * WINDOW
    what = "" if held is None else f" with {', '.join(n for n in space.free if n not in held.free)} held"
    if long:
        stages.append((None, space if held is None else held, reversals, "the first window"))
    if held is not None and long and held_iter is not None and reversals is None:
        stages.append((_WINDOW, space, None, "the first window with every parameter free"))
    elif held is not None:
        stages.append((data, held, reversals, f"the record{what}"))
    vals, least, weight, moved = dict(space.start), 1, 0.01, False
    on_moves = False   # a stage's moves converged: the next one fits the moves first
    fallback = None   # a short record's held stage: the solution if the free stage does not converge
    for i, (head, sp_k, given, name) in enumerate(stages):   # continuation (module notes, identify/held_first.py)
        at = sp_k.build(vals) if moved else model
        budget = max_iter if held_iter is None else min(max_iter, held_iter)
        if long and i == 0:
            stage, head, name = _first_window(at, data, sp_k, sp_k.theta_of(vals), n_sub, budget, tol, reversals,
                                              progress, t0, weight, steps, what)
            window = head
        elif head is _WINDOW:   # the window of the stage before, every parameter free: a free stage's budget
            head = window
            stage = solve_layouts(at, window, sp_k, sp_k.theta_of(vals), n_sub, max_iter, tol, None,
                                  _tag(progress, name, t0), weight, steps, least, on_moves)
        else:
            stage = solve_layouts(at, head, sp_k, sp_k.theta_of(vals), n_sub, budget, tol, given,
                                  _tag(progress, name, t0), weight, steps, least, on_moves)
        if head is data and stage.success:  # the full record with the held parameters held
            held_stage = (at, data if stage.data is None else stage.data, space,
                          dict(vals, **sp_k.values(stage.w[: sp_k.n_free])), stage, name)
            done = _settled_without(*held_stage) if long else None
            if done is not None:
                steps.append(done[1])
                return dataclasses.replace(done[0], steps=tuple(steps))
            fallback = None if long else held_stage
        on_moves = stage.moves_converged   # the next stage fits the moves first (solve_layouts)
        if not stage.success:
            closer = closer_estimates(data, space, vals, dict(vals, **sp_k.values(stage.w[: sp_k.n_free])))
            steps.append(f"continuation: the fit of {name} did not converge ({stage.message}); the next stage "
                         + ("started from its estimates, whose shooting segments follow the record more closely "
                            "than those of the values before it" if closer else "started from the values before it"))
            if closer:
                vals, moved = closer, True
            continue
        least, weight, moved = stage.n_sub, 10.0, True
        vals = dict(vals, **sp_k.values(stage.w[: sp_k.n_free]))
        steps.append(f"continuation: {name} fitted ({stage.message}); the next stage started from these estimates "
                     f"({_at(sp_k, stage.w)})")
    # the sub-steps of the full record from the last stage's estimates
    sol = solve_layouts(space.build(vals) if moved else model, data, space, space.theta_of(vals), n_sub, max_iter,
                        tol, reversals, _tag(progress, "the record", t0), weight, steps, least, on_moves)
    if not sol.success and fallback is not None and (done := _settled_without(*fallback)) is not None:
        steps.append(f"the fit with every parameter free did not converge ({sol.message[-160:]}); {done[1]}")
        return dataclasses.replace(done[0], steps=tuple(steps))
    return dataclasses.replace(sol, steps=tuple(steps))


def closer_estimates(data: Motion, space: ParameterSpace, before: dict[str, float],
            after: dict[str, float]) -> dict[str, float] | None:
    """``after`` (the estimates of a stage that did not converge) if its shooting segments follow
    ``data`` more closely than those of ``before`` (:func:`start_error`), else ``None``.

    A stage with Dahl's ``gamma`` held near the truth (at the force balance's estimate,
    :mod:`prefriction.identify.balance_start`) may stop in the rests of a closed loop and still
    bring the other parameters close: on the 2.5 kg, 2 kHz, 10 nm closed-loop stage at 2,500
    samples, the moves' fit with ``gamma`` held at 1.956 stopped after 200 evaluations with
    ``sigma`` 2.3 % off and every other estimate within 0.4 %, and the free stage from there
    converged within 0.01 % of every true value."""
    if not all(math.isfinite(v) for v in after.values()):
        return None
    try:
        errors = [start_error(space.build(v), data, space, space.theta_of(v)) for v in (after, before)]
    except (ValueError, SolverError):
        return None
    return after if errors[0] < errors[1] else None


def _first_window(model: FrictionModel, data: Motion, space: ParameterSpace, theta0: np.ndarray, n_sub: int | None,
                  max_iter: int, tol: float, reversals: Any, progress: Any, t0: float, weight: float,
                  steps: list[str], what: str) -> tuple[MotionSolution, Motion, str]:
    """The fit of a long record's first window (continuation): ``(solution, window, name)``.

    The window is one cut from pieces of the record around its reversals where
    :func:`prefriction.identify.pieces.piece_window` gives one (solved to at least
    :data:`prefriction.identify.pieces.PIECE_TOL`), else the busiest contiguous :data:`WINDOW`
    samples. When the pieces cannot start the record (:func:`_window_weak`) the contiguous window
    is fitted from the same start; the first fit that converges is kept when neither pins every
    parameter. Notes go to ``steps``; ``what`` names held parameters."""
    k0 = _busiest_window(data)
    part = slice(k0, k0 + WINDOW)
    inside = None if reversals is None else [r for r in reversals if data.t[k0] < r < data.t[k0 + WINDOW - 1]]
    span = f"samples {k0} to {k0 + WINDOW - 1}"
    choices: list[tuple[Motion, Any, str, str, float]] = [
        (Motion(data.t[part], data.x[part], data.u[part], data.mass, data.hold), inside, f"{span}{what}", span, tol)]
    pieces = piece_window(data, k0, WINDOW, SEGMENT)
    if pieces is not None:
        choices.insert(0, (pieces, None if reversals is None else pieces.to_piece_times(reversals),
                           f"{describe(pieces)}{what}", f"{len(pieces.source)} pieces around reversals",
                           max(tol, PIECE_TOL)))
    kept = None
    for k, (window, given, name, short, tol_k) in enumerate(choices):
        stage = solve_layouts(model, window, space, theta0, n_sub, max_iter, tol_k, given, _tag(progress, short, t0),
                              weight, steps)
        weak = _window_weak(stage, space)
        if kept is None or (stage.success and not kept[0].success):
            kept = (stage, window, name)
        if not weak:
            return stage, window, name
        if k + 1 < len(choices):
            steps.append(f"continuation: the fit of {name} {weak}: the first window is {choices[k + 1][2]} instead")
    return kept


def _window_weak(stage: MotionSolution, space: ParameterSpace) -> str:
    """Why the fit ``stage`` of a long record's first window cannot start the record: it did not
    converge, or it leaves a free parameter of ``space`` unpinned (relative standard error above
    50 % under white residuals, :func:`prefriction.identify.statistics.gauss_newton`; measured: the
    busiest contiguous window of a 25,000-sample 0.3 kg open-loop Dahl + viscous + offset record
    converges without pinning ``sigma``, and the record started from it ends with ``sigma`` 99 %
    low); ``""`` when it can."""
    from prefriction.identify.statistics import gauss_newton

    if not stage.success:
        return f"did not converge ({stage.message[-160:]})"
    theta = stage.w[: space.n_free]
    at = space.values(theta)
    Jp, sc = space.physical_jacobian(stage.jacobian, theta)
    stats = gauss_newton(Jp, stage.residuals, space.free, np.array([at[n] for n in space.free]), sc, limit=0.5)
    loose = "; ".join(f"{n}: {why}" for n, why in stats.unidentifiable)
    return f"converged without pinning every parameter ({loose})" if loose else ""


def _settled_without(at: FrictionModel, data: Motion, space: ParameterSpace, after: dict,
                     stage: MotionSolution, name: str) -> tuple[MotionSolution, str] | None:
    """The solution ``stage`` of a long record with the held parameters held (started at the model
    ``at``, ended at the values ``after``, its nodes in the scales of ``stage.problem``) as a solution of ``space`` (every
    parameter free), when the record does not pin every parameter there and the pinned estimates
    sit within :data:`prefriction.identify.settled.SETTLED` standard errors of the minimum of the
    linearised problem with every parameter free: ``(solution, note)``, else ``None`` (the free
    stage runs).

    In the flat valley of the held parameters (:mod:`prefriction.identify.held_first`) the free
    stage of a long record creeps for hundreds of evaluations (measured: 25,000 GMS(2) samples,
    more than 5 min of CPU) and ends where this point already is; the statistics at it, with every
    parameter free, report the ones the record does not pin with their full spread."""
    from prefriction.identify.settled import SETTLED, unsettled
    from prefriction.identify.statistics import gauss_newton, widen_statistics

    held = stage.problem
    if held is None:
        return None
    mass_free = "mass" in space.start and "mass" in space.free
    prob = _Problem(at, space, data, held.lay, stage.n_sub, mass_free, held.mass, held.xs, held.native)
    prob.first_flags, prob.gw = list(held.first_flags), held.gw
    prob.args["m0"] = held.args["m0"].copy()
    xs, mass = held.xs, held.mass
    theta = space.theta_of(after)
    w = np.r_[theta, stage.w[held.nth:]]
    r, _g, out = prob.residuals(w)
    if not (r.size == stage.residuals.size and np.allclose(r * xs, stage.residuals, rtol=1e-6,
                                                            atol=1e-9 * float(np.max(np.abs(stage.residuals))))):
        return None    # the held values do not give the stage's motion in the free space: run the free stage
    J = prob.reduced_jacobian(w)
    Jp, sc = space.physical_jacobian(J * xs, theta)
    est = np.array([after[n] for n in space.free])
    stats = gauss_newton(Jp, r * xs, space.free, est, sc, limit=0.5, covariance="hac")
    widen = valley_secant(prob, w, J, r, space, at, stage.n_sub, mass_free, stats)
    if widen:
        stats = widen_statistics(stats, space.free, est, widen, 0.5)
    loose = {n for n, _ in stats.unidentifiable}
    if not loose or unsettled(Jp, r * xs, space.free, sc, stats.stderr, np.array([n not in loose for n in space.free])):
        return None
    pred, vel = out["X"][0, prob.rows], out["X"][1, prob.rows]
    said = "" if not widen else (" (" + ", ".join(f"{n}'s standard error widened {f:.3g} times" for n, f in widen.items())
                                 + ": along the valley the sum of squares rises less than its linearisation says, "
                                 "identify/polish.py)")
    return (MotionSolution(w, r * xs, J * xs, None, pred, _nuisance(at, space, w, prob, data, vel, mass_free, mass),
                           stage.message, True, n_sub=stage.n_sub, widen=widen, problem=prob,
                           data=stage.data),
            f"continuation: the fit of {name} is the solution: with every parameter free the record does not pin "
            f"{', '.join(sorted(loose))} there either{said}, and the other estimates sit within "
            f"{SETTLED:g} standard errors of the linearised minimum (identify/settled.py), so no free stage was run")


def _busiest_window(data: Motion) -> int:
    """First sample of the :data:`WINDOW`-sample window (starts every ``WINDOW / 4`` samples) with
    the most velocity reversals of the smoothed positions, then the most travel: the part of the
    record that excites the friction most."""
    _x, v, _a = derivatives(data.t, data.x)
    flips = np.zeros(len(data))
    flips[moving_flips(v)[1]] = 1.0
    travel = np.abs(np.diff(data.x, prepend=data.x[0]))
    best, key = 0, (-1.0, -1.0)
    for k in range(0, len(data) - WINDOW + 1, WINDOW // 4):
        cand = (float(flips[k:k + WINDOW].sum()), float(travel[k:k + WINDOW].sum()))
        if cand > key:
            best, key = k, cand
    return best
