"""Symbolic time steps of a friction model (CasADi): RK4 sub-steps, event snaps, reversals.

A fit needs the model's state as an expression of the parameters, differentiable by CasADi.
Between two samples the direction ``s`` is fixed; the state is advanced by ``n_sub`` classical
Runge-Kutta sub-steps of the protocol's ``rate`` (``docs/models.md#protocol``). After each
sub-step every in-branch event whose indicator has turned negative is applied with
``on_event``, which puts the state on the switching surface: for piecewise-linear models
(Maxwell-slip, Dahl with ``gamma < 1``, whose rates are constant up to the event and zero after
it) this is exact; otherwise it costs one sub-step of accuracy at the event.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import casadi as ca

from prefriction.models.base import FrictionModel

__all__ = ["apply_events", "interval_function", "rk4"]


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


def interval_function(model: FrictionModel, n_sub: int, snap: float = 1e-12) -> ca.Function:
    """The state over one sample interval of prescribed motion, as a CasADi ``Function``.

    ``(X, v, dt, s_prev, s, v_end, q) -> (X_next, F)``: state ``X = [z; m]`` (normalised), the
    interval's constant normalised velocity ``v`` and duration ``dt``, the direction of the
    previous interval ``s_prev`` and of this one ``s`` (a reversal, ``reverse``, where they
    differ), the velocity ``v_end`` at the sample that ends the interval (rate-dependent forces)
    and the run-time numbers ``q``. ``F`` is the normalised force at the end of the interval.
    """
    nz, nm, nq = model.n_states, model.n_flags, len(_q_template(model))
    X = ca.SX.sym("X", nz + nm)
    v, dt, s_prev, s, v_end = (ca.SX.sym(n) for n in ("v", "dt", "s_prev", "s", "v_end"))
    qs = ca.SX.sym("q", nq)
    q = [qs[i] for i in range(nq)]
    z = [X[i] for i in range(nz)]
    m = [X[nz + i] for i in range(nm)]
    zr, mr = model.reverse(z, m, s, q, snap)
    rev = s * s_prev < 0.0
    z = [ca.if_else(rev, a, b) for a, b in zip(zr, z)]
    m = [ca.if_else(rev, a, b) for a, b in zip(mr, m)]
    h = dt / n_sub
    for _ in range(n_sub):
        mm = list(m)
        z = rk4(lambda y, mm=mm: model.rate(y, mm, v, s, q), z, h)
        z, m = apply_events(model, z, m, v, s, q)
    F = model.force(z, m, v_end, s, q)
    return ca.Function("interval", [X, v, dt, s_prev, s, v_end, qs], [ca.vertcat(*z, *m), F])


def _q_template(model: FrictionModel) -> Sequence[float]:
    return model.runtime_params()
