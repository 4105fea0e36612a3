"""CasADi model of the Dahl oscillator on a branch, with reversal, saturation and rest events.

The integrated state is normalised (DESIGN.md section 2) and, per call, scaled by amplitude
parameters so that the error control of the integrator is relative to the current motion.
Time inside one call is ``tau`` in ``[0, n_out]``; the control ``dur`` of each output interval
(one unit of ``tau``) is its duration in normalised time, so one compiled Function serves any
output grid.

State vector (indices in :class:`Layout`), kept short because the cost of a step grows with it:

``xh, vh, Fh``
    ``x~ = xref + Ax xh``, ``v~ = Av vh`` and the branch distance ``p = AF Fh`` with
    ``F~ = s f(p)`` (see :class:`PlantSpec` and :func:`force_of_p`);
``s, n``
    branch direction (+-1) and reversals so far; the call stops (right-hand side zero) once
    ``n`` reaches the parameter ``nstop``;
``sat``
    saturation flag (gamma < 1 only): ``|F| = Fc``, ``F' = 0`` until the next reversal;
``rest, Wh``
    (forced systems only) rest flag (``v = 0`` and ``u = F``) and the input work since the last
    reversal, ``W~ = AE Wh``;
``Eh``
    work of the friction force since t = 0, ``E_f~ = Efref + AE Eh`` (dense output only), (2.8);
``xch``
    continuous controller states, ``xc = S * xch``;
register
    the newest ``K`` reversals, newest first: ``(t~, x~, F~[, W~])`` each.

Normalised time is ``t~ = t0 + dur * tau`` with the integrator time ``tau`` and the controls
``t0``, ``dur`` of the output interval.

Events (the integrator fires when an indicator goes from positive to negative):

- reversal, indicator ``s v`` (forced: ``s v / Av + EPS_START``). Unforced: always a reversal (register shift, ``s -> -s``).
  Forced: the net force ``a~ = u~ - F~`` decides: ``s a~ < -eps``: a reversal;
  ``s a~ > eps``: the velocity touches zero and keeps its sign (nothing changes); otherwise
  the mass rests (``v = 0``, right-hand side zero).
- saturation (gamma < 1 only), indicator ``1 - (1 - gamma) p``: ``F~ = s`` exactly, ``F' = 0``
  until the next reversal; a reversal within ``snap`` of saturation is one at saturation.
- end of rest (forced only), indicator ``eps_rest - |a~|``: the mass moves again in direction
  ``sign(a~)``, a reversal if that differs from ``s``.

``eps`` and ``eps_rest`` are :data:`EPS_TOUCH` and :data:`EPS_REST` times the amplitude scale.

Compact model (``PlantSpec.compact``, unforced without dense output): states ``vh, Fh``
(gamma >= 1: the position follows from ``x - x_start = s (p - p_start)`` on the branch) or
``xh, vh, Fh, sat`` (gamma < 1), the direction ``s`` a parameter; the call stops at the first
reversal (its transition sets ``vh = -s (1 + tau)``: the stop flag and the time of the reversal
in one state) and the caller starts the next branch. A step costs about a third less than with
the register of two reversals (2 states instead of 11).
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import tempfile
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import casadi as ca
import numpy as np

__all__ = ["EPS_TOUCH", "EPS_REST", "Layout", "PlantSpec", "build_integrator"]

EPS_TOUCH = 1e-14
"""Net force (relative to the call's amplitude scale) below which a zero velocity is rest."""
EPS_REST = 1e-12
"""Net force (relative to the call's amplitude scale) above which a resting mass moves again."""
EPS_START = 1e-13
"""Offset of the forced reversal indicator ``s v / Av + EPS_START``: a branch that starts at
``v = 0`` starts with a positive indicator, so a velocity that turns against ``s`` before it
has grown (the net force reverses within the first step) still fires the reversal event."""


@dataclass(frozen=True)
class PlantSpec:
    """Structure of the integrated model (everything that changes the generated code).

    The force state is the distance coordinate ``p`` of the branch, ``dp/dt = s v~``:
    ``p = -ln(1 - f)`` for gamma = 1, ``p = (1 - (1 - f)^(1 - gamma)) / (1 - gamma)`` otherwise,
    with ``f = s F~`` (:func:`force_of_p`). The right-hand side is then linear in the state
    except for the smooth map ``f(p)``: no stiff decay of the gap ``1 - f`` in gross sliding,
    full relative accuracy for small forces (``p ~ f``), and for gamma < 1 saturation is the
    transversal crossing ``p = 1 / (1 - gamma)``.
    """

    u_kind: str = "none"
    u_fun: Callable[[Any], Any] | None = None
    fb: str = "none"
    n_c: int = 0
    r_kind: str = "none"
    r_fun: Callable[[Any], Any] | None = None
    energy: bool = False
    K: int = 4
    n_out: int = 1
    method: str = "erk"
    gamma: float = 1.0
    compact: bool = False
    """Use the compact model (:func:`build_integrator`) where it applies: unforced, no dense output."""

    @property
    def saturates(self) -> bool:
        """True if the branch reaches ``|F| = Fc`` at a finite distance (gamma < 1)."""
        return self.gamma < 1.0


    @property
    def forced(self) -> bool:
        """True if any force besides friction acts (input or feedback)."""
        return self.u_kind != "none" or self.fb != "none"

    @property
    def stops_at_reversal(self) -> bool:
        """True for the compact unforced model (:func:`build_integrator`, ``compact=True``)."""
        return self.compact and not self.forced and not self.energy and self.n_out == 1


class Layout:
    """Index map of the state, parameter and control vectors for a :class:`PlantSpec`."""

    def __init__(self, spec: PlantSpec) -> None:
        if spec.stops_at_reversal:
            self._compact(spec)
            return
        names = ["xh", "vh", "Fh", "s", "n"]
        if spec.saturates:
            names.append("sat")
        if spec.forced:
            names += ["rest", "Wh"]
        if spec.energy:
            names.append("Eh")
        self.state = {k: i for i, k in enumerate(names)}
        self.xc = slice(len(names), len(names) + spec.n_c)
        self.reg = len(names) + spec.n_c
        self.reg_width = 4 if spec.forced else 3
        self.nx = self.reg + spec.K * self.reg_width
        self.n_active = 3 + int(spec.forced) + int(spec.energy) + spec.n_c
        pnames = ["Ax", "Av", "AF", "AE", "xref", "Efref", "nstop", "snap", "tunit", "xunit", "Fc"]
        if spec.r_kind == "const":
            pnames.append("r")
        self.param = {k: i for i, k in enumerate(pnames)}
        n = spec.n_c
        self.p_A = len(pnames)
        self.p_B = self.p_A + n * n
        self.p_C = self.p_B + n
        self.p_D = self.p_C + n
        self.p_S = self.p_D + (1 if spec.fb == "continuous" else 0)
        self.np = self.p_S + n
        cnames = ["dur", "t0"]
        if spec.u_kind == "samples" or spec.r_kind == "samples":
            cnames.append("tl")
        if spec.u_kind == "samples":
            cnames += ["ua", "ub"]
        if spec.r_kind == "samples":
            cnames += ["ra", "rb"]
        if spec.fb == "sampled":
            cnames.append("uhold")
        self.control = {k: i for i, k in enumerate(cnames)}
        self.nu = len(cnames)

    def _compact(self, spec: PlantSpec) -> None:
        """Layout of the compact unforced model: ``vh, Fh`` (``xh, vh, Fh, sat`` for gamma < 1),
        parameters ``Ax, Av, AF, s``, controls ``dur, t0``."""
        # without saturation x - x_start = s (p - p_start) on the branch: no position state
        names = ["xh", "vh", "Fh", "sat"] if spec.saturates else ["vh", "Fh"]
        self.state = {k: i for i, k in enumerate(names)}
        self.xc = slice(len(names), len(names))
        self.reg = self.nx = len(names)
        self.reg_width = 0
        self.n_active = 3 if spec.saturates else 2
        self.param = {k: i for i, k in enumerate(["Ax", "Av", "AF", "s"])}
        self.p_A = self.p_B = self.p_C = self.p_D = self.p_S = self.np = len(self.param)
        self.control = {"dur": 0, "t0": 1}
        self.nu = 2


def _signal(kind: str, fun: Callable[[Any], Any] | None, t_si: ca.SX, c: dict, prefix: str, p: dict) -> Any:
    """Symbolic value (SI) of an input or reference signal at time ``t_si``."""
    if kind == "callable":
        return fun(t_si)
    if kind == "samples":
        return c[prefix + "a"] + c[prefix + "b"] * (t_si - c["tl"])
    if kind == "const":
        return p["r"]
    return 0.0


def force_of_p(p: Any, g: float) -> Any:
    """Normalised branch force ``f = s F / Fc`` at the distance coordinate ``p`` (CasADi or float).

    Inverse of :func:`p_of_force`. Symbolically, past saturation ``p = 1 / (1 - gamma)`` (before
    the saturation event stops the force) ``f`` continues smoothly so that the step across it
    stays accurate: analytically where ``1 / (1 - gamma)`` is an integer (gamma = 0, 1/2, 2/3,
    ...), otherwise as ``f = 1`` (continuous in the derivatives of order < 1 / (1 - gamma)).
    """
    if g == 1.0:
        return -ca.expm1(-p) if isinstance(p, ca.SX) else -math.expm1(-p)
    if isinstance(p, ca.SX):
        m = 1.0 / (1.0 - g)
        if g > 1.0:
            return -ca.expm1(ca.log1p(-(1.0 - g) * p) * m)
        q = ca.fmin((1.0 - g) * p, 1.0 - 1e-16)
        f = -ca.expm1(ca.log1p(-q) * m)  # accurate for small p
        if m.is_integer():  # past saturation: the polynomial 1 - (1 - (1 - g) p)^m continues it
            return ca.if_else((1.0 - g) * p < 1.0, f, 1.0 - (1.0 - (1.0 - g) * p) ** int(m))
        return f
    q = (1.0 - g) * p
    if q >= 1.0:
        return 1.0
    return -math.expm1(math.log1p(-q) / (1.0 - g))


def p_of_force(f: Any, g: float) -> Any:
    """Distance coordinate ``p`` of the branch force ``f = s F / Fc`` (``-ln(1 - f)`` for gamma = 1)."""
    if isinstance(f, ca.SX):
        if g == 1.0:
            return -ca.log1p(-f)
        return -ca.expm1((1.0 - g) * ca.log1p(-f)) / (1.0 - g)
    if f >= 1.0:
        return 1.0 / (1.0 - g) if g < 1.0 else math.inf
    if g == 1.0:
        return -math.log1p(-f)
    return -math.expm1((1.0 - g) * math.log1p(-f)) / (1.0 - g)


def trace_signal(fun: Callable[[Any], Any], what: str) -> ca.SX:
    """Evaluate ``fun`` on a CasADi symbol; ``TypeError`` with advice if it cannot be traced."""
    t = ca.SX.sym("t")
    try:
        val = fun(t)
        val = ca.SX(val) if not isinstance(val, ca.SX) else val
    except Exception as exc:  # any failure of user code on a symbol means: not traceable
        raise TypeError(
            f"{what} must accept a CasADi symbol for time t (use numpy ufuncs such as np.sin, "
            f"arithmetic, or casadi functions; no if/else on t, no float(t)); calling it on a symbol "
            f"failed with {type(exc).__name__}: {exc}. Pass samples (t, values) instead."
        ) from None
    if val.numel() != 1:
        raise TypeError(f"{what} must return a scalar, got shape {val.shape}")
    # math.sin(symbol) gives nan, float(symbol) branches silently: compare with numeric calls
    f = ca.Function("signal", [t], [val])
    for t0 in (0.0, 0.3183, 1.7):
        traced = float(f(t0))
        try:
            direct = float(np.asarray(fun(t0), dtype=float))
        except Exception as exc:  # user code failing on a float
            raise TypeError(f"{what} failed on a float time t = {t0}: {type(exc).__name__}: {exc}") from None
        same = (np.isnan(traced) and np.isnan(direct)) or abs(traced - direct) <= 1e-12 * max(1.0, abs(direct))
        if not same:
            raise TypeError(
                f"{what} does not trace into CasADi: on a symbol it gives {traced!r} at t = {t0}, "
                f"called directly {direct!r} (math.* functions and if/else on t do not trace; use numpy "
                f"ufuncs such as np.sin, or casadi.if_else). Pass samples (t, values) instead."
            )
    return val


def _symbols(spec: PlantSpec) -> tuple:
    """Layout, symbols (state ``X``, parameters ``P``, controls ``U``, time ``tau``) and the
    name -> entry maps of state, parameters and controls of the model ``spec``."""
    L = Layout(spec)
    X = ca.SX.sym("X", L.nx)
    P = ca.SX.sym("P", L.np)
    U = ca.SX.sym("U", L.nu)
    tau = ca.SX.sym("tau")
    st = {k: X[i] for k, i in L.state.items()}
    p = {k: P[i] for k, i in L.param.items()}
    c = {k: U[i] for k, i in L.control.items()}
    return L, X, P, U, tau, st, p, c


def build_integrator(spec: PlantSpec, tol: float, atol: float) -> ca.Function:
    """CasADi integrator (``spec.method``) over ``spec.n_out`` output intervals, with events
    (the compact model of the module notes if ``spec.stops_at_reversal``).

    Parameters
    ----------
    spec : PlantSpec
        Model structure.
    tol, atol : float
        Relative and absolute tolerance of the scaled state, already corrected for the
        root-mean-square error norm over all states (see :func:`prefriction.simulate`).
    """
    if spec.stops_at_reversal:
        return _build_compact(spec, tol, atol)
    L, X, P, U, tau, st, p, c = _symbols(spec)
    n = spec.n_c
    x = p["xref"] + p["Ax"] * st["xh"]
    v = p["Av"] * st["vh"]
    s = st["s"]
    g = spec.gamma
    sat = st["sat"] if spec.saturates else 0.0
    rest = st["rest"] if spec.forced else 0.0
    pp = p["AF"] * st["Fh"]
    F = s * force_of_p(pp, g)
    t_n = c["t0"] + c["dur"] * tau  # normalised time
    t_si = t_n * p["tunit"]
    u = _signal(spec.u_kind, spec.u_fun, t_si, c, "u", p) / p["Fc"]
    xc = ca.SX(0, 1)
    if spec.fb != "none":
        r = _signal(spec.r_kind, spec.r_fun, t_si, c, "r", p) / p["xunit"]
        e = r - x
        if spec.fb == "continuous":
            A = ca.reshape(P[L.p_A:L.p_B], n, n)
            B = P[L.p_B:L.p_C]
            C = ca.reshape(P[L.p_C:L.p_D], 1, n)
            S = P[L.p_S:L.np]
            xc = S * X[L.xc]
            u = u + (ca.mtimes(C, xc) if n else 0.0) + P[L.p_D] * e
        else:
            u = u + c["uhold"] / p["Fc"]
    acc = u - F
    run = ca.if_else(st["n"] < p["nstop"], 1.0, 0.0)  # stop after the nstop-th reversal
    run_m = run * (1.0 - rest) if spec.forced else run
    dF = s * v * (1.0 - sat)  # dp/dt
    dot = {"xh": run_m * v / p["Ax"], "vh": run_m * acc / p["Av"], "Fh": run_m * dF / p["AF"]}
    if spec.forced:
        dot["Wh"] = run_m * u * v / p["AE"]
    if spec.energy:
        dot["Eh"] = run_m * F * v / p["AE"]
    ode = ca.SX.zeros(L.nx)
    for k, val in dot.items():
        ode[L.state[k]] = val
    if spec.fb == "continuous" and n:
        ode[L.xc] = run * (ca.mtimes(A, xc) + B * e) / S
    ode = c["dur"] * ode
    # forced: offset so that a branch starting at v = 0 has a positive indicator (EPS_START)
    zero = [ca.if_else(run_m > 0.5, s * st["vh"] + (EPS_START if spec.forced else 0.0), 1.0)]
    if spec.saturates:
        zero.append(ca.if_else(run_m * (1.0 - sat) > 0.5, 1.0 - (1.0 - g) * pp, 1.0))
    if spec.forced:
        zero.append(ca.if_else(run * rest > 0.5, EPS_REST * p["Av"] - ca.fabs(acc), 1.0))
    dae = {"x": X, "p": P, "u": U, "t": tau, "ode": ode, "zero": ca.vertcat(*zero)}

    # transition: the state just after an event
    idx = ca.SX.sym("index")
    reg = X[L.reg:]
    W = p["AE"] * st["Wh"] if spec.forced else None
    entry = [t_n, x, F] + ([W] if spec.forced else [])
    shifted = ca.vertcat(*entry, reg[: -L.reg_width])

    def with_(changes: dict, base: ca.SX = X) -> ca.SX:
        out = ca.SX(base)
        for k, val in changes.items():
            if k == "reg":
                out[L.reg:] = val
            else:
                out[L.state[k]] = val
        return out

    def force_state(new_s: Any) -> Any:
        """Scaled force state on the branch of direction ``new_s`` for the current force.

        For gamma < 1 a reversal closer than ``snap`` to saturation is a reversal at
        saturation: the two events coincide to the tolerance (gamma = 0 reaches both at once
        in its undamped oscillation; resolving their order by round-off would bleed energy).
        """
        Fs = ca.if_else(1.0 - (1.0 - g) * pp < p["snap"], s, F) if spec.saturates else F
        return p_of_force(new_s * Fs, g) / p["AF"]

    def reversal(new_s: Any, extra: dict) -> ca.SX:
        ch = {"reg": shifted, "n": st["n"] + 1, "s": new_s, "Fh": force_state(new_s)}
        if spec.saturates:
            ch["sat"] = 0.0
        if spec.forced:
            ch["Wh"] = 0.0
        ch.update(extra)
        return with_(ch)

    sa = s * acc
    if spec.forced:  # zero velocity: reversal, touch (velocity keeps its sign) or rest
        eps = EPS_TOUCH * p["Av"]
        posts = [ca.if_else(sa < -eps, reversal(-s, {}),
                            ca.if_else(sa > eps, X, with_({"rest": 1.0, "vh": 0.0})))]
    else:
        posts = [reversal(-s, {})]
    if spec.saturates:
        posts.append(with_({"sat": 1.0, "Fh": 1.0 / ((1.0 - g) * p["AF"])}))
    if spec.forced:
        new_dir = ca.if_else(acc > 0, 1.0, -1.0)
        posts.append(ca.if_else(new_dir != s, reversal(new_dir, {"rest": 0.0}), with_({"rest": 0.0})))
    post = posts[-1]
    for k in range(len(posts) - 2, -1, -1):
        post = ca.if_else(idx == k, posts[k], post)
    trans = ca.Function(
        "transition", [idx, tau, X, ca.SX(0, 1), P, U], [post, ca.SX(0, 1)],
        ca.event_in(), ca.event_out(),
    )
    opts = _options(spec, trans, tol, atol)
    grid = [float(j) for j in range(1, spec.n_out + 1)]
    with _without_event_notice():
        return ca.integrator(f"dahl_{spec.method}_{spec.n_out}", spec.method, dae, 0.0, grid, opts)


def _build_compact(spec: PlantSpec, tol: float, atol: float) -> ca.Function:
    """The unforced oscillator up to its next reversal, with as few states as possible.

    States ``vh, Fh`` (as in :func:`build_integrator`; with ``xh`` and ``sat`` for gamma < 1,
    else the caller takes ``x`` from ``p``); the direction ``s`` is a parameter. Before the
    reversal ``s vh > 0``; the transition of the reversal sets ``vh = -s (1 + tau)`` (the
    velocity there is zero; ``tau`` in [0, 1] is the integrator time of the reversal), which
    also stops the right-hand side: the state at the end of the call is the state at the
    reversal, and the caller starts the next branch. The cost of a step grows with the number
    of states: 2 here (4 with saturation) against 11 with a register of two reversals.
    """
    L, X, P, U, tau, st, p, _ = _symbols(spec)
    g, s = spec.gamma, p["s"]
    sat = st["sat"] if spec.saturates else 0.0
    pp = p["AF"] * st["Fh"]
    F = s * force_of_p(pp, g)
    v = p["Av"] * st["vh"]
    moving = s * st["vh"] > -0.5  # no reversal yet in this call
    run = ca.if_else(moving, U[0], 0.0)  # dur while no reversal came, then 0
    ode = ca.SX.zeros(L.nx)
    if spec.saturates:
        ode[L.state["xh"]] = run * v / p["Ax"]
    ode[L.state["vh"]] = -run * F / p["Av"]
    ode[L.state["Fh"]] = run * s * v * (1.0 - sat) / p["AF"]
    zero = [ca.if_else(moving, s * st["vh"], 1.0)]
    if spec.saturates:
        zero.append(ca.if_else(moving * (1.0 - sat) > 0.5, 1.0 - (1.0 - g) * pp, 1.0))
    dae = {"x": X, "p": P, "u": U, "t": tau, "ode": ode, "zero": ca.vertcat(*zero)}
    idx = ca.SX.sym("index")
    post = ca.SX(X)
    post[L.state["vh"]] = -s * (1.0 + tau)
    if spec.saturates:
        post_sat = ca.SX(X)
        post_sat[L.state["sat"]] = 1.0
        post_sat[L.state["Fh"]] = 1.0 / ((1.0 - g) * p["AF"])
        post = ca.if_else(idx == 0, post, post_sat)
    trans = ca.Function(
        "transition", [idx, tau, X, ca.SX(0, 1), P, U], [post, ca.SX(0, 1)],
        ca.event_in(), ca.event_out(),
    )
    opts = _options(spec, trans, tol, atol)
    with _without_event_notice():
        return ca.integrator(f"dahl_{spec.method}_stop", spec.method, dae, 0.0, [1.0], opts)


def _options(spec: PlantSpec, trans: ca.Function, tol: float, atol: float) -> dict:
    """Integrator options: events to round-off, tolerances, first step of a single-output call."""
    opts = {
        "transition": trans,
        "max_events": spec.n_out * (4 * spec.K + 16),
        # events to round-off (defaults 1e-6 and 3 are far too loose: tau spans a whole call)
        "event_tol": 1e-15,
        "max_event_iter": 40,
        "reltol": tol,
        "abstol": atol,
        "max_num_steps": 200000,
    }
    if spec.n_out == 1:
        # A call covers about K + 1 half-cycles (the compact model: 2; see the integration
        # loop): a first step of about 1/60 of it at tol ~ 4e-10, scaled like an order-5 step,
        # spares the ramp-up from the default estimate (about 13 % of all steps with K = 2).
        opts["step0"] = min(0.03, max(1e-4, 0.015 * (tol / 3.7e-10) ** 0.2))
    return opts


_EVENT_NOTICE = b'WARNING("Event support is experimental")'


@contextlib.contextmanager
def _without_event_notice() -> Iterator[None]:
    """Drop CasADi's "Event support is experimental" line from stderr; pass every other line on.

    CasADi writes the notice from C++ straight to file descriptor 2 each time an integrator
    with events is built, which clutters progress output. The events are tested here
    (tests/test_simulate*.py), so the notice carries no information for our users.
    """
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as capture:
        os.dup2(capture.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            capture.seek(0)
            kept = [line for line in capture.read().splitlines(keepends=True) if _EVENT_NOTICE not in line]
            if kept:
                os.write(2, b"".join(kept))
