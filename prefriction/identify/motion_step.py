"""One sample of a mass moved by friction and a known force, and shooting segments of them (CasADi).

The oscillator ``m x'' + F + F_off = u`` (2.1) with the model's state ``z`` is advanced from one
sample to the next by ``n_sub`` classical Runge-Kutta sub-steps, in SI units for ``x`` [m] and
``v`` [m/s] and the model's normalised units for ``z`` and its rate (``docs/models.md#protocol``):
``z' = rate(z, v / V, s, q) / T``, ``F = Fc force(z, v / V, s, q)`` with the time unit
``T = sqrt(m / sigma)`` and the velocity unit ``V = Fc / sqrt(m sigma)``. The applied force is
``u0 + (u1 - u0) tau / dt`` at the time ``tau`` into the sample (``u1 = u0``: held, zero-order hold).

The direction ``s`` is carried along with the state. A sub-step whose Euler-predicted end
velocity has the other sign is cut at the predicted zero of the velocity: Runge-Kutta on the
old branch up to it, the model's ``reverse`` (a change of coordinates for models without events,
e.g. Dahl's log-gap), Runge-Kutta on the new branch for the rest. A velocity left a little
on the old side of zero by the cut does not turn the branch back. No step straddles a reversal
by more than the error of that prediction, where the velocity and so the rates are small.

A model with in-branch events carries its flags beside the direction. On the part of a
sub-step before a reversal each event is located at the zero of its indicator (secant from a
Runge-Kutta trial step, refined by one Newton step on the quadratic through three values), the
model's ``on_event`` applied there and the rest integrated (:func:`_branch`); the event time is
a differentiable function of the state and the parameters, so the sensitivities carry its jump.

Forward sensitivities ride along: the carried matrix ``S = dy/dw`` of a segment is propagated
sample by sample, ``S <- (dy+/dy) S + (dy+/dp) (dp/dw)``, with the small Jacobians of one sample
built symbolically once. A segment is that step repeated with ``mapaccum`` over ``K`` samples
(compiled: one sub-step repeated over ``K n_sub`` sub-samples, :func:`segment_functions`);
the segments of a record are evaluated with ``map``. Memory grows with the samples only through
the inputs and outputs (``K`` samples times the number of sensitivity columns per segment).
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from prefriction.identify.parameters import ParameterSpace, symbolic_units
from prefriction.models.base import FrictionModel

__all__ = ["segment_functions", "step_function"]

_CACHE: dict[Any, tuple[ca.Function, ca.Function]] = {}
STATE_CAP = 50.0
"""Bound of a state just after a reversal: Dahl's log-gap reversed twice at a saturated force
is infinite (``exp(-50)`` of ``Fc`` away from it is the same force); the protocol's states are
otherwise of the size of the normalised force."""


def _rk4(f: Any, y: list[Any], tau: Any, h: Any) -> list[Any]:
    """One classical Runge-Kutta step of ``y' = f(y, tau)`` from time ``tau`` with step ``h``."""
    k1 = f(y, tau)
    k2 = f([a + 0.5 * h * b for a, b in zip(y, k1)], tau + 0.5 * h)
    k3 = f([a + 0.5 * h * b for a, b in zip(y, k2)], tau + 0.5 * h)
    k4 = f([a + h * b for a, b in zip(y, k3)], tau + h)
    return [a + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4)]


def _sub_samples(U0: ca.MX, U1: ca.MX, DT: ca.MX, fold: int) -> tuple[ca.MX, ca.MX, ca.MX]:
    """The rows ``U0``, ``U1``, ``DT`` (``1 x K``: force [N] at the start and end of each sample,
    its interval [s]) split into ``fold`` equal sub-samples each (``1 x K fold``, the applied force
    interpolated linearly as in :func:`step_function`)."""
    if fold == 1:
        return U0, U1, DT
    K = U0.size2()
    a = ca.DM([k / fold for k in range(fold)])
    D, start = U1 - U0, ca.repmat(U0, fold, 1)
    rows = [start + ca.mtimes(a, D), start + ca.mtimes(a + 1.0 / fold, D), ca.repmat(DT / fold, fold, 1)]
    return tuple(ca.reshape(r, 1, K * fold) for r in rows)   # type: ignore[return-value]


def step_function(model: FrictionModel, n_sub: int) -> ca.Function:
    """``(y, u0, u1, dt, pp) -> y+``: one sample of the forced oscillator (SX ``Function``).

    ``y = [x, v, z, m, s]`` (position [m], velocity [m/s], the model's normalised states, its
    flags (none for a model without events), the direction +-1), ``u0``, ``u1`` the applied
    force [N] at the start and end of the sample (equal for a held force), ``dt`` [s] the sample
    interval (0 leaves ``y`` unchanged) and ``pp = [m, sigma, Fc, F_off, q]`` (mass [kg],
    reference stiffness [N/m], reference force [N], force offset [N], the model's run-time
    numbers). In-branch events are located inside the sub-steps (:func:`_branch`).
    """
    nz, nf, nq = model.n_states, model.n_flags, len(model.runtime_params())
    y = ca.SX.sym("y", 3 + nz + nf)
    u0, u1, dt = ca.SX.sym("u0"), ca.SX.sym("u1"), ca.SX.sym("dt")
    pp = ca.SX.sym("pp", 4 + nq)
    m, sigma, Fc, off = pp[0], pp[1], pp[2], pp[3]
    q = [pp[4 + i] for i in range(nq)]
    T, V = ca.sqrt(m / sigma), Fc / ca.sqrt(m * sigma)
    slope = (u1 - u0) / ca.fmax(dt, 1e-300)

    def rhs(s: Any, flags: list[Any]) -> Any:
        def f(yy: list[Any], tau: Any) -> list[Any]:
            z, vn = yy[2:], yy[1] / V
            F = Fc * model.force(z, flags, vn, s, q)
            return [yy[1], (u0 + slope * tau - F - off) / m, *[r / T for r in model.rate(z, flags, vn, s, q)]]
        return f

    passes = min(model.n_events, MAX_EVENTS)
    h = dt / n_sub
    yl = [y[i] for i in range(2 + nz)]
    fl = [y[2 + nz + i] for i in range(nf)]
    s = y[2 + nz + nf]
    for k in range(n_sub):
        tau = k * h
        a0 = rhs(s, fl)(yl, tau)[1]
        v0, v1 = yl[1], yl[1] + h * a0
        # a velocity the last cut left a little on the old side of zero (s v0 < 0, s v1 > 0) is no turn: taken for
        # one, the next sub-step ran on the old branch and the end state jumped as the cut crossed a boundary
        turn = s * v1 < 0.0
        frac = ca.if_else(turn, ca.if_else(s * v0 > 0.0, v0 / (v0 - v1), 0.0), 1.0)
        if passes:
            ya, fa = _branch(model, rhs, yl, fl, s, tau, frac * h, passes, V, q)
        else:
            ya, fa = _rk4(rhs(s, fl), yl, tau, frac * h), fl
        s_new = ca.if_else(turn, -s, s)
        zr, fr = model.reverse(ya[2:], fa, s_new, q, 1e-12)
        zr = [ca.fmin(ca.fmax(a, -STATE_CAP), STATE_CAP) for a in zr]
        ya = ya[:2] + [ca.if_else(turn, a, b) for a, b in zip(zr, ya[2:])]
        fl = [ca.if_else(turn, a, b) for a, b in zip(fr, fa)]
        yl = _rk4(rhs(s_new, fl), ya, tau + frac * h, (1.0 - frac) * h)
        s = s_new
    return ca.Function("motion_step", [y, u0, u1, dt, pp], [ca.vertcat(*yl, *fl, s)])


MAX_EVENTS = 4
"""Most in-branch events located inside one sub-step (on its part before a reversal); a further
one fires at the start of the next sub-step (its indicator is then negative)."""


def _branch(model: FrictionModel, rhs: Any, y: list[Any], flags: list[Any], s: Any, tau: Any, length: Any,
            passes: int, V: Any, q: list[Any]) -> tuple[list[Any], list[Any]]:
    """``length`` of time on the branch of direction ``s`` from ``(y, flags)`` at ``tau``, the
    in-branch events located inside it (symbolic, one expression).

    Each pass takes a Runge-Kutta trial step over what is left. An event whose indicator is
    positive at the start and not at the trial's end is located at the zero of the indicator's
    secant, ``theta = g0 / (g0 - g1)`` of the remaining length; one already not positive fires at
    once (``theta = 0``). The earliest event is applied: Runge-Kutta up to it, ``on_event``, and
    the next pass continues from there. ``theta`` is a differentiable function of the state and
    the parameters, so the forward sensitivities carry the jump of the event time (saltation).
    After ``passes`` passes a last Runge-Kutta step covers the rest of the length.
    """
    nz = model.n_states
    left = length
    for _ in range(passes):
        trial = _rk4(rhs(s, flags), y, tau, left)
        g0 = model.events(y[2:], flags, y[1] / V, s, q)
        g1 = model.events(trial[2:], flags, trial[1] / V, s, q)
        best, sel = ca.SX(2.0), ca.SX(-1.0)
        for k, (a, b) in enumerate(zip(g0, g1)):
            cross = ca.logic_and(a > 0.0, b <= 0.0)
            theta = ca.if_else(a <= 0.0, 0.0, ca.if_else(cross, a / ca.if_else(cross, a - b, 1.0), 2.0))
            better = theta < best
            best = ca.if_else(better, theta, best)
            sel = ca.if_else(better, float(k), sel)
        hit = best <= 1.0
        theta = ca.if_else(hit, best, 1.0)
        # one Newton step on the quadratic through the indicator at 0, theta and 1
        ym = _rk4(rhs(s, flags), y, tau, theta * left)
        gs = _selected(sel, g0), _selected(sel, model.events(ym[2:], flags, ym[1] / V, s, q)), _selected(sel, g1)
        inner = ca.logic_and(theta > 0.0, theta < 1.0)
        d0, d1 = theta, 1.0 - theta
        slope = (ca.if_else(inner, (gs[1] - gs[0]) / ca.if_else(inner, d0, 1.0) + (gs[2] - gs[1]) / ca.if_else(inner, d1, 1.0), 0.0)
                 - (gs[2] - gs[0]))
        newton = theta - gs[1] / ca.if_else(slope < 0.0, slope, -1.0)
        theta = ca.if_else(ca.logic_and(inner, slope < 0.0), ca.fmin(ca.fmax(newton, 0.0), 1.0), theta)
        step = theta * left
        ye = _rk4(rhs(s, flags), y, tau, step)
        ze, fe = _fire(model, sel, ye[2:], flags, s, q)
        y = ye[:2] + [ca.if_else(hit, a, b) for a, b in zip(ze, ye[2:2 + nz])]
        flags = [ca.if_else(hit, a, b) for a, b in zip(fe, flags)]
        tau, left = tau + step, left - step
    return _rk4(rhs(s, flags), y, tau, left), flags


def _fire(model: FrictionModel, sel: Any, z: list[Any], flags: list[Any], s: Any,
          q: list[Any]) -> tuple[list[Any], list[Any]]:
    """The state just after the in-branch event of symbolic index ``sel`` (``on_event_at`` where
    the model has it: one expression for every index; else ``on_event`` of each, selected)."""
    at = getattr(model, "on_event_at", None)
    if at is not None:
        zn, fn = at(sel, z, flags, s, q)
        return list(zn), list(fn)
    zo, fo = list(z), list(flags)
    for k in range(model.n_events):
        zk, fk = model.on_event(k, z, flags, s, q)
        zo = [ca.if_else(sel == k, a, b) for a, b in zip(zk, zo)]
        fo = [ca.if_else(sel == k, a, b) for a, b in zip(fk, fo)]
    return zo, fo


def _units_function(model: FrictionModel, space: ParameterSpace, mass_free: bool) -> ca.Function:
    """``(theta, scale, fixed, mass) -> pp``: the step's numbers from the free parameters
    ``theta * scale`` (SX; the scales are inputs, so one function serves every start point)."""
    theta = ca.SX.sym("theta", space.n_free)
    scale = ca.SX.sym("scale", space.n_free)
    fixed = ca.SX.sym("fixed", len(space.fixed))
    mass_in = ca.SX.sym("mass")
    values = space.symbols(theta, fixed, scale)
    mass = values["mass"] if mass_free else mass_in
    sigma, Fc, q = symbolic_units(model, values, mass)
    off = values.get("offset", 0.0)
    pp = ca.vertcat(mass, sigma, Fc, off, q)
    return ca.Function("units", [theta, scale, fixed, mass_in], [pp])


def segment_functions(model: FrictionModel, space: ParameterSpace, K: int, n_sub: int,
                      mass_free: bool, native: bool = False) -> tuple[ca.Function, ca.Function]:
    """The shooting segment of ``K`` samples, with and without forward sensitivities (cached).

    Inputs of both: ``node`` (the scaled start state ``[x / Xs, v / Vs, z]``), ``m0`` (its
    flags, none for a model without events), ``s0`` (its direction), ``s_to`` (the direction of
    the next node), ``theta`` and ``scale`` (the free
    parameters are ``theta * scale``), ``fixed``, ``mass``,
    ``U0``, ``U1``, ``DT`` (rows of ``K`` samples) and ``scl = [Xs, Vs]``. Outputs: ``X``
    (``2 x (K + 1)``: position [m] and velocity [m/s] at the node and after each sample), ``Ye``
    (the scaled end state in the coordinates of ``s_to``) and ``Me`` (its flags in those
    coordinates: they ride along like the direction, without derivatives); the sensitive one adds ``dX``
    (``ncol x (K + 1)``: ``dx/dw`` of each position) and ``dYe`` (``ny x ncol``), ``w`` the
    segment's ``[theta, node]``.

    ``native``: one Runge-Kutta sub-step (with and without its sensitivities) is compiled to C
    (:func:`prefriction.simulation.compiled`, cached on disk per structure and free set, whatever
    ``n_sub``; the interpreted segments of ``native=False`` if it cannot be compiled) and repeated ``n_sub`` times per
    sample over the sample split into equal sub-samples: the same arithmetic as the interpreted
    step of ``n_sub`` sub-steps, the sensitivities carried sub-step by sub-step
    (``S <- (dy+/dy) S + (dy+/dp) (dp/dw)``, the chain rule of the interpreted step's Jacobian).
    """
    key = (type(model), model.structure_key(), tuple(space.free), tuple(space.fixed), K, n_sub, mass_free, native)
    if key in _CACHE:
        return _CACHE[key]
    nz, nf, nq = model.n_states, model.n_flags, len(model.runtime_params())
    ny, nth = 2 + nz, space.n_free
    ncol = nth + ny
    fold = n_sub if native else 1   # compiled: one sub-step, repeated (one library per structure, any n_sub)
    step = step_function(model, 1 if native else n_sub)
    units = _units_function(model, space, mass_free)

    # one sample with sensitivities: carry c = [y (ny + nf + 1); vec(S) (ny * ncol)]
    y = ca.SX.sym("y", ny + nf + 1)
    S = ca.SX.sym("S", ny, ncol)
    u0, u1, dt = ca.SX.sym("u0"), ca.SX.sym("u1"), ca.SX.sym("dt")
    pp = ca.SX.sym("pp", 4 + nq)
    dpp = ca.SX.sym("dpp", 4 + nq, ncol)
    y1 = step(y, u0, u1, dt, pp)
    Jy = ca.jacobian(y1[:ny], y[:ny])
    Jp = ca.jacobian(y1[:ny], pp)
    S1 = ca.mtimes(Jy, S) + ca.mtimes(Jp, dpp)
    c = ca.vertcat(y, ca.vec(S))
    c1 = ca.vertcat(y1, ca.vec(S1))
    sens_step = ca.Function("sens_step", [c, u0, u1, dt, pp, dpp], [c1, ca.vertcat(y1[:2], S1[0, :].T)])
    plain_step = ca.Function("plain_step", [y, u0, u1, dt, pp], [y1, y1[:2]])
    if native:
        from prefriction.simulation.compiled import compiled

        sens_step, made = compiled(sens_step, "Motion fit step with sensitivities")
        if made.mode == "interpreted":   # no compiler: the unrolled interpreted step is the faster (Dahl: 1.6 times)
            _CACHE[key] = segment_functions(model, space, K, n_sub, mass_free, False)
            return _CACHE[key]
        plain_step = compiled(plain_step, "Motion fit step")[0]
    sens_acc = sens_step.mapaccum("sens_segment", K * fold)
    plain_acc = plain_step.mapaccum("plain_segment", K * fold)
    last = ca.Slice(fold - 1, K * fold, fold)   # the sub-steps that end a sample

    # the end state in the coordinates of the next node's direction, scaled
    ye = ca.SX.sym("ye", ny + nf + 1)
    s_to = ca.SX.sym("s_to")
    scl = ca.SX.sym("scl", 2)
    q = [pp[4 + i] for i in range(nq)]
    fe = [ye[ny + i] for i in range(nf)]
    zr, fr = model.reverse([ye[2 + i] for i in range(nz)], fe, s_to, q, 1e-12)
    flip = ye[ny + nf] != s_to
    z_to = [ca.if_else(flip, a, ye[2 + i]) for i, a in enumerate(zr)]
    Ye = ca.vertcat(ye[0] / scl[0], ye[1] / scl[1], *z_to)
    Me = ca.vertcat(*[ca.if_else(flip, a, b) for a, b in zip(fr, fe)]) if nf else ca.SX(0, 1)
    end = ca.Function("end", [ye, s_to, pp, scl], [Ye, Me])
    Se = ca.SX.sym("Se", ny, ncol)
    dYe = ca.mtimes(ca.jacobian(Ye, ye[:ny]), Se) + ca.mtimes(ca.jacobian(Ye, pp), dpp)
    end_sens = ca.Function("end_sens", [ye, Se, s_to, pp, dpp, scl], [Ye, Me, dYe])

    node = ca.MX.sym("node", ny)
    m0 = ca.MX.sym("m0", nf)
    s0, s_next = ca.MX.sym("s0"), ca.MX.sym("s_to")
    th = ca.MX.sym("theta", nth)
    scale = ca.MX.sym("scale", nth)
    fx = ca.MX.sym("fixed", len(space.fixed))
    mass = ca.MX.sym("mass")
    U0, U1, DT = ca.MX.sym("U0", 1, K), ca.MX.sym("U1", 1, K), ca.MX.sym("DT", 1, K)
    sc = ca.MX.sym("scl", 2)
    p_mx = units(th, scale, fx, mass)
    y0 = ca.vertcat(node[0] * sc[0], node[1] * sc[1], node[2:], m0, s0)
    inputs = [node, m0, s0, s_next, th, scale, fx, mass, U0, U1, DT, sc]
    names = ["node", "m0", "s0", "s_to", "theta", "scale", "fixed", "mass", "U0", "U1", "DT", "scl"]

    U0f, U1f, DTf = _sub_samples(U0, U1, DT, fold)
    C, O = plain_acc(y0, U0f, U1f, DTf, ca.repmat(p_mx, 1, K * fold))
    X = ca.horzcat(y0[:2], O[:, last])
    Ye, Me = end(C[:, K * fold - 1], s_next, p_mx, sc)
    plain = ca.Function("segment", inputs, [X, Ye, Me], names, ["X", "Ye", "Me"])

    w = ca.vertcat(th, node)
    dp_mx = ca.horzcat(ca.jacobian(p_mx, th), ca.MX.zeros(4 + nq, ny))
    S0 = ca.jacobian(y0[:ny], w)
    C, O = sens_acc(ca.vertcat(y0, ca.vec(S0)), U0f, U1f, DTf, ca.repmat(p_mx, 1, K * fold),
                    ca.repmat(dp_mx, 1, K * fold))
    O = O[:, last]
    X = ca.horzcat(y0[:2], O[:2, :])
    dX = ca.horzcat(S0[0, :].T, O[2:, :])
    cK = C[:, K * fold - 1]
    Ye, Me, dYe = end_sens(cK[: ny + nf + 1], ca.reshape(cK[ny + nf + 1:], ny, ncol), s_next, p_mx, dp_mx, sc)
    sens = ca.Function("segment_sens", inputs, [X, Ye, Me, dX, dYe], names, ["X", "Ye", "Me", "dX", "dYe"])
    _CACHE[key] = (plain, sens)
    return plain, sens


def _selected(sel: Any, values: list[Any]) -> Any:
    """``values[sel]`` for a symbolic index ``sel`` (0 where ``sel`` is no index)."""
    out = ca.SX(0.0)
    for k, value in enumerate(values):
        out = ca.if_else(sel == k, value, out)
    return out
