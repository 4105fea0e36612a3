"""CasADi plant of the oscillator (2.1) with any friction model: reversal, model and rest events.

One plant is built (and compiled) per structure (:class:`PlantSpec`): the model's class and
event set, forced or not, dense output or not, the controller's order and the kinds of the
input and reference signals. Every number is a run-time input: the model's numbers ``q``, the
signals' numbers, controller matrices and the tolerance ``eps`` (``docs/simulator.md``).

The integrated state is normalised (``docs/mathematics.md``, normalised units) and, per call,
scaled by the amplitude of the motion times ``eps``, so that the integrator's absolute error
control (``abstol = 1``, ``reltol = 0``) is relative to the current motion at the tolerance of
the run. Time inside one call is ``tau`` in ``[0, n_out]``; the control ``dur`` of each output
interval (one unit of ``tau``) is its duration in normalised time, so one compiled Function
serves any output grid.

State vector (indices in :class:`Layout`), kept short because the cost of a step grows with it:

``xh, vh``
    ``x~ = xref + Ax xh``, ``v~ = Av vh``;
``z0 ...``
    the model's continuous states, ``z = AF zh``;
``s, n``
    branch direction (+-1) and reversals so far; the call stops (right-hand side zero) once
    ``n`` reaches the parameter ``nstop``;
``m0 ...``
    the model's flags (e.g. Dahl's saturation for gamma < 1);
``rest, Wh, armed, tmiss``
    (forced systems only) rest flag (``v = 0`` and ``u = F``), the input work since the last
    reversal, ``W~ = AE Wh``, the flag of the least-speed event and ``1 + t~`` of a skipped
    reversal pair (0 if none; see below);
``Eh``
    work of the friction force since t = 0, ``E_f~ = Efref + AE Eh`` (dense output only), (2.8);
``ne, nr0 ...``
    (models with events only) the model events since the last reversal, each counted as the
    number of flags it changes (:func:`event_count`), and the counts of the newest ``K``
    half-cycles, shifted in by each reversal as the register is;
``Ebh``
    (models with events and a branch potential) the branch's mechanical energy
    ``v~^2 / 2 + potential - W~``, ``AE`` times it; the model events set the speed from it
    when the parameter ``ecorr`` is 1 (the compact model has it as the parameter ``Eb``);
``xch``
    continuous controller states, ``xc = S * xch``; the controller's force is
    ``clip(C xc + D e, -umax, umax)`` with back-calculation ``k_aw (u - w)`` on ``xc'``
    (run-time ``umax``, ``k_aw``; ``umax = 1e300`` and ``k_aw = 0`` give the linear law);
register
    the newest ``K`` reversals, newest first: ``(t~, x~, F~[, W~])`` each.

Normalised time is ``t~ = t0 + dur * tau`` with the integrator time ``tau`` and the controls
``t0``, ``dur`` of the output interval.

Events (the integrator fires when an indicator goes from positive to negative):

- reversal, indicator ``s v / A`` (forced: ``+ EPS_START``). Unforced: always a reversal
  (register shift, ``s -> -s``, the model's :meth:`~prefriction.FrictionModel.reverse`).
  Forced: the net force ``a~ = u~ - F~`` decides: ``s a~ < -eps``: a reversal;
  ``s a~ > eps``: the velocity touches zero and keeps its sign (nothing changes); otherwise
  the mass rests (``v = 0``, right-hand side zero).
- the model's in-branch events (Dahl with gamma < 1: saturation), with its transitions.
- end of rest (forced only), indicator ``eps_rest - |a~|``: the mass moves again in direction
  ``sign(a~)``, a reversal if that differs from ``s``.
- least speed (forced only, while ``armed``), indicator ``-s a~``: the speed ``s v`` has a
  local minimum. If ``s v < 0`` there, the velocity changed sign twice inside one step (a
  reversal pair that the reversal indicator, checked at the ends of the steps only, skipped):
  ``tmiss = 1 + t~`` and the right-hand side stops; the loop integrates the call again up to that
  time, so that a step ends where ``s v < 0`` and the first reversal is located
  (:meth:`Run.advance`). The event clears ``armed``; the next greatest speed (indicator
  ``s a~`` while not armed) and every reversal set it again, so neither event fires twice at the
  same instant.

``eps`` and ``eps_rest`` are :data:`EPS_TOUCH` and :data:`EPS_REST` times the amplitude scale.

Compact model (``PlantSpec.compact``, unforced without dense output): states ``vh, z...``
(with ``xh`` unless the model tracks the position, e.g. Dahl with gamma >= 1 where
``x - x_start = s (p - p_start)``) and the flags (the loop counts the events by the flags a call
set), the direction ``s`` a parameter; the call
stops at the first reversal (its transition sets ``vh eps = -s (1 + tau)``: the stop flag and the
time of the reversal in one state) and the caller starts the next branch. A step costs about a
third less than with the register of two reversals (2 states instead of 11).
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from dataclasses import dataclass, field
from typing import Any, Callable, Hashable, Iterator

import casadi as ca

from prefriction.models.base import FrictionModel

__all__ = ["EPS_CAL", "EPS_DIED", "EPS_TOUCH", "EPS_REST", "Layout", "PlantSpec", "build_integrator"]

EPS_TOUCH = 1.0
"""Net force, in units of the call's velocity scale ``Av = eps A`` (the tolerance times the
amplitude: the integrator's error level of the net force), below which a zero velocity is rest."""
EPS_CAL = 0.1
"""Calibration of the run-time tolerance: ``eps = rtol * EPS_CAL * sqrt(active / all states)``
(:func:`prefriction.simulate`; the global error over 50 reversals is then about ``0.7 rtol``)."""
EPS_REST = 3.0
"""Net force, in units of ``Av = eps A``, above which a resting mass moves again (a hysteresis
above :data:`EPS_TOUCH`, so that a mass just put to rest does not leave at once)."""
EPS_START = 1e-13
"""Offset of the forced reversal indicator ``s v / Av + EPS_START``: a branch that starts at
``v = 0`` starts with a positive indicator, so a velocity that turns against ``s`` before it
has grown (the net force reverses within the first step) still fires the reversal event."""
EPS_DIED = 10.0
"""Unforced runs: a reversal whose force is below ``EPS_DIED eps Fmax`` (``Fmax`` the largest force
on its branch) is the creep of a mass to rest crossing ``v = 0`` at the level of the
integration error, not a reversal: the run ends at rest (``docs/simulator.md#native``)."""


@dataclass(frozen=True)
class PlantSpec:
    """Structure of the integrated plant: everything that changes the generated code, and
    nothing else (numbers are run-time inputs, ``docs/simulator.md``).

    ``model``, ``u_sig`` and ``r_sig`` are instances that give the structure; they do not take
    part in equality or hashing (their keys do), so one plant serves every instance of a
    structure.
    """

    model: FrictionModel = field(compare=False)
    model_key: Hashable
    u_sig: Any = field(default=None, compare=False)
    u_key: Hashable = None
    fb: str = "none"
    n_c: int = 0
    r_sig: Any = field(default=None, compare=False)
    r_key: Hashable = None
    energy: bool = False
    K: int = 4
    n_out: int = 1
    method: str = "erk"
    compact: bool = False
    """Use the compact model (:func:`build_integrator`) where it applies: unforced, no dense output."""

    @classmethod
    def of(cls, model: FrictionModel, u_sig: Any = None, r_sig: Any = None, **kw: Any) -> "PlantSpec":
        """The spec of ``model`` with input ``u_sig`` and reference ``r_sig`` (keys filled in)."""
        from prefriction.signals import compiled_form

        key = (type(model).__module__, type(model).__qualname__, model.structure_key())
        u_sig, r_sig = compiled_form(u_sig), compiled_form(r_sig)
        return cls(model=model, model_key=key, u_sig=u_sig,
                   u_key=None if u_sig is None else u_sig.key, r_sig=r_sig,
                   r_key=None if r_sig is None else r_sig.key, **kw)

    @property
    def forced(self) -> bool:
        """True if any force besides friction acts (input or feedback)."""
        return self.u_sig is not None or self.fb != "none"

    @property
    def stops_at_reversal(self) -> bool:
        """True for the compact unforced model (:func:`build_integrator`, ``compact=True``)."""
        return self.compact and not self.forced and not self.energy and self.n_out == 1

    @property
    def n_q(self) -> int:
        """Number of the model's run-time numbers."""
        return len(self.model.runtime_params())


def _sizes(sig: Any) -> tuple[int, int]:
    return (0, 0) if sig is None else (sig.n_params, sig.n_piece)


class Layout:
    """Index map of the state, parameter and control vectors for a :class:`PlantSpec`."""

    def __init__(self, spec: PlantSpec) -> None:
        model = spec.model
        self.nz, self.nm = model.n_states, model.n_flags
        if spec.stops_at_reversal:
            self._compact(spec)
            return
        names = ["xh", "vh"] + [f"z{i}" for i in range(self.nz)] + ["s", "n"]
        names += [f"m{i}" for i in range(self.nm)]
        if spec.forced:
            names += ["rest", "Wh", "armed", "tmiss"]
        if spec.energy:
            names.append("Eh")
        if model.n_events:  # model events since the last reversal, and in the newest K half-cycles
            names += ["ne"] + [f"nr{j}" for j in range(spec.K)]
        self.potential = has_potential(model)
        if self.potential:  # the branch's mechanical energy (speed at events, FrictionModel.branch_potential)
            names.append("Ebh")
        if spec.fb == "continuous":
            names.append("sat")  # clip of the controller force: 0 inside, +-1 at +-umax
        self.state = {k: i for i, k in enumerate(names)}
        self.xc = slice(len(names), len(names) + spec.n_c)
        self.reg = len(names) + spec.n_c
        self.reg_width = 4 if spec.forced else 3
        self.nx = self.reg + spec.K * self.reg_width
        self.n_active = 2 + self.nz + int(spec.forced) + int(spec.energy) + spec.n_c
        pnames = ["Ax", "Av", "AF", "AE", "xref", "Efref", "nstop", "snap", "tunit", "xunit", "Fc", "eps"]
        if self.potential:
            pnames.append("ecorr")  # 1: the speed at model events from the energy (0: as integrated)
        self.param = {k: i for i, k in enumerate(pnames)}
        self.q = self._block(len(pnames), spec.n_q)
        (nu_p, nu_c), (nr_p, nr_c) = _sizes(spec.u_sig), _sizes(spec.r_sig)
        self.up = self._block(self.q.stop, nu_p)
        self.rp = self._block(self.up.stop, nr_p)
        n = spec.n_c
        self.p_A = self.rp.stop
        self.p_B = self.p_A + n * n
        self.p_C = self.p_B + n
        self.p_D = self.p_C + n
        cont = 1 if spec.fb == "continuous" else 0
        self.p_S = self.p_D + cont
        self.p_umax = self.p_S + n  # force limit / Fc (1e300: none), then the anti-windup gains
        self.p_kaw = self.p_umax + cont
        self.np = self.p_kaw + cont * n
        cnames = ["dur", "t0"]
        if spec.fb == "sampled":
            cnames.append("uhold")
        self.control = {k: i for i, k in enumerate(cnames)}
        self.uc = self._block(len(cnames), nu_c)
        self.rc = self._block(self.uc.stop, nr_c)
        self.nu = self.rc.stop

    @staticmethod
    def _block(start: int, size: int) -> slice:
        return slice(start, start + size)

    def _compact(self, spec: PlantSpec) -> None:
        """Layout of the compact unforced model: ``[xh,] vh, z..., m...`` (no ``xh`` if the model
        tracks the position), parameters ``Ax, Av, AF, s, eps[, Eb], q...``, controls ``dur, t0``."""
        self.potential = has_potential(spec.model)
        names = [] if spec.model.tracks_position else ["xh"]
        names += ["vh"] + [f"z{i}" for i in range(self.nz)] + [f"m{i}" for i in range(self.nm)]
        self.state = {k: i for i, k in enumerate(names)}
        self.xc = slice(len(names), len(names))
        self.reg = self.nx = len(names)
        self.reg_width = 0
        self.n_active = len(names) - self.nm
        # Eb: the branch's mechanical energy v^2 / 2 + potential (speed at model events)
        self.param = {k: i for i, k in enumerate(["Ax", "Av", "AF", "s", "eps"] + (["Eb"] if self.potential else []))}
        self.q = self._block(len(self.param), spec.n_q)
        self.up = self.rp = self._block(self.q.stop, 0)
        self.p_A = self.p_B = self.p_C = self.p_D = self.p_S = self.p_umax = self.p_kaw = self.np = self.q.stop
        self.control = {"dur": 0, "t0": 1}
        self.uc = self.rc = self._block(2, 0)
        self.nu = 2


def trace_signal(fun: Callable[[Any], Any], what: str) -> ca.SX:
    """Evaluate ``fun`` on a CasADi symbol; ``TypeError`` with advice if it cannot be traced."""
    from prefriction.signals import Traced

    return ca.SX(Traced(fun, name=what).expr(ca.SX.sym("t"), ()))


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


def has_potential(model: FrictionModel) -> bool:
    """True if the model has events and a branch potential (:meth:`FrictionModel.branch_potential`)."""
    return bool(model.n_events) and type(model).branch_potential is not FrictionModel.branch_potential


def event_count(m: list, mn: list) -> Any:
    """What one model event adds to the event count: the number of flags it changes (an element
    that starts to slip, Dahl's saturation; ties count each element), at least 1."""
    changed = 0.0
    for old, new in zip(m, mn):
        changed = changed + ca.fabs(new - old)
    return ca.fmax(changed, 1.0)


def _model_state(L: Layout, st: dict, AF: Any) -> tuple[list, list]:
    """Model state ``(z, m)`` from the scaled plant state (``z = AF zh``)."""
    return [AF * st[f"z{i}"] for i in range(L.nz)], [st[f"m{i}"] for i in range(L.nm)]


def build_integrator(spec: PlantSpec) -> ca.Function:
    """CasADi integrator (``spec.method``) over ``spec.n_out`` output intervals, with events
    (the compact model of the module notes if ``spec.stops_at_reversal``).

    The error control is absolute on states scaled by the amplitude times the run-time
    tolerance ``eps`` (parameter): ``reltol = 0``, ``abstol = 1``, so one compiled plant serves
    every tolerance.
    """
    if spec.stops_at_reversal:
        return _build_compact(spec)
    L, X, P, U, tau, st, p, c = _symbols(spec)
    model, n = spec.model, spec.n_c
    q = P[L.q]
    x = p["xref"] + p["Ax"] * st["xh"]
    v = p["Av"] * st["vh"]
    s = st["s"]
    rest = st["rest"] if spec.forced else 0.0
    z, m = _model_state(L, st, p["AF"])
    F = model.force(z, m, v, s, q)
    t_n = c["t0"] + c["dur"] * tau  # normalised time
    t_si = t_n * p["tunit"]
    u = spec.u_sig.expr(t_si, P[L.up], U[L.uc]) / p["Fc"] if spec.u_sig is not None else 0.0
    xc = ca.SX(0, 1)
    if spec.fb != "none":
        if spec.fb == "continuous":
            r = spec.r_sig.expr(t_si, P[L.rp], U[L.rc]) / p["xunit"] if spec.r_sig is not None else 0.0
            e = r - x
            A = ca.reshape(P[L.p_A:L.p_B], n, n)
            B = P[L.p_B:L.p_C]
            C = ca.reshape(P[L.p_C:L.p_D], 1, n)
            S = P[L.p_S:L.p_umax]
            xc = S * X[L.xc]
            w = (ca.mtimes(C, xc) if n else 0.0) + P[L.p_D] * e  # unclipped controller output
            umax, sat = P[L.p_umax], st["sat"]
            u_fb = ca.if_else(ca.fabs(sat) < 0.5, w, sat * umax)  # force limit: the clip's mode is a state
            u = u + u_fb
        else:
            u = u + c["uhold"] / p["Fc"]
    acc = u - F
    run = ca.if_else(st["n"] < p["nstop"], 1.0, 0.0)  # stop after the nstop-th reversal
    if spec.forced:  # at rest, or stopped after a skipped reversal pair
        run = run * ca.if_else(st["tmiss"] > 0.5, 0.0, 1.0)
    run_m = run * (1.0 - rest) if spec.forced else run
    dz = model.rate(z, m, v, s, q)
    dot = {"xh": run_m * v / p["Ax"], "vh": run_m * acc / p["Av"]}
    for i in range(L.nz):
        dot[f"z{i}"] = run_m * dz[i] / p["AF"]
    if spec.forced:
        dot["Wh"] = run_m * u * v / p["AE"]
    if spec.energy:
        dot["Eh"] = run_m * F * v / p["AE"]
    ode = ca.SX.zeros(L.nx)
    for k, val in dot.items():
        ode[L.state[k]] = val
    if spec.fb == "continuous" and n:
        # back-calculation anti-windup: k_aw (u - w) (zero while the limit does not bind)
        ode[L.xc] = run * (ca.mtimes(A, xc) + B * e + P[L.p_kaw:L.np] * (u_fb - w)) / S
    ode = c["dur"] * ode
    # indicators in units of the amplitude (vh is scaled by 1/eps); forced: offset so that a
    # branch starting at v = 0 has a positive indicator (EPS_START)
    zero = [ca.if_else(run_m > 0.5, s * st["vh"] * p["eps"] + (EPS_START if spec.forced else 0.0), 1.0)]
    zero += [ca.if_else(run_m > 0.5, ind, 1.0) for ind in model.events(z, m, v, s, q)]
    if spec.forced:  # rest thresholds at the error level of the net force: eps times the amplitude
        zero.append(ca.if_else(run * rest > 0.5, EPS_REST * p["Av"] - ca.fabs(acc), 1.0))
        armed = st["armed"] > 0.5
        sa_n = s * acc / p["Av"] * p["eps"]  # s a~ relative to the amplitude
        zero.append(ca.if_else(ca.logic_and(run_m > 0.5, armed), -sa_n, 1.0))  # least speed
        zero.append(ca.if_else(ca.logic_and(run_m > 0.5, ca.logic_not(armed)), sa_n, 1.0))  # greatest
    if spec.fb == "continuous":  # the clip's switches (w = +-umax), relative to umax
        inside = ca.fabs(sat) < 0.5
        zero.append(ca.if_else(run > 0.5, ca.if_else(inside, 1.0 - w / umax, ca.if_else(sat > 0.5, w / umax - 1.0, 1.0)), 1.0))
        zero.append(ca.if_else(run > 0.5, ca.if_else(inside, 1.0 + w / umax, ca.if_else(sat < -0.5, -1.0 - w / umax, 1.0)), 1.0))
    dae = {"x": X, "p": P, "u": U, "t": tau, "ode": ode, "zero": ca.vertcat(*zero)}

    # transition: the state just after an event
    idx = ca.SX.sym("index")
    reg = X[L.reg:]
    W = p["AE"] * st["Wh"] if spec.forced else None

    def with_(changes: dict, base: ca.SX = X) -> ca.SX:
        out = ca.SX(base)
        for k, val in changes.items():
            if k == "reg":
                out[L.reg:] = val
            else:
                out[L.state[k]] = val
        return out

    def model_changes(zn: list, mn: list) -> dict:
        ch = {f"z{i}": zn[i] / p["AF"] for i in range(L.nz)}
        ch.update({f"m{i}": mn[i] for i in range(L.nm)})
        return ch

    def event_changes(k: Any) -> dict:
        zn, mn = model_event(model, k, z, m, s, q)
        ch = model_changes(zn, mn)
        ch["ne"] = st["ne"] + event_count(m, mn)
        if L.potential:  # v^2 / 2 + potential - W conserved up to the event
            kinetic = p["AE"] * st["Ebh"] + (W if spec.forced else 0.0) - model.branch_potential(zn, m, s, q)
            vh = s * ca.sqrt(ca.fmax(2.0 * kinetic, 0.0)) / p["Av"]
            ch["vh"] = ca.if_else(p["ecorr"] > 0.5, vh, st["vh"])
        return ch

    def reversal(new_s: Any, extra: dict) -> ca.SX:
        zn, mn = model.reverse(z, m, new_s, q, p["snap"])
        # the register records the force after the model's reset (an event within snap of the
        # reversal coincides with it), as the unforced loop does
        entry = [t_n, x, model.force(zn, mn, 0.0, new_s, q)] + ([W] if spec.forced else [])
        ch = {"reg": ca.vertcat(*entry, reg[: -L.reg_width]), "n": st["n"] + 1, "s": new_s}
        ch.update(model_changes(zn, mn))
        if spec.forced:
            ch["Wh"] = 0.0
            ch["armed"] = 1.0
        if L.potential:  # at rest on the new branch, no work yet
            ch["Ebh"] = model.branch_potential(zn, mn, new_s, q) / p["AE"]
        if model.n_events:  # the half-cycle's event count enters the count register
            ch["ne"] = 0.0
            for j in range(spec.K - 1, 0, -1):
                ch[f"nr{j}"] = st[f"nr{j - 1}"]
            ch["nr0"] = st["ne"]
        ch.update(extra)
        return with_(ch)

    sa = s * acc
    if spec.forced:  # zero velocity: reversal, touch (velocity keeps its sign) or rest
        eps = EPS_TOUCH * p["Av"]
        posts = [ca.if_else(sa < -eps, reversal(-s, {}),
                            ca.if_else(sa > eps, X, with_({"rest": 1.0, "vh": 0.0})))]
    else:
        posts = [reversal(-s, {})]
    model_posts = [with_(event_changes(k)) for k in _event_indices(model, idx - 1.0)]
    if spec.forced:
        new_dir = ca.if_else(acc > 0, 1.0, -1.0)
        posts.append(ca.if_else(new_dir != s, reversal(new_dir, {"rest": 0.0}), with_({"rest": 0.0})))
        posts.append(ca.if_else(s * st["vh"] < 0.0, with_({"tmiss": 1.0 + t_n, "armed": 0.0}), with_({"armed": 0.0})))
        posts.append(with_({"armed": 1.0}))
    if spec.fb == "continuous":  # enter or leave the upper, then the lower limit
        posts.append(with_({"sat": ca.if_else(ca.fabs(st["sat"]) < 0.5, 1.0, 0.0)}))
        posts.append(with_({"sat": ca.if_else(ca.fabs(st["sat"]) < 0.5, -1.0, 0.0)}))
    post = _select(idx, posts[:1], model_posts, model.n_events, posts[1:])
    trans = ca.Function(
        "transition", [idx, tau, X, ca.SX(0, 1), P, U], [post, ca.SX(0, 1)],
        ca.event_in(), ca.event_out(),
    )
    opts = _options(spec, trans)
    grid = [float(j) for j in range(1, spec.n_out + 1)]
    with _without_event_notice():
        return ca.integrator(f"{_name(spec)}_{spec.n_out}", spec.method, dae, 0.0, grid, opts)


def _name(spec: PlantSpec) -> str:
    """A readable name of the plant (model class, forced or not)."""
    forced = "forced" if spec.forced else "free"
    return f"{type(spec.model).__name__.lower()}_{forced}_{spec.method}"


def _build_compact(spec: PlantSpec) -> ca.Function:
    """The unforced oscillator up to its next reversal, with as few states as possible.

    States ``vh, z...`` (with ``xh`` unless the model tracks the position, and the model's
    flags); the direction ``s`` is a parameter. Before the reversal ``s vh > 0``; the
    transition of the reversal sets ``vh eps = -s (1 + tau)`` (the velocity there is zero; ``tau``
    in [0, 1] is the integrator time of the reversal), which also stops the right-hand side:
    the state at the end of the call is the state at the reversal, and the caller starts the
    next branch. The cost of a step grows with the number of states: 2 for Dahl with
    gamma >= 1 against 11 with a register of two reversals.
    """
    L, X, P, U, tau, st, p, _ = _symbols(spec)
    model, s, q = spec.model, p["s"], P[L.q]
    z, m = _model_state(L, st, p["AF"])
    v = p["Av"] * st["vh"]
    F = model.force(z, m, v, s, q)
    moving = s * st["vh"] * p["eps"] > -0.5  # no reversal yet in this call (vh ~ 1/eps)
    run = ca.if_else(moving, U[0], 0.0)  # dur while no reversal came, then 0
    ode = ca.SX.zeros(L.nx)
    if "xh" in L.state:
        ode[L.state["xh"]] = run * v / p["Ax"]
    ode[L.state["vh"]] = -run * F / p["Av"]
    for i, dz in enumerate(model.rate(z, m, v, s, q)):
        ode[L.state[f"z{i}"]] = run * dz / p["AF"]
    zero = [ca.if_else(moving, s * st["vh"] * p["eps"], 1.0)]
    zero += [ca.if_else(moving, ind, 1.0) for ind in model.events(z, m, v, s, q)]
    dae = {"x": X, "p": P, "u": U, "t": tau, "ode": ode, "zero": ca.vertcat(*zero)}
    idx = ca.SX.sym("index")
    post = ca.SX(X)
    post[L.state["vh"]] = -s * (1.0 + tau) / p["eps"]
    model_posts = []
    for k in _event_indices(model, idx - 1.0):
        zn, mn = model_event(model, k, z, m, s, q)
        after = ca.SX(X)
        for i in range(L.nz):
            after[L.state[f"z{i}"]] = zn[i] / p["AF"]
        for i in range(L.nm):
            after[L.state[f"m{i}"]] = mn[i]
        if L.potential:  # v^2 / 2 + potential conserved up to the event
            kinetic = p["Eb"] - model.branch_potential(zn, m, s, q)
            after[L.state["vh"]] = s * ca.sqrt(ca.fmax(2.0 * kinetic, 0.0)) / p["Av"]
        model_posts.append(after)
    post = _select(idx, [post], model_posts, model.n_events, [])
    trans = ca.Function(
        "transition", [idx, tau, X, ca.SX(0, 1), P, U], [post, ca.SX(0, 1)],
        ca.event_in(), ca.event_out(),
    )
    opts = _options(spec, trans)
    with _without_event_notice():
        return ca.integrator(f"{_name(spec)}_stop", spec.method, dae, 0.0, [1.0], opts)


def _event_indices(model: FrictionModel, k: Any) -> list:
    """The model events' indices for the transition: ``0 ... n_events - 1``, one expression
    each; or, if the model has ``on_event_at`` (a symbolic event index, e.g. Maxwell-slip and
    GMS), the one symbolic index ``k``, so that the transition is one piece of size
    proportional to the number of events, not to its square."""
    if not model.n_events:
        return []
    return [k] if callable(getattr(model, "on_event_at", None)) else list(range(model.n_events))


def model_event(model: FrictionModel, k: Any, z: list, m: list, s: Any, q: Any) -> tuple[list, list]:
    """The model's state after its event ``k``: ``on_event`` for an integer ``k``, ``on_event_at``
    for a symbolic one (:func:`_event_indices`)."""
    return model.on_event(k, z, m, s, q) if isinstance(k, int) else model.on_event_at(k, z, m, s, q)


def _select(idx: Any, before: list, model_posts: list, n_events: int, after: list) -> Any:
    """The state after the event ``idx`` of the transition: ``before[i]`` for ``idx = i``, then the
    model's ``n_events`` events (one post each, or one post for all of them, see
    :func:`_event_indices`), then ``after``; the last candidate for any larger ``idx``."""
    b = len(before)
    if len(model_posts) == n_events:  # one post per event (or no model events)
        posts = before + model_posts + after
        post = posts[-1]
        for k in range(len(posts) - 2, -1, -1):
            post = ca.if_else(idx == k, posts[k], post)
        return post
    post = model_posts[0]  # one post for every model event
    if after:
        tail = after[-1]
        for k in range(len(after) - 2, -1, -1):
            tail = ca.if_else(idx == b + n_events + k, after[k], tail)
        post = ca.if_else(idx < b + n_events, post, tail)
    for k in range(b - 1, -1, -1):
        post = ca.if_else(idx == k, before[k], post)
    return post


def _options(spec: PlantSpec, trans: ca.Function) -> dict:
    """Integrator options: events to round-off, tolerance (run-time, see :func:`build_integrator`),
    first step of a single-output call."""
    opts = {
        "transition": trans,
        "max_events": spec.n_out * (4 * spec.K + 16 + (spec.K + 1) * spec.model.n_events),
        # events to round-off (defaults 1e-6 and 3 are far too loose: tau spans a whole call)
        "event_tol": 1e-15,
        "max_event_iter": 40,
        "reltol": 0.0,
        "abstol": 1.0,
        "max_num_steps": 200000,
    }
    if spec.n_out == 1 and spec.model.rate_independent:
        # A call covers about K + 1 half-cycles (the compact model: 2; see the integration
        # loop): a first step of about 1/60 of it (right for rtol ~ 1e-8) spares the ramp-up
        # from the default estimate (about 13 % of all steps with K = 2). Not for rate-dependent
        # models: a Stribeck curve narrower than that step (LuGre, vs = 1e-5 m/s) is crossed
        # just after each reversal, and a first step that spans it can pass the error test
        # (296 rtol at rtol 1e-8); the estimate from the right-hand side at the start sees it.
        opts["step0"] = 0.015
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
