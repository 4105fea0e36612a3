"""Reusable checks that hold any friction model to the protocol and the generic invariants.

``check_model(model)`` is what ``docs/models.md`` asks of every new model: use it in a test
(``tests/test_protocol.py`` does, for Dahl and for a model written only through the protocol).
The reference it compares the simulator with is an independent scipy integration (DOP853 at
rtol 1e-12, restarted at every reversal and every model event) of the model's own numeric
equations, so it tests the simulator and the plant, not the model's equations themselves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from prefriction.models.sizes import check_sizes
from prefriction._validation import check_choice, check_count, check_finite, check_interval, check_positive
from prefriction.models import FrictionModel, Oscillator

__all__ = ["MAX_CHECK_REVERSALS", "ModelCheck", "check_model", "reference_reversals"]

MAX_CHECK_REVERSALS = 100_000
"""Most reversals of :func:`reference_reversals` and :func:`check_model` (one scipy run per
reversal: about a minute at the limit)."""
_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
_DIED_OUT = 1e-9  # reversal force (relative to the largest) below which a motion has died out
_MAX_T_END = 1e12  # normalised t_end of the checks (a cycle is about 2 pi units)
_MAX_SPEED = 1e150  # |v0| in normalised units: initial energy far inside double precision


def _check_model_and_speed(model: Any, v0: Any) -> float:
    """Check ``model`` (a FrictionModel) and the normalised initial velocity ``v0``."""
    if not isinstance(model, FrictionModel):
        raise TypeError(f"model must be a prefriction.FrictionModel (e.g. prefriction.Dahl), got {model!r} "
                        f"of type {type(model).__name__}")
    v0 = check_finite("v0", v0)
    if not 0.0 < abs(v0) <= _MAX_SPEED:
        raise ValueError(f"v0 must be a finite nonzero normalised velocity with |v0| <= {_MAX_SPEED:g} (the motion "
                         f"starts from F = 0, so v0 = 0 never moves; larger speeds overflow), got {v0!r}")
    return v0


@dataclass(frozen=True)
class ModelCheck:
    """What :func:`check_model` measured (normalised units).

    Attributes
    ----------
    n_reversals : int
        Reversals found by both the simulator and the reference.
    max_error : float
        Largest relative error of the simulated reversal times, positions and forces against the
        reference (relative to the largest position / force of the run).
    branch_energy_error : float
        Largest difference between the model's branch energy at a reversal and the work
        ``-int F dx`` from that reversal to the force's zero crossing on the reference
        trajectory, relative to the initial energy (rate-independent models; else 0).
    """

    n_reversals: int
    max_error: float
    branch_energy_error: float


def _sibling(model: FrictionModel) -> FrictionModel:
    """Another instance of the same structure with other numbers: every float or float-array
    field moved by 3 % where the model accepts it (e.g. not GMS's fractions, which must sum to
    1), or ``model`` itself if nothing can move."""
    import dataclasses

    if not dataclasses.is_dataclass(model):
        return model
    changes = {}
    for field in dataclasses.fields(model):
        value = getattr(model, field.name)
        if isinstance(value, float):
            moved: Any = value * 1.03 if value != 0.0 else 0.03
        elif isinstance(value, np.ndarray) and value.dtype.kind == "f" and value.size:
            moved = value * 1.03
        else:
            continue
        try:
            trial = dataclasses.replace(model, **{field.name: moved})
        except (TypeError, ValueError):
            continue
        if trial.structure_key() == model.structure_key():
            changes[field.name] = moved
    try:
        other = dataclasses.replace(model, **changes)
    except (TypeError, ValueError):
        return model
    return other if other.structure_key() == model.structure_key() else model


def _contract(model: FrictionModel, rng: np.random.Generator) -> None:
    """The symbolic functions of ``model``, built from a symbolic ``q``, equal the numeric
    functions of another instance of the same structure at that instance's ``q``: one compiled
    plant serves every instance. ``force``, ``rate``, ``events``, ``on_event`` and ``reverse``."""
    other = _sibling(model)
    q_num = other.runtime_params()
    nz, nm = model.n_states, model.n_flags
    z, m = ca.SX.sym("z", nz), ca.SX.sym("m", nm)
    v, s, q = ca.SX.sym("v"), ca.SX.sym("s"), ca.SX.sym("q", max(len(q_num), 0))
    zl, ml = [z[i] for i in range(nz)], [m[i] for i in range(nm)]

    def outputs(mod: FrictionModel, zz: list, mm: list, vv: Any, ss: Any, qq: Any) -> list:
        ev = list(mod.events(zz, mm, vv, ss, qq))
        assert len(ev) == mod.n_events, "events() must return n_events indicators"
        out = [mod.force(zz, mm, vv, ss, qq)] + list(mod.rate(zz, mm, vv, ss, qq)) + ev
        zr, mr = mod.reverse(zz, mm, -ss, qq, 1e-9)
        out += list(zr) + list(mr)
        for k in range(mod.n_events):
            ze, me = mod.on_event(k, zz, mm, ss, qq)
            out += list(ze) + list(me)
        return out

    f = ca.Function("contract", [z, m, v, s, q], [ca.vertcat(*outputs(model, zl, ml, v, s, q))])
    for _ in range(20):
        s_ = float(rng.choice([-1.0, 1.0]))
        f0 = float(rng.uniform(-0.9, 0.9))
        try:
            z0, m0 = other.initial_state(f0, s_)
        except NotImplementedError:  # no initial_state of a given force (several states): any state
            z0, m0 = [f0 / nz] * nz, [0.0] * nm
        v_ = float(rng.uniform(0.0, 2.0)) * s_
        sym = np.array(f(z0, m0, v_, s_, q_num)).ravel()
        num = np.array(outputs(other, list(z0), list(m0), v_, s_, q_num.tolist()), dtype=float)
        np.testing.assert_allclose(sym, num, rtol=1e-13, atol=1e-14,
                                   err_msg="symbolic (from q) and numeric model functions differ: the "
                                           "symbolic methods must use q, not the instance's numbers")


def reference_reversals(model: FrictionModel, v0: float, n: int, *, rtol: float = 1e-12,
                        method: str = "DOP853", t_end: Optional[float] = None) -> tuple[np.ndarray, np.ndarray]:
    """Reversals ``(t~, x~, F~)`` rows and the branch-energy work check of the unforced
    oscillator (unit mass) in normalised units, by scipy ``solve_ivp`` (``method``, default
    DOP853; Radau for stiff models) restarted at every reversal and every model event.

    Parameters
    ----------
    model : FrictionModel
        The friction model.
    v0 : float
        Initial normalised velocity (from ``F = 0``), ``0 < |v0| <= 1e150``.
    n : int
        Number of reversals, ``1 <= n <=`` :data:`MAX_CHECK_REVERSALS`.
    rtol : float, default 1e-12
        Relative tolerance of ``solve_ivp``, in ``[1e-13, 1e-2]`` (``atol = rtol / 100``).
    method : str, default "DOP853"
        A ``solve_ivp`` method: ``"RK45"``, ``"RK23"``, ``"DOP853"``, ``"Radau"``, ``"BDF"`` or ``"LSODA"``.
    t_end : float, optional
        Normalised end time (unit ``sqrt(m / sigma)``), ``0 < t_end <= 1e12``: stop there if
        fewer than ``n`` reversals came (a motion that dies out). Without it a run that finds no
        next reversal within 1e4 time units raises ``RuntimeError``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Reversal rows ``(t, x, F)`` (shape ``(k, 3)``, ``k <= n``; ``k = n`` without ``t_end``)
        and, per reversal, ``-int F dx`` from the reversal to the next zero crossing of ``F``
        (NaN where the run ended before it).
    """
    return _reference(model, v0, n, rtol=rtol, method=method, t_end=t_end)[:2]


def _reference(model: FrictionModel, v0: float, n: int, *, rtol: float, method: str,
               t_end: Optional[float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`reference_reversals` and the state ``(x, v)`` where it stopped (normalised)."""
    v0 = _check_model_and_speed(model, v0)
    n = check_count("n", n, minimum=1, maximum=MAX_CHECK_REVERSALS, why="one scipy run per reversal")
    rtol = check_interval("rtol", rtol, 1e-13, 1e-2)
    method = check_choice("method", method, _METHODS)
    if t_end is not None:
        t_end = check_positive("t_end", t_end)
        if t_end > _MAX_T_END:
            raise ValueError(f"t_end must be a normalised time <= {_MAX_T_END:g} (about {_MAX_T_END / 6.3:.1g} "
                             f"cycles of scipy reference), got {t_end!r}")
    q = model.runtime_params().tolist()
    nz = model.n_states
    s = 1.0 if v0 > 0 else -1.0
    z, m = model.initial_state(0.0, s)
    y = np.array([0.0, v0, *z, 0.0])  # x, v, z, work -int F dx since the last reversal
    t, rows, works, pending = 0.0, [], [], False
    snap = 1e-12
    while len(rows) < n:
        mm = list(m)

        def rhs(_t: float, y: np.ndarray, s: float = s, mm: list = mm) -> np.ndarray:
            zz = y[2:2 + nz].tolist()
            F = model.force(zz, mm, y[1], s, q)
            return np.array([y[1], -F, *model.rate(zz, mm, y[1], s, q), -F * y[1]])

        def rev(_t: float, y: np.ndarray, s: float = s) -> float:
            return s * y[1]

        def zero_force(_t: float, y: np.ndarray, s: float = s, mm: list = mm) -> float:
            return model.force(y[2:2 + nz].tolist(), mm, y[1], s, q)

        rev.terminal, rev.direction = True, -1.0
        zero_force.terminal = False
        evs = [rev, zero_force]
        for k in range(model.n_events):
            def ev(_t: float, y: np.ndarray, k: int = k, s: float = s, mm: list = mm) -> float:
                return model.events(y[2:2 + nz].tolist(), mm, y[1], s, q)[k]
            ev.terminal, ev.direction = True, -1.0
            evs.append(ev)
        stop = t + 1e4 if t_end is None else t_end
        sol = solve_ivp(rhs, (t, stop), y, method=method, rtol=rtol, atol=rtol * 1e-2, events=evs)
        if sol.status == 0 and t_end is not None:  # reached t_end before the next event
            if pending and len(sol.t_events[1]):
                works[-1] = float(sol.y_events[1][0][-1])
            return np.array(rows).reshape(-1, 3), np.array(works), sol.y[:2, -1].copy()
        if sol.status != 1:
            raise RuntimeError(f"reference integration did not reach an event: {sol.message}; give t_end "
                               f"if the motion dies out")
        if pending and len(sol.t_events[1]):
            works[-1] = float(sol.y_events[1][0][-1])
            pending = False
        which = min((float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te) and i != 1)
        t, i = which
        y = sol.y_events[i][0].copy()
        zz = y[2:2 + nz].tolist()
        if i == 0:  # reversal: the force after the model's reset, as simulate records it
            s = -s
            z, m = model.reverse(zz, m, s, q, snap)
            rows.append((t, y[0], model.force(list(z), list(m), 0.0, s, q)))
            works.append(math.nan)
            pending = True
            y[1], y[-1] = 0.0, 0.0
        else:  # a model event
            z, m = model.on_event(i - 2, zz, m, s, q)
        y[2:2 + nz] = [float(v) for v in z]
    return np.array(rows), np.array(works), y[:2].copy()


def check_model(model: FrictionModel, *, v0: float = 1.5, reversals: int = 12, rtol: float = 1e-8,
                tol_factor: float = 20.0, seed: int = 0, t_end: Optional[float] = None) -> ModelCheck:
    """Hold ``model`` to the protocol and the generic invariants; ``AssertionError`` if it fails.

    1. The symbolic functions (from a symbolic ``q``; ``force``, ``rate``, ``events``,
       ``on_event``, ``reverse``) equal the numeric ones of another instance of the same
       structure (float and array parameters moved by 3 %): the plant compiled once serves
       every instance.
    2. :func:`prefriction.simulate` finds the same reversals (count, times, positions, forces)
       as an independent scipy reference, within ``tol_factor * rtol``: no reversal missed.
    3. Rate-independent models: energy balance at every reversal (the potential energy ``E_p``
       of the table equals the work ``-int F dx`` until the force's zero crossing on the
       reference), dissipation ``E_p(i) - E_p(i+1) >= 0`` on every half-cycle, and the bound
       (2.12) ``E_p <= Fc^2 / (2 k_min)`` from the second reversal on (the first excursion may
       be gross sliding, which (2.12) does not cover).

    Parameters
    ----------
    model : FrictionModel
        The model under test (its ``sigma`` and ``Fc`` set the units; the check runs in them).
    v0 : float, default 1.5
        Initial normalised velocity (from ``F = 0``), ``0 < |v0| <= 1e150``.
    reversals : int, default 12
        Number of reversals compared, ``1 <= reversals <=`` :data:`MAX_CHECK_REVERSALS`.
    rtol : float, default 1e-8
        Tolerance of the simulation, in ``[1e-13, 1e-2]``.
    tol_factor : float, default 20
        Allowed error in units of ``rtol``, finite and > 0.
    seed : int, default 0
        Seed of the random states of the contract check, ``>= 0``.
    t_end : float, optional
        Normalised end time (unit ``sqrt(m / sigma)``), ``0 < t_end <= 1e12``: the runs stop
        there or at ``reversals``, whichever comes first, so a model whose motion dies out
        (e.g. an overdamped LuGre) is checked on the reversals before ``t_end`` and on the
        position and velocity at ``t_end``. Without it the motion must reach ``reversals``.

    Raises
    ------
    TypeError, ValueError
        For an argument of the wrong type or out of range (before any simulation), naming it.
    AssertionError
        If the model fails a check.

    Returns
    -------
    ModelCheck
    """
    from prefriction.simulation.simulate import simulate
    from prefriction.units import Scales

    v0 = _check_model_and_speed(model, v0)
    reversals = check_count("reversals", reversals, minimum=1, maximum=MAX_CHECK_REVERSALS,
                            why="one scipy run per reversal")
    rtol = check_interval("rtol", rtol, 1e-13, 1e-2)
    tol_factor = check_positive("tol_factor", tol_factor)
    seed = check_count("seed", seed, minimum=0)
    check_sizes(model)
    _contract(model, np.random.default_rng(seed))
    system = Oscillator(model, mass=1.0)
    sc = Scales.of(system)
    ref, works, end = _reference(model, v0, reversals, rtol=1e-12, method="DOP853", t_end=t_end)
    if t_end is None:
        _check_not_died_out(ref)
    if len(ref) == reversals:
        sim = simulate(system, v0 * sc.v, reversals=reversals, rtol=rtol)
    else:  # stopped at t_end: the state there too (one dense sample)
        sim = simulate(system, v0 * sc.v, t_end=t_end * sc.t, rtol=rtol, dense=[t_end * sc.t])
    tab = sim.reversals
    assert len(tab.t) == len(ref), f"simulate found {len(tab.t)} reversals, the reference {len(ref)}"
    err = _reversal_error(tab, ref, sc)
    if len(ref) < reversals:  # relative to the initial speed and the final position
        got_end = np.array([sim.x[-1] / sc.x, sim.v[-1] / sc.v])
        err = max(err, float(np.max(np.abs(got_end - end)) / max(abs(v0), abs(float(end[0])))))
    assert err <= tol_factor * rtol, f"reversals differ from the reference by {err:.3g} (> {tol_factor} rtol)"
    energy_err = 0.0
    if model.rate_independent:
        E_p = tab.E_p / sc.E
        E0 = 0.5 * v0 * v0
        ok = ~np.isnan(works)
        energy_err = float(np.max(np.abs(works[ok] - E_p[ok]), initial=0.0) / E0)
        assert energy_err <= 1e-6, f"branch energy differs from -int F dx by {energy_err:.3g} E_0"
        assert np.all(np.diff(E_p) <= 1e-9 * E0), "negative dissipation on a half-cycle"
        bound = 0.5 * model.Fc ** 2 / model.k_min / (sc.E)
        assert np.all(E_p[1:] <= bound * (1 + 1e-9)), "bound (2.12) violated after the first reversal"
    return ModelCheck(len(ref), err, energy_err)


def _check_not_died_out(ref: np.ndarray) -> None:
    """``ValueError`` if the reference's motion died out before its last reversal: reversals at
    forces below :data:`_DIED_OUT` of the largest are round-off, not a motion to compare."""
    F = np.abs(ref[:, 2])
    dead = np.flatnonzero(F <= _DIED_OUT * np.max(F))
    if dead.size:
        k = int(dead[0])
        raise ValueError(
            f"the motion dies out: after {k} reversals the reference reverses at a force of "
            f"{F[k]:.3g} Fc (t = {ref[k, 0]:.6g} time units), round-off of a mass at rest, so the "
            f"requested reversals cannot be compared; give t_end (e.g. t_end={0.5 * ref[k, 0]:.3g}) "
            f"or ask for at most {k} reversals"
        )


def _reversal_error(tab: Any, ref: np.ndarray, sc: Any) -> float:
    """Largest relative error of the simulated reversals ``tab`` (SI) against the normalised
    reference rows ``ref`` (times and forces relative to each row, positions to the largest)."""
    if len(ref) == 0:
        return 0.0
    got = np.column_stack([tab.t / sc.t, tab.x / sc.x, tab.F / sc.F])
    size = np.maximum(np.max(np.abs(ref), axis=0), 1e-300)
    scale = np.maximum(np.abs(ref), size * 1e-3)
    scale[:, 1] = size[1]  # positions relative to the largest excursion (a reversal may be near x = 0)
    return float(np.max(np.abs(got - ref) / scale))
