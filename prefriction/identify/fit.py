"""``fit(model, data)``: friction parameters from measurements, with Gauss-Newton uncertainty."""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, Sequence

import numpy as np

from prefriction._validation import check_bool, check_count, check_finite, check_positive
from prefriction.errors import SolverError
from prefriction.identify.data import ForceDisplacement, ForceVelocity, Motion
from prefriction.identify.options import check_solver
from prefriction.identify.parameters import ParameterSpace, name_list
from prefriction.identify.pinned import unpinned_message as _unpinned_message
from prefriction.identify.result import FitResult
from prefriction.identify.validation import model_name
from prefriction.identify.statistics import (BoundWarning, ConvergenceWarning, IdentifiabilityWarning,
                                             NoisyPositionsWarning, ResidualWarning, at_bounds, gauss_newton)
from prefriction.models.base import FrictionModel

__all__ = ["EVENT_MAX_ITER", "fit"]

EVENT_MAX_ITER = 500
"""Default ``max_iter`` of a Motion fit of a model with in-branch events or a free Dahl ``gamma``
(:func:`fit`)."""

def fit(model: FrictionModel, data: ForceDisplacement | Motion, *, free: Sequence[str] | None = None,
        fixed: Sequence[str] | None = None, bounds: dict[str, tuple[float, float]] | None = None,
        offset: bool = False, structures: str = "given", mass0: float | None = None, offset0: float | None = None,
        reversals: Sequence[float] | None = None, substeps: int | None = None, max_iter: int | None = None,
        tol: float = 1e-10, identifiability_limit: float = 0.5) -> FitResult:
    """Fit a friction model's parameters to measured data.

    Parameters
    ----------
    model : FrictionModel
        The model to fit (:class:`prefriction.Dahl`, :class:`prefriction.MaxwellSlip`,
        :class:`prefriction.LuGre`, ...); its parameter values are the starting values, and fix
        its structure (Dahl: ``gamma >= 1`` or ``gamma < 1``; Maxwell-slip: the number of elements).
    data : ForceDisplacement, Motion or ForceVelocity
        :class:`ForceVelocity` (steady-sliding force against velocity): fits a
        :class:`prefriction.identify.StaticFriction` map (Coulomb + viscous + Stribeck,
        optionally direction-dependent) by least squares (``docs/identify_motion.md#static-maps``);
        a map with :class:`Motion` data is the inverse model with the mass
        (:func:`prefriction.identify.fit_inverse`, ``docs/identify_closed_loop.md``).
        :class:`ForceDisplacement`: friction force along a prescribed displacement; the model's
        force along the measured ``x`` is fitted to ``F`` by least squares (trust-region
        reflective, Jacobian by CasADi). :class:`Motion`: positions of a mass under a known
        force ``u`` (a free decay for ``u = 0``), held or linear between samples as
        ``data.hold`` says; fitted by multiple shooting over segments of 50 samples with
        scipy's trust-region least squares in an augmented Lagrangian, records of more than 4,000
        samples after a fit of their 2,000 with the most reversals (``docs/identify_motion.md``: time and memory
        grow linearly with the samples).
    free : sequence of str, optional
        Parameters to fit (names of ``type(model).parameters``; ``"stiffness[0]"`` for an
        array entry; ``"mass"``). Default: every parameter not in ``fixed``.
    fixed : sequence of str, optional
        Parameters held at the model's values.
    bounds : dict, optional
        ``{name: (low, high)}`` in the parameter's unit, inside the declared range; the start
        value must lie inside (a list or tuple is refused: it cannot name the parameters).
        Default: the declared range, narrowed to keep the model's structure (Dahl ``gamma``).
    offset : bool, default False
        Also fit a constant force offset ``"offset"`` [N] (a sensor bias), added to the model's
        force (:class:`ForceDisplacement`) or to the friction of a :class:`Motion`
        (``m x'' + F + F_off = u``, a bias of the force sensor or the drive); estimated, with its
        interval, like any parameter.
    structures : {"given", "both"}, default "given"
        For :class:`prefriction.Dahl` with ``gamma`` free and not bounded by ``bounds``:
        ``"given"`` fits the start model's structure only (``gamma >= 1`` from the default
        ``gamma = 1``: the structure every later step takes, ``docs/conventions.md#fits-downstream``);
        ``"both"`` fits the start model's structure and the other one (``gamma < 1`` started at
        0.5, or ``gamma >= 1`` started at 1.5; the two use different states), keeps the one with
        the smaller residual, and says in ``FitResult.notes`` what it compared and, when it keeps
        ``gamma < 1``, which later steps refuse that structure.
    mass0 : float, optional
        Start value of the mass [kg] when ``data.mass`` is ``None`` (the mass is then fitted).
        Default: the static least-squares fit of the force balance of a forced record
        (``docs/identify_motion.md#start-values``). The start values the user gives (``mass0``,
        ``offset0``, the start model's parameters) are the ones the fit uses; the static
        estimates fill in only what is not given, and :attr:`FitResult.start` says what set each.
    offset0 : float, optional
        Start value of the offset [N] of a :class:`Motion` fit with ``offset=True``; default: the
        static least-squares estimate (0 for a record that slides one way only).
    reversals : sequence of float, optional
        Approximate velocity reversal times [s] of :class:`Motion` data: the direction of
        motion at each shooting node is taken from them; default: the sign of a smoothed
        velocity. Reversals inside a sample are located by the fit itself.
    substeps : int, optional
        Runge-Kutta sub-steps per sample interval (1 to 64); default: chosen from the data and
        the start values (1 for Maxwell-slip on force-displacement data, where one step is the
        exact stop operator).
    max_iter : int, optional
        Most solver iterations (Jacobian evaluations of a :class:`Motion` fit, function
        evaluations for force-displacement data), 1 to 100 000. Default 200, and
        :data:`EVENT_MAX_ITER` (500) for a :class:`Motion` fit of a model with in-branch events
        (Dahl ``gamma < 1``, Maxwell-slip, GMS): its motion is only piecewise smooth in the
        parameters and a fit from a factor-2 start takes 150 to 300 (``docs/identify_motion.md#limits``);
        also 500 with a free Dahl ``gamma``: ``gamma`` and the stiffness trade off along a long
        valley, and a 1,000-sample ``gamma = 2`` fit from a factor-2 start took 415.
        A fit that stops there returns with ``success = False`` and a :class:`ConvergenceWarning`.
    tol : float, default 1e-10
        Solver tolerance (relative), ``1e-14 <= tol <= 1e-6``: looser tolerances stop before the
        estimates settle.
    identifiability_limit : float, default 0.5
        Relative standard error above which a parameter is reported as not identifiable.

    Returns
    -------
    FitResult
        The fitted model, estimates, standard errors, 95 % intervals (Student t), correlation
        matrix, residuals; ``report()`` and ``plot()``.

    Raises
    ------
    TypeError
        If ``model`` is not a FrictionModel, ``data`` is neither data class, or an argument
        has the wrong type (unknown keyword arguments included).
    ValueError
        For unknown parameter names, bounds outside the declared range, a missing ``mass0``
        when the mass is free and the record gives no static estimate, or a model the data type
        cannot fit (the message says why).
    prefriction.SolverError
        If the model's motion or force is not finite at the start values; the message names
        where and what to try. A solver that stops without converging returns the last
        estimates with ``success = False`` and a :class:`ConvergenceWarning`.

    Warns
    -----
    BoundWarning
        Naming every estimate that ends on a bound (the declared range, a user bound, or a
        structure boundary such as Dahl's ``gamma = 1``); its interval starts at the bound.
    ConvergenceWarning
        If the solver stops without converging (``max_iter``, or a Motion fit that cannot
        close the continuity of its segments); the result holds the last estimates.
    NoisyPositionsWarning
        For :class:`ForceDisplacement` data whose positions turn far more often than the motion
        reverses, with neither ``x_noise`` nor ``quantum`` declared.
    ResidualWarning
        If the residuals show structure the model does not explain (runs with a lag-1
        autocorrelation above 0.3, or spikes after the reversals); it names the estimates to
        distrust (``FitResult.diagnostics``).
    IdentifiabilityWarning
        Naming every parameter the data cannot identify: a relative standard error above
        ``identifiability_limit`` (e.g. ``Fc`` from loops that never leave pre-sliding), or a
        parameter that enters only in a combination with others (e.g. the mass, ``sigma`` and
        ``Fc`` of a free decay).

    Notes
    -----
    Standard errors are the HAC (Newey-West) sandwich around the Gauss-Newton covariance
    ``s^2 (J^T J)^-1`` (correlated residuals), never below it, nuisance variables (initial
    state, shooting nodes, reversal times) marginalised; for :class:`ForceDisplacement` data with
    declared ``x_noise`` or ``quantum`` the model follows the estimated true path and that path's
    error is added (errors in variables); intervals are cut at the allowed range; see
    ``docs/identify.md#statistics`` and ``#positions``.

    Examples
    --------
    >>> import prefriction as pf
    >>> from prefriction.data import tribometer
    >>> data = tribometer().window(12.0, 60.0, step=4)
    >>> res = pf.identify.fit(pf.Dahl(sigma=4e4, Fc=2.4, gamma=0.5), data, offset=True)
    >>> res.estimate("offset") > 0.0
    True
    """
    from prefriction.identify.static_map import StaticFriction

    if max_iter is None:
        max_iter = EVENT_MAX_ITER if isinstance(data, Motion) and (getattr(model, "n_events", 0) or
                                                                   _gamma_free(model, free, fixed)) else 200
    if isinstance(model, StaticFriction) and isinstance(data, Motion):  # the inverse model (identify/inverse.py)
        from prefriction.identify.inverse import fit_inverse

        if reversals is not None or substeps is not None:
            raise ValueError("reversals and substeps are for the open-loop Motion fit; a StaticFriction map on Motion "
                             "data is fitted by the inverse model (allowed: reversals=None, substeps=None)")
        return fit_inverse(model, data, offset=offset, free=free, fixed=fixed, bounds=bounds, mass0=mass0,
                           max_iter=max_iter, tol=tol, identifiability_limit=identifiability_limit)
    if isinstance(model, StaticFriction) != isinstance(data, ForceVelocity):
        raise TypeError(f"a StaticFriction map is fitted to ForceVelocity data and only it, got {type(model).__name__} "
                        f"and {type(data).__name__}")
    if not isinstance(model, (FrictionModel, StaticFriction)):
        raise TypeError(f"model must be a prefriction.FrictionModel (e.g. prefriction.Dahl), got {model!r} "
                        f"of type {type(model).__name__}")
    if not isinstance(data, (ForceDisplacement, Motion, ForceVelocity)):
        raise TypeError(f"data must be prefriction.identify.ForceDisplacement, Motion or ForceVelocity, got "
                        f"{type(data).__name__}")
    free, fixed = name_list("free", free), name_list("fixed", fixed)
    if substeps is not None:
        substeps = check_count("substeps", substeps, 1)
        if substeps > 64:
            raise ValueError(f"substeps must be an integer in [1, 64], got {substeps}")
    max_iter, tol, limit = check_solver(max_iter, tol, identifiability_limit)
    offset = check_bool("offset", offset)
    if structures not in ("both", "given"):
        raise ValueError(f"structures must be 'both' or 'given', got {structures!r}")
    if isinstance(data, ForceVelocity):
        from prefriction.identify.static_fit import fit_static

        return fit_static(model, data, free=free, fixed=fixed, bounds=bounds, offset=offset, max_iter=max_iter,
                          tol=tol, limit=limit)
    if isinstance(data, Motion):
        return _fit_motion(model, data, free, fixed, bounds, mass0, offset0, reversals, substeps, max_iter, tol, limit,
                           offset)
    if reversals is not None:
        raise ValueError("reversals is for Motion data; force-displacement data have their directions from dx "
                         "(allowed: reversals=None)")
    if mass0 is not None:
        raise ValueError(f"mass0 = {mass0!r} is for Motion data with a free mass; force-displacement data "
                         f"involve no mass (allowed: mass0=None)")
    if offset0 is not None:
        raise ValueError(f"offset0 = {offset0!r} is for Motion data; a force-displacement offset starts at 0 "
                         f"(allowed: offset0=None)")
    from prefriction.identify.positions import noisy_positions_message
    from prefriction.identify.structures import fit_structures, gamma_entry

    if not data.noisy_positions and (why := noisy_positions_message(data.x)) is not None:
        warnings.warn(why, NoisyPositionsWarning, stacklevel=2)

    scale = float(np.std(data.F)) if offset else None

    def one(start: FrictionModel) -> FitResult:
        return _fit_prescribed(start, data, free, fixed, bounds, scale, substeps, max_iter, tol, limit)

    gamma = gamma_entry(model) if structures == "both" else None
    if gamma is not None and not (
            (free is None or gamma in ([free] if isinstance(free, str) else list(free)))
            and gamma not in ([fixed] if isinstance(fixed, str) else list(fixed or []))
            and not (isinstance(bounds, dict) and gamma in bounds)):
        gamma = None  # gamma held, or bounded to one side by the user
    return fit_structures(model, one, compare=gamma)


def _fit_prescribed(model: FrictionModel, data: ForceDisplacement, free: Any, fixed: Any, bounds: Any,
                    offset: float | None, substeps: int | None, max_iter: int, tol: float, limit: float) -> FitResult:
    from prefriction.identify.prescribed import fit_prescribed

    space = ParameterSpace(model, free, fixed, bounds, offset=offset)
    sol = fit_prescribed(model, data, space, n_sub=substeps, max_iter=max_iter, tol=tol)
    values = space.values(sol.w[:-1])
    est = np.array([values[n] for n in space.free])
    J, scale = space.physical_jacobian(sol.jacobian, sol.w[:-1])
    stats = gauss_newton(J, sol.residuals, space.free, est, scale, limit=limit, covariance="hac",
                         extra=sol.extra_covariance)
    nuisance = {"initial force F0 [N]": float(sol.prediction[0])}
    return _finish(space, values, est, stats, -sol.residuals, sol.prediction, data, None, nuisance, sol.message,
                   sol.success, level=6, limit=limit)


def _gamma_free(model: FrictionModel, free: Sequence[str] | None, fixed: Sequence[str] | None) -> bool:
    """Whether the fit frees the model's Dahl ``gamma`` (:func:`prefriction.identify.structures.gamma_entry`)."""
    from prefriction.identify.structures import gamma_entry

    name = gamma_entry(model)
    if name is None:
        return False
    return name in free if free is not None else name not in (fixed or ())


def _fit_motion(model: FrictionModel, data: Motion, free: Any, fixed: Any, bounds: Any, mass0: Any, offset0: Any,
                reversals: Any, substeps: int | None, max_iter: int, tol: float, limit: float,
                offset: bool) -> FitResult:
    from prefriction.identify.held_first import held_first
    from prefriction.identify.motion_start import data_start, start_values
    from prefriction.identify.continuation import fit_motion
    from prefriction.identify.structures import gamma_entry

    if data.mass is None:
        if mass0 is not None:
            mass0 = check_positive("mass0", mass0)
    elif mass0 is not None:
        raise ValueError(f"mass0 = {mass0!r} is only for a free mass, but data.mass = {data.mass!r} is known "
                         f"(allowed: mass0=None)")
    if offset and data.free_decay:
        raise ValueError("offset=True needs an applied force: in a free decay (u = 0) a force offset cannot be told "
                         "from the rest position (allowed: offset=False)")
    if offset0 is not None:
        if not offset:
            raise ValueError(f"offset0 = {offset0!r} is the start of a fitted offset: give offset=True "
                             f"(allowed without it: offset0=None)")
        offset0 = check_finite("offset0", offset0)
    start = start_values(model, data, mass0, offset0, offset)

    def space_of(m: FrictionModel, mass_start: float | None, offset_start: float) -> ParameterSpace:
        return ParameterSpace(m, free, fixed, bounds, mass=mass_start if data.mass is None else None,
                              offset=max(abs(float(m.Fc)), abs(offset_start)) if offset else None,
                              offset0=offset_start)

    def held_of(sp: ParameterSpace, also: tuple = ()) -> ParameterSpace | None:
        """``sp`` with the parameters a first stage holds (:mod:`prefriction.identify.held_first`, and ``also``)
        fixed."""
        names = held_first(sp.model, sp) + also
        if not names:
            return None
        return ParameterSpace(sp.model, None if free is None else [n for n in free if n not in names],
                              list(fixed or []) + (list(names) if free is None else []), bounds,
                              mass=sp.start.get("mass"), offset=sp.scale[sp.free.index("offset")] if offset else None,
                              offset0=sp.start.get("offset", 0.0))

    space = space_of(model, start.mass, start.offset)
    from prefriction.identify.balance_start import HELD_EVALS, BalanceStart, balance_start
    from prefriction.identify.element_start import element_start

    hold: tuple[str, ...] = ()   # held in the first stage besides held_first's (a start from the force balance)
    found = element_start(model, data, list(space.free), start.mass, start.offset, offset) \
        or balance_start(model, data, space, free, fixed, bounds, offset)
    if found is not None:  # said in FitResult.start, taken where its shooting segments follow the record better
        from prefriction.identify.shooting import start_error

        space_found = space_of(found.model, found.mass, found.offset)
        given, better = _start_error(start_error, model, data, space), _start_error(start_error, found.model,
                                                                                   data, space_found)
        said = (f"rms error of the 50-sample shooting segments {math.sqrt(better):.4g} m against "
                f"{math.sqrt(given):.4g} m of the given start")
        if better < given:
            model, space = found.model, space_found
            hold = (found.gamma,) if isinstance(found, BalanceStart) else ()
            start = dataclasses.replace(start, mass=found.mass, offset=found.offset,
                                        steps=start.steps + (f"{found.line}; {said}: it replaces the given start",))
        else:
            start = dataclasses.replace(start, steps=start.steps + (
                f"{found.line.split(':')[0]} not used ({said}): the given start kept",))
    first_steps = start.steps
    try:
        sol, error = fit_motion(model, data, space, n_sub=substeps, max_iter=max_iter, tol=tol,
                                reversals=reversals, held=held_of(space, hold),
                                held_iter=HELD_EVALS if hold else None), None
    except SolverError as err:
        sol, error = None, err
    retried = False
    if sol is None or not sol.success:  # second start from the data alone (motion_start.data_start)
        second = data_start(model, space.free, start)
        retried = second is not None
        first = str(error) if sol is None else sol.message
        if second is not None:
            sol2, space2, err2 = _fit_from(second, data, space_of, substeps, max_iter, tol, reversals, held_of)
            if sol2 is None:
                start = dataclasses.replace(start, steps=start.steps + (
                    f"the fit from these start values did not converge ({first[:200]}); a second start from "
                    f"{second[3]} failed too ({str(err2)[:200]})",))
            else:
                keep = sol2.success or sol is None
                start = dataclasses.replace(start, steps=start.steps + (
                    f"the fit from these start values did not converge ({first[:200]}); second start from "
                    f"{second[3]}: {'converged, its result kept' if sol2.success else 'did not converge either'}"
                    + ("" if keep else ", the first fit's result kept"),))
                if keep:
                    sol, space, error = sol2, space2, None
    gamma = gamma_entry(model)
    if gamma in space.free and (doubtful := _doubtful(space, sol, limit, gamma)):  # continuation in Dahl's gamma
        cont, line = _gamma_continuation(model, data, space_of(model, start.mass, start.offset), gamma, free, fixed,
                                         bounds, space_of, substeps, max_iter, tol, reversals, limit)
        kept = cont is not None and (sol is None or doubtful or _rss(cont[0]) <= _rss(sol))
        start = dataclasses.replace(start, steps=start.steps + (
            line + ("" if cont is None else ": its result kept" if kept else ": the first fit's result kept"),))
        if kept:
            sol, space, error = cont[0], cont[1], None
    if sol is None:
        extra = "".join(f"; {x}" for x in (_route_advice(data), *start.steps[len(first_steps):]) if x)
        if extra:
            raise SolverError(f"{error}{extra}") from error
        raise error
    values, est, stats = _motion_statistics(space, sol, limit)
    if sol.success and not retried and (found := _unpinned(space, values, est, stats, limit)):
        second = data_start(model, space.free, start)  # an estimate the bound holds, not the data: retry
        why = "; ".join(w for _, w in found)
        if second is None:
            start = dataclasses.replace(start, steps=start.steps + (
                f"the fit from these start values ended with {why}; no second start from the data (no static "
                f"estimates, or they change nothing)",))
        else:
            sol2, space2, err2 = _fit_from(second, data, space_of, substeps, max_iter, tol, reversals, held_of)
            said = (f"failed ({str(err2)[:200]})" if sol2 is None
                    else "converged" if sol2.success else "did not converge")
            if sol2 is not None and sol2.success:
                v2, e2, s2 = _motion_statistics(space2, sol2, limit)
                if not _unpinned(space2, v2, e2, s2, limit):
                    sol, space, values, est, stats = sol2, space2, v2, e2, s2
                    said += ", its result kept"
                else:
                    said += " on a bound the data do not pin down either, the first fit's result kept"
            elif sol2 is not None:
                said += ", the first fit's result kept"
            start = dataclasses.replace(start, steps=start.steps + (
                f"the fit from these start values ended with {why}; second start from {second[3]}: {said}",))
    held = bool(held_first(space.model, space))
    short = _short_of_minimum(space, sol, stats, held)
    from prefriction.identify.continuation import WINDOW

    # once more, the held stage from where it stopped (a long record: its cost, and the flag, instead)
    if short and held and len(data) <= 2 * WINDOW:
        model2 = space.build(values)
        sol2, space2, err2 = _fit_from((model2, values.get("mass"), values.get("offset", 0.0),
                                        "the estimates where the fit stopped short of its minimum"),
                                       data, space_of, substeps, max_iter, tol, reversals, held_of)
        said = f"failed ({str(err2)[:200]})" if sol2 is None else "converged" if sol2.success else "did not converge"
        if sol2 is not None and sol2.success and _rss(sol2) < _rss(sol):
            v2, e2, s2 = _motion_statistics(space2, sol2, limit)
            short2 = _short_of_minimum(space2, sol2, s2, True)
            if len(short2) <= len(short):
                sol, space, values, est, stats, short = sol2, space2, v2, e2, s2, short2
                said += ", its result kept (a lower sum of squares)"
        start = dataclasses.replace(start, steps=start.steps + (
            f"the fit stopped short of its minimum; the continuation again from its estimates: {said}",))
    message, success = sol.message, sol.success
    if success and short:
        from prefriction.identify.settled import unsettled_message

        loose = stats.unidentifiable or tuple((n, "the record pins it only barely, in a combination with Fs")
                                              for n in held_first(space.model, space))
        message, success = f"{unsettled_message(short, loose)}; solver: {message}", False
    if not sol.success:
        advice = _route_advice(data, sol)
        message = f"{message}; {advice}" if advice else message
        if gamma in space.free:  # measured: docs/identify_motion.md (the Dahl gamma = 2 stage)
            message += (f"; {gamma} was free: it trades off with the stiffness along a long valley, and a fit with "
                        f"it fixed (fixed=[{gamma!r}]) at a value from the branch shape (a ForceDisplacement fit) "
                        f"converges in far fewer evaluations; or give max_iter more")
    mass = values["mass"] if data.mass is None else data.mass
    fitted = data if sol.data is None else sol.data   # the moves, where the hovers were left out
    return _finish(space, values, est, stats, -sol.residuals, sol.prediction, fitted, mass, sol.nuisance, message,
                   success, start=start.steps + sol.steps, limit=limit)


def _fit_from(second: tuple, data: Motion, space_of: Any, substeps: Any, max_iter: int, tol: float,
              reversals: Any, held_of: Any) -> tuple[Any, ParameterSpace | None, Exception | None]:
    """The Motion fit from a second start ``(model, mass, offset, origin)``
    (:func:`prefriction.identify.motion_start.data_start`): ``(solution, space, None)``, or
    ``(None, None, error)`` where building its space or solving raised."""
    from prefriction.identify.continuation import fit_motion

    try:
        space2 = space_of(second[0], second[1], second[2])
        return fit_motion(second[0], data, space2, n_sub=substeps, max_iter=max_iter, tol=tol,
                          reversals=reversals, held=held_of(space2)), space2, None
    except (SolverError, ValueError) as err:
        return None, None, err


def _short_of_minimum(space: ParameterSpace, sol: Any, stats: Any, valley: bool) -> tuple[tuple[str, float], ...]:
    """The pinned estimates of a converged fit that stopped short of the minimum
    (:func:`prefriction.identify.settled.unsettled`: a curved valley), else ``()``; checked where
    the fit has unidentifiable parameters or ``valley`` (parameters a first stage held,
    :mod:`prefriction.identify.held_first`, that the record may pin only barely)."""
    loose = {n for n, _ in stats.unidentifiable}
    if not sol.success or not (loose or valley):
        return ()
    from prefriction.identify.settled import unsettled

    J, scale = space.physical_jacobian(sol.jacobian, sol.w[: space.n_free])
    return unsettled(J, sol.residuals, space.free, scale, stats.stderr, np.array([n not in loose for n in space.free]))


def _rss(sol: Any) -> float:
    """Mean square residual of a solution (per sample: a fit of the record's moves alone compares
    with one of the whole record)."""
    return float(np.mean(np.square(sol.residuals)))


def _doubtful(space: ParameterSpace, sol: Any, limit: float, gamma: str) -> bool:
    """A Motion solution that failed, ends on a bound the data do not pin down, or leaves Dahl's
    ``gamma`` unidentifiable (a flat valley, often a local minimum of the start's side)."""
    if sol is None or not sol.success:
        return True
    values, est, stats = _motion_statistics(space, sol, limit)
    return bool(_unpinned(space, values, est, stats, limit)) or gamma in {n for n, _ in stats.unidentifiable}


def _gamma_continuation(model: FrictionModel, data: Motion, space: ParameterSpace, gamma: str, free: Any, fixed: Any,
                        bounds: Any, space_of: Any, substeps: Any, max_iter: int, tol: float, reversals: Any,
                        limit: float) -> tuple[tuple[Any, ParameterSpace] | None, str]:
    """Fit with Dahl's ``gamma`` held at its start value, then with it free from those estimates.

    With ``gamma`` held the branch shape is fixed and the stiffness, Coulomb force, viscous
    coefficient, mass and offset settle where the data put them; freed from there, ``gamma``
    starts in the valley of the truth instead of running to a bound (measured on the noisy
    300-sample Dahl ``gamma = 0.6`` records of ``tests/test_identify_pinned.py``: the fits that
    ended at ``gamma = 0`` or at an unidentifiable ``gamma`` land within 4 % of every parameter).

    Returns
    -------
    ((MotionSolution, ParameterSpace) or None, str)
        The second stage's solution (``None`` if either stage failed or it is doubtful itself,
        :func:`_doubtful`) and a line for :attr:`FitResult.start`.
    """
    from prefriction.identify.continuation import fit_motion

    mass_start = space.start.get("mass")
    offset_start = space.start.get("offset", 0.0)
    held_free = None if free is None else [n for n in free if n != gamma]
    held_fixed = list(fixed or []) + ([gamma] if free is None else [])
    what = f"continuation in {gamma}: fitted with {gamma} held at its start {space.start[gamma]:.4g}, then freed"
    try:
        sp1 = ParameterSpace(model, held_free, held_fixed, bounds, mass=mass_start if data.mass is None else None,
                             offset=max(abs(float(model.Fc)), abs(offset_start)) if "offset" in space.start else None,
                             offset0=offset_start)
        sol1 = fit_motion(model, data, sp1, n_sub=substeps, max_iter=max_iter, tol=tol, reversals=reversals)
        if not sol1.success:
            return None, f"{what}: the first stage did not converge ({sol1.message[:160]})"
        vals = sp1.values(sol1.w[: sp1.n_free])
        model2 = sp1.build(vals)
        sp2 = space_of(model2, vals.get("mass", mass_start), vals.get("offset", offset_start))
        sol2 = fit_motion(model2, data, sp2, n_sub=substeps, max_iter=max_iter, tol=tol, reversals=reversals)
    except (SolverError, ValueError) as err:
        return None, f"{what}: failed ({str(err)[:200]})"
    if _doubtful(sp2, sol2, limit, gamma):
        return None, f"{what}: {'did not converge' if not sol2.success else 'no better'} ({_short(sp2, sol2)})"
    return (sol2, sp2), f"{what}: converged ({_short(sp2, sol2)})"


def _short(space: ParameterSpace, sol: Any) -> str:
    vals = space.values(sol.w[: space.n_free])
    return ", ".join(f"{n} {vals[n]:.4g}" for n in space.free)


def _motion_statistics(space: ParameterSpace, sol: Any, limit: float) -> tuple[dict, np.ndarray, Any]:
    """Values by name, the free estimates and their statistics of a Motion solution."""
    values = space.values(sol.w[: space.n_free])
    est = np.array([values[n] for n in space.free])
    J, scale = space.physical_jacobian(sol.jacobian, sol.w[: space.n_free])
    stats = gauss_newton(J, sol.residuals, space.free, est, scale, constraints=sol.constraints, limit=limit,
                         covariance="hac")
    if sol.widen:   # a curved valley's secant check (identify/polish.py valley_secant)
        from prefriction.identify.statistics import widen_statistics

        stats = widen_statistics(stats, space.free, est, sol.widen, limit)
    return values, est, stats


def _unpinned(space: ParameterSpace, values: dict, est: np.ndarray, stats: Any,
              limit: float) -> tuple[tuple[str, str], ...]:
    """The estimates on a bound the data do not pin down (:func:`prefriction.identify.pinned.unpinned`)."""
    from prefriction.identify.pinned import unpinned

    lower, upper = space.limits(values)
    start = np.array([abs(space.start[n]) for n in space.free])
    return unpinned(space.free, est, stats.stderr, stats.low, stats.high, start, lower, upper, space.why_low,
                    space.why_high, limit)


def _start_error(error: Any, model: FrictionModel, data: Motion, space: ParameterSpace) -> float:
    """``error(model, data, space)``, ``inf`` where the start's motion cannot be simulated."""
    try:
        return error(model, data, space)
    except (SolverError, ValueError, RuntimeError):
        return math.inf


def _route_advice(data: Motion, sol: Any = None) -> str:
    """The route :func:`prefriction.identify.recommend` advises when it is not this open-loop fit
    (a long closed-loop record on which an open-loop replay drifts), else ``""``; also ``""``
    where the failed fit ``sol``'s own chain from the first sample (``MotionSolution.chain``)
    follows the record by the route's own test (within its tolerance for an eighth of the
    record): the static inverse model's replay drifts on a record ruled by pre-sliding, open
    loop or not."""
    from prefriction.identify.routes import recommend

    rec = recommend(data)
    if rec.route == "motion":
        return ""
    chain = getattr(sol, "chain", None)
    if chain is not None:
        left = np.flatnonzero(~(np.abs(chain) <= rec.tolerance))
        if (int(left[0]) if left.size else chain.size) >= len(data) // 8:
            return ""
    call = "identify.fit_inverse" if rec.route == "inverse" else "identify.fit_closed_loop"
    return f"this record suits another route ({rec}): use {call} (docs/identify_closed_loop.md)"


def _finish(space: ParameterSpace, values: dict, est: np.ndarray, stats: Any, residuals: np.ndarray,
            fitted: np.ndarray, data: Any, mass: float | None, nuisance: dict, message: str,
            success: bool = True, level: int = 4, start: tuple[str, ...] = (), limit: float = 0.5) -> FitResult:
    fitted_model = space.build(values)
    found = _unpinned(space, values, est, stats, limit) if success else ()
    if found:  # on a bound the data do not pin down: not a success (docs/identify.md#bounds)
        tried = "" if not any("second start from" in line for line in start) else \
            " (a second start from the data was tried, see FitResult.start)"
        message, success = f"{_unpinned_message(found, tried)}; solver: {message}", False
    for name, why in stats.unidentifiable:
        warnings.warn(f"the data cannot identify {name}: {why}; its interval is meaningless. Fix it (fixed=[{name!r}]) "
                      f"or record data that excite it (docs/identify.md#identifiability)",
                      IdentifiabilityWarning, stacklevel=level)
    lower, upper = space.limits(values)
    floor = {hi: max(float(stats.low[space.free.index(lo)]), lower[lo]) for hi, lo in space.excess.items()}
    low, high, flags = at_bounds(space.free, est, stats.low, stats.high, space.scale, lower, upper,
                                 space.why_low, space.why_high, floor)
    for name, value, flag in zip(space.free, est, flags):
        if flag.startswith("on its"):
            todo = "fit the other structure (structures='both')" if "structure" in flag else "widen the bound"
            warnings.warn(f"{name} = {value:.6g} ends {flag}: the data may want a value beyond it; {todo} "
                          f"(docs/identify.md#bounds)", BoundWarning, stacklevel=level)
    if found:
        warnings.warn(f"the fit of {model_name(fitted_model)} is not a success: {message}", ConvergenceWarning,
                      stacklevel=level)
    elif not success:
        warnings.warn(f"the fit of {model_name(fitted_model)} did not converge: {message}; the estimates are where "
                      f"the solver stopped (raise max_iter, or give better start values)", ConvergenceWarning,
                      stacklevel=level)
    res = FitResult(fitted_model, mass, tuple(space.free), tuple(space.units[n] for n in space.free), est,
                    stats.stderr, low, high, stats.correlation, residuals, fitted, data, stats,
                    nuisance, message, success=success, flags=flags, start=start)
    _warn_structure(res, level)
    return res


def _warn_structure(res: FitResult, level: int) -> None:
    """A :class:`ResidualWarning` if the residuals show structure (``docs/identify.md#diagnostics``)."""
    diag = res.diagnostics
    if not diag.structured:
        return
    who = "; ".join(f"{n} ({why})" for n, why in diag.distrust) if diag.distrust else \
        "no single estimate stands out, every one may be biased"
    noise = ", declare the position noise (x_noise, quantum)" if isinstance(res.data, ForceDisplacement) and \
        not res.data.noisy_positions else ""
    warnings.warn(f"the residuals of the {model_name(res.model)} fit show structure the model does not explain: "
                  f"{'; '.join(diag.findings)}. Distrust: {who}. Try another model or structure, free the "
                  f"parameters held{noise}, and look at res.plot_residuals() (docs/identify.md#diagnostics)",
                  ResidualWarning, stacklevel=level + 1)
