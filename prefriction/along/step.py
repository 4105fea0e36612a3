"""Symbolic steps of a friction model over one sample interval of prescribed motion (CasADi).

Re-exported by :mod:`prefriction.identify.stepping` (where the fit imports it).

One step serves every consumer: the force-displacement fit (:mod:`prefriction.identify.prescribed`),
:func:`prefriction.friction_along` and its streaming form :class:`prefriction.FrictionStream`.
Between two samples the motion is linear (constant velocity ``v``) and the direction ``s`` is
fixed. A model with an exact step (:meth:`prefriction.FrictionModel.advance`: Dahl, Maxwell-slip,
LuGre, GMS, Viscous and sums of them) is advanced by it, every in-branch event located inside the
interval. Any other model is advanced by ``n_sub`` classical Runge-Kutta sub-steps of the
protocol's ``rate`` (``docs/models.md#protocol``); after each sub-step every in-branch event whose
indicator has turned negative is applied with ``on_event``, which puts the state on the switching
surface: exact for piecewise-linear models, one sub-step of accuracy at the event otherwise.
"""

from __future__ import annotations

from typing import Any, Callable

import casadi as ca

from prefriction.models.base import FrictionModel

__all__ = ["apply_events", "counted_interval_function", "has_exact_step", "interval_function", "rk4"]


def rk4(f: Callable[[list[Any]], list[Any]], y: list[Any], h: Any) -> list[Any]:
    """One classical Runge-Kutta step of ``y' = f(y)`` with step ``h`` (lists of symbols)."""
    k1 = f(y)
    k2 = f([a + 0.5 * h * b for a, b in zip(y, k1)])
    k3 = f([a + 0.5 * h * b for a, b in zip(y, k2)])
    k4 = f([a + h * b for a, b in zip(y, k3)])
    return [a + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4)]


def apply_events(model: FrictionModel, z: list[Any], m: list[Any], v: Any, s: Any, q: Any) -> tuple[list[Any], list[Any]]:
    """Apply every in-branch event whose indicator is negative (``on_event``), in order."""
    for k in range(model.n_events):
        ind = model.events(z, m, v, s, q)[k]
        zk, mk = model.on_event(k, z, m, s, q)
        hit = ind < 0.0
        z = [ca.if_else(hit, a, b) for a, b in zip(zk, z)]
        m = [ca.if_else(hit, a, b) for a, b in zip(mk, m)]
    return z, m


def has_exact_step(model: FrictionModel) -> bool:
    """True if ``model`` gives an exact interval step (:meth:`FrictionModel.advance` not ``None``)."""
    nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
    z = [ca.SX.sym(f"z{i}") for i in range(nz)]
    m = [ca.SX.sym(f"m{i}") for i in range(nm)]
    q = [ca.SX.sym(f"q{i}") for i in range(nq)]
    return model.advance(z, m, ca.SX.sym("v"), ca.SX.sym("dt"), ca.SX.sym("s"), q) is not None


def interval_function(model: FrictionModel, n_sub: int = 16, snap: float = 1e-12) -> ca.Function:
    """The state over one sample interval of prescribed motion, as a CasADi ``Function``.

    ``(X, v, dt, s_prev, s, v_end, q) -> (X_next, F)``: state ``X = [z; m]`` (normalised), the
    interval's constant normalised velocity ``v`` and duration ``dt``, the direction of the
    previous interval ``s_prev`` and of this one ``s`` (a reversal, ``reverse``, where they
    differ), the velocity ``v_end`` at the sample that ends the interval (rate-dependent forces)
    and the run-time numbers ``q``. ``F`` is the normalised force at the end of the interval.

    The model's exact step (:meth:`FrictionModel.advance`) if it has one (``n_sub`` unused),
    else ``n_sub`` Runge-Kutta sub-steps with events applied after each (module notes).
    """
    ins, X_next, F, _events = _interval(model, n_sub, snap)
    return ca.Function("interval", ins, [X_next, F], _NAMES_IN, ["X_next", "F"])


def counted_interval_function(model: FrictionModel, n_sub: int = 16, snap: float = 1e-12,
                              reversal: bool = True) -> ca.Function:
    """:func:`interval_function` with a third output: the number of model events in the
    interval (flags set at its end that were clear after the reversal at its start).
    ``reversal=False``: the step of an interval that keeps the direction of the one before
    (``s_prev`` unused), for a caller that chooses between the two."""
    ins, X_next, F, events = _interval(model, n_sub, snap, reversal)
    return ca.Function("interval_counted", ins, [X_next, F, events], _NAMES_IN, ["X_next", "F", "events"])


_NAMES_IN = ["X", "v", "dt", "s_prev", "s", "v_end", "q"]


def _interval(model: FrictionModel, n_sub: int, snap: float,
              reversal: bool = True) -> tuple[list[ca.SX], ca.SX, ca.SX, ca.SX]:
    """Inputs and outputs ``(X_next, F, events)`` of the interval step (SX)."""
    nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
    X = ca.SX.sym("X", nz + nm)
    v, dt, s_prev, s, v_end = (ca.SX.sym(n) for n in ("v", "dt", "s_prev", "s", "v_end"))
    qs = ca.SX.sym("q", nq)
    q = [qs[i] for i in range(nq)]
    z = [X[i] for i in range(nz)]
    m = [X[nz + i] for i in range(nm)]
    if reversal:
        zr, mr = model.reverse(z, m, s, q, snap)
        rev = s * s_prev < 0.0
        z = [ca.if_else(rev, a, b) for a, b in zip(zr, z)]
        m = [ca.if_else(rev, a, b) for a, b in zip(mr, m)]
    m0 = m
    exact = model.advance(z, m, v, dt, s, q)
    if exact is not None:
        z, m = list(exact[0]), list(exact[1])
    else:
        h = dt / n_sub
        for _ in range(n_sub):
            mm = list(m)
            z = rk4(lambda y, mm=mm: model.rate(y, mm, v, s, q), z, h)
            z, m = apply_events(model, z, m, v, s, q)
    F = model.force(z, m, v_end, s, q)
    events = ca.SX(0.0)
    for a, b in zip(m0, m):
        events = events + ca.logic_and(a < 0.5, b > 0.5)
    return [X, v, dt, s_prev, s, v_end, qs], ca.vertcat(*z, *m), F, events
