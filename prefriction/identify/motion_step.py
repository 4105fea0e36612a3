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

Forward sensitivities ride along: the carried matrix ``S = dy/dw`` of a segment is propagated
sample by sample, ``S <- (dy+/dy) S + (dy+/dp) (dp/dw)``, with the small Jacobians of one sample
built symbolically once. A segment is that step repeated with ``mapaccum`` over ``K`` samples;
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


def step_function(model: FrictionModel, n_sub: int) -> ca.Function:
    """``(y, u0, u1, dt, pp) -> y+``: one sample of the forced oscillator (SX ``Function``).

    ``y = [x, v, z, s]`` (position [m], velocity [m/s], the model's normalised states, the
    direction +-1), ``u0``, ``u1`` the applied force [N] at the start and end of the sample (equal
    for a held force), ``dt`` [s] the sample interval (0 leaves ``y`` unchanged) and
    ``pp = [m, sigma, Fc, F_off, q]`` (mass [kg], reference stiffness [N/m], reference force [N],
    force offset [N], the model's run-time numbers).
    """
    nz, nq = model.n_states, len(model.runtime_params())
    y = ca.SX.sym("y", 3 + nz)
    u0, u1, dt = ca.SX.sym("u0"), ca.SX.sym("u1"), ca.SX.sym("dt")
    pp = ca.SX.sym("pp", 4 + nq)
    m, sigma, Fc, off = pp[0], pp[1], pp[2], pp[3]
    q = [pp[4 + i] for i in range(nq)]
    T, V = ca.sqrt(m / sigma), Fc / ca.sqrt(m * sigma)
    slope = (u1 - u0) / ca.fmax(dt, 1e-300)

    def rhs(s: Any) -> Any:
        def f(yy: list[Any], tau: Any) -> list[Any]:
            z, vn = yy[2:], yy[1] / V
            F = Fc * model.force(z, [], vn, s, q)
            return [yy[1], (u0 + slope * tau - F - off) / m, *[r / T for r in model.rate(z, [], vn, s, q)]]
        return f

    h = dt / n_sub
    yl = [y[i] for i in range(2 + nz)]
    s = y[2 + nz]
    for k in range(n_sub):
        tau = k * h
        a0 = rhs(s)(yl, tau)[1]
        v0, v1 = yl[1], yl[1] + h * a0
        turn = ca.logic_or(s * v0 < 0.0, s * v1 < 0.0)
        frac = ca.if_else(turn, ca.if_else(s * v0 > 0.0, v0 / (v0 - v1), 0.0), 1.0)
        ya = _rk4(rhs(s), yl, tau, frac * h)
        s_new = ca.if_else(turn, -s, s)
        zr, _ = model.reverse(ya[2:], [], s_new, q, 1e-12)
        zr = [ca.fmin(ca.fmax(a, -STATE_CAP), STATE_CAP) for a in zr]
        ya = ya[:2] + [ca.if_else(turn, a, b) for a, b in zip(zr, ya[2:])]
        yl = _rk4(rhs(s_new), ya, tau + frac * h, (1.0 - frac) * h)
        s = s_new
    return ca.Function("motion_step", [y, u0, u1, dt, pp], [ca.vertcat(*yl, s)])


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
                      mass_free: bool) -> tuple[ca.Function, ca.Function]:
    """The shooting segment of ``K`` samples, with and without forward sensitivities (cached).

    Inputs of both: ``node`` (the scaled start state ``[x / Xs, v / Vs, z]``), ``s0`` (its
    direction), ``s_to`` (the direction of the next node), ``theta`` and ``scale`` (the free
    parameters are ``theta * scale``), ``fixed``, ``mass``,
    ``U0``, ``U1``, ``DT`` (rows of ``K`` samples) and ``scl = [Xs, Vs]``. Outputs: ``X``
    (``2 x (K + 1)``: position [m] and velocity [m/s] at the node and after each sample) and
    ``Ye`` (the scaled end state in the coordinates of ``s_to``); the sensitive one adds ``dX``
    (``ncol x (K + 1)``: ``dx/dw`` of each position) and ``dYe`` (``ny x ncol``), ``w`` the
    segment's ``[theta, node]``.
    """
    key = (type(model), model.structure_key(), tuple(space.free), tuple(space.fixed), K, n_sub, mass_free)
    if key in _CACHE:
        return _CACHE[key]
    nz, nq = model.n_states, len(model.runtime_params())
    ny, nth = 2 + nz, space.n_free
    ncol = nth + ny
    step = step_function(model, n_sub)
    units = _units_function(model, space, mass_free)

    # one sample with sensitivities: carry c = [y (ny + 1); vec(S) (ny * ncol)]
    y = ca.SX.sym("y", ny + 1)
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
    sens_acc = sens_step.mapaccum("sens_segment", K)
    plain_acc = plain_step.mapaccum("plain_segment", K)

    # the end state in the coordinates of the next node's direction, scaled
    ye = ca.SX.sym("ye", ny + 1)
    s_to = ca.SX.sym("s_to")
    scl = ca.SX.sym("scl", 2)
    q = [pp[4 + i] for i in range(nq)]
    zr, _ = model.reverse([ye[2 + i] for i in range(nz)], [], s_to, q, 1e-12)
    flip = ye[ny] != s_to
    z_to = [ca.if_else(flip, a, ye[2 + i]) for i, a in enumerate(zr)]
    Ye = ca.vertcat(ye[0] / scl[0], ye[1] / scl[1], *z_to)
    end = ca.Function("end", [ye, s_to, pp, scl], [Ye])
    Se = ca.SX.sym("Se", ny, ncol)
    dYe = ca.mtimes(ca.jacobian(Ye, ye[:ny]), Se) + ca.mtimes(ca.jacobian(Ye, pp), dpp)
    end_sens = ca.Function("end_sens", [ye, Se, s_to, pp, dpp, scl], [Ye, dYe])

    node = ca.MX.sym("node", ny)
    s0, s_next = ca.MX.sym("s0"), ca.MX.sym("s_to")
    th = ca.MX.sym("theta", nth)
    scale = ca.MX.sym("scale", nth)
    fx = ca.MX.sym("fixed", len(space.fixed))
    mass = ca.MX.sym("mass")
    U0, U1, DT = ca.MX.sym("U0", 1, K), ca.MX.sym("U1", 1, K), ca.MX.sym("DT", 1, K)
    sc = ca.MX.sym("scl", 2)
    p_mx = units(th, scale, fx, mass)
    y0 = ca.vertcat(node[0] * sc[0], node[1] * sc[1], node[2:], s0)
    inputs = [node, s0, s_next, th, scale, fx, mass, U0, U1, DT, sc]
    names = ["node", "s0", "s_to", "theta", "scale", "fixed", "mass", "U0", "U1", "DT", "scl"]

    C, O = plain_acc(y0, U0, U1, DT, ca.repmat(p_mx, 1, K))
    X = ca.horzcat(y0[:2], O)
    plain = ca.Function("segment", inputs, [X, end(C[:, K - 1], s_next, p_mx, sc)], names, ["X", "Ye"])

    w = ca.vertcat(th, node)
    dp_mx = ca.horzcat(ca.jacobian(p_mx, th), ca.MX.zeros(4 + nq, ny))
    S0 = ca.jacobian(y0[:ny], w)
    C, O = sens_acc(ca.vertcat(y0, ca.vec(S0)), U0, U1, DT, ca.repmat(p_mx, 1, K), ca.repmat(dp_mx, 1, K))
    X = ca.horzcat(y0[:2], O[:2, :])
    dX = ca.horzcat(S0[0, :].T, O[2:, :])
    cK = C[:, K - 1]
    Ye, dYe = end_sens(cK[: ny + 1], ca.reshape(cK[ny + 1:], ny, ncol), s_next, p_mx, dp_mx, sc)
    sens = ca.Function("segment_sens", inputs, [X, Ye, dX, dYe], names, ["X", "Ye", "dX", "dYe"])
    _CACHE[key] = (plain, sens)
    return plain, sens
