"""The implicit path of an unforced run: branches too stiff for the explicit Runge-Kutta method.

The native driver (``native/driver.c``) tests every step for stiffness (Hairer and Wanner's test
of ``h |lambda|`` from the two stages at the step's end) and stops with ``PF_STIFF`` when a
branch has taken more than 20,000 steps and the last 15 of them were held by the method's
stability rather than its accuracy: GMS with a stiff slip law (``C = 1e7`` N/s) took 0.66 M
steps for 6 reversals. :func:`advance_stiff` then continues the run with scipy's Radau IIA
(order 5, L-stable) on the same normalised oscillator, written from the model's protocol
methods with CasADi (right-hand side, exact Jacobian, indicators), each reversal and model
event located on Radau's dense output to round-off and the model's transitions applied there
(``docs/simulator.md#stiff``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from prefriction.simulation.plant import EPS_DIED, event_count

if TYPE_CHECKING:
    from prefriction.models.base import FrictionModel
    from prefriction.simulation.run_state import RunState

__all__ = ["StiffFunctions", "advance_stiff", "stiff_functions"]

_BAND = 3.0  # half-width of the band around v = 0 stepped finely, in velocity scales (driver.c: PF_CURVE_K)
_DIED = 1e-250  # normalised amplitude below which the motion has died out (driver.c)
_MIN_RTOL = 1e-13  # Radau's tolerance floor (scipy lifts anything below 100 x machine epsilon)
_FUNCTIONS: dict = {}


class StiffFunctions:
    """CasADi Functions of the normalised unforced oscillator ``y = (x~, v~, z...)`` of one model
    structure: the exact Jacobian ``jac(y, m, s, q)`` of the right-hand side in ``y`` (the right-hand side
    and the indicators themselves are evaluated on floats, through the model's methods)."""

    def __init__(self, model: "FrictionModel") -> None:
        nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
        y, m, s, q = ca.SX.sym("y", 2 + nz), ca.SX.sym("m", nm), ca.SX.sym("s"), ca.SX.sym("q", nq)
        z, mm = [y[2 + i] for i in range(nz)], [m[i] for i in range(nm)]
        F = model.force(z, mm, y[1], s, q)
        rhs = ca.vertcat(y[1], -F, *model.rate(z, mm, y[1], s, q))
        self.jac = ca.Function("stiff_jac", [y, m, s, q], [ca.jacobian(rhs, y)])
        self.n_events = model.n_events


def stiff_functions(model: "FrictionModel") -> StiffFunctions:
    """The :class:`StiffFunctions` of ``model``'s structure (built once per process)."""
    key = (type(model).__module__, type(model).__qualname__, model.structure_key())
    if key not in _FUNCTIONS:
        _FUNCTIONS[key] = StiffFunctions(model)
    return _FUNCTIONS[key]


def _scales(y: np.ndarray, F: float, eps: float, travel: bool) -> np.ndarray:
    """Absolute tolerances from the amplitude ``A = hypot(v~, F~)``, as the native driver's
    ``pf_scale``: position ``max(A, A^2/2, min(|x~|, 1))``, velocity ``A``, model states
    ``min(A, 1)`` (``max(min(A, 1), |z|)`` for states that carry the ``travel``), all times
    ``eps``."""
    A = max(math.hypot(y[1], F), 1e-300)
    out = np.empty(y.size)
    out[0] = max(A, 0.5 * A * A, min(abs(y[0]), 1.0))
    out[1] = A
    out[2:] = np.maximum(min(A, 1.0), np.abs(y[2:])) if travel else min(A, 1.0)
    return out * eps


def _rhs(model: "FrictionModel", y: np.ndarray, m: list, s: float, q: list) -> list[float]:
    """``(v~, -F~, z')`` of the normalised unforced oscillator, on floats."""
    z, v = y[2:].tolist(), float(y[1])
    return [v, -float(model.force(z, m, v, s, q)), *(float(r) for r in model.rate(z, m, v, s, q))]


def _event(fun: Callable[[float, np.ndarray], float]) -> Callable[[float, np.ndarray], float]:
    """``fun`` as a terminal scipy event that fires where it falls through zero."""
    fun.terminal, fun.direction = True, -1.0  # type: ignore[attr-defined]
    return fun


def advance_stiff(run: "RunState", t_target: float, n_target: float) -> bool:
    """Continue ``run`` (the state of a :class:`~prefriction.simulation.run.Run`: ``run.st``, normalised) with Radau to the normalised time
    ``t_target`` or ``n_target`` reversals (True if the latter), appending reversals and their
    half-cycles' event counts as the native driver does."""
    model, st = run.model, run.st
    fn = stiff_functions(model)
    ql, qd = run.q.tolist(), ca.DM(run.q)
    y = np.array([st["x"], st["v"], *st["z"]], dtype=float)
    m, s, t, ne = list(st["m"]), float(st["s"]), float(st["t"]), int(st.get("ne", 0))
    rtol = max(run.eps, _MIN_RTOL)
    F_max = abs(st["F"])  # the largest |F~| on the branch (a reversal below the error level is rest)
    vs = model.velocity_scale(ql)
    inside = vs is not None and s * y[1] <= _BAND * vs  # the phase: inside the band (toggled by its events)
    steps = 0
    while len(run.rev) < n_target and t < t_target:
        md = ca.DM(m)
        rhs = lambda _t, yy, m=m, s=s: _rhs(model, yy, m, s, ql)  # floats: a CasADi call costs ~0.2 ms
        jac = lambda _t, yy, md=md, s=s: np.asarray(fn.jac(yy, md, s, qd))
        events: list[Any] = [_event(lambda _t, yy, s=s: s * yy[1])]
        for k in range(fn.n_events):
            events.append(_event(lambda _t, yy, k=k, m=m, s=s: float(model.events(yy[2:].tolist(), m, yy[1], s, ql)[k])))
        F = float(model.force(y[2:].tolist(), m, float(y[1]), s, ql))
        n_model = len(events)
        # the motion has died out below the double range (the driver's amplitude test)
        events.append(_event(lambda _t, yy, m=m, s=s: math.hypot(yy[1], float(model.force(
            yy[2:].tolist(), m, float(yy[1]), s, ql))) - _DIED))
        max_step = math.inf
        if vs is not None:  # a narrow Stribeck curve: the band |v~| < 3 vs~ in steps of vs~/4 at most
            if not inside:  # outside: stop at the band's edge
                events.append(_event(lambda _t, yy, s=s: s * yy[1] - _BAND * vs))
            else:  # inside: stop on leaving it
                events.append(_event(lambda _t, yy, s=s: _BAND * vs - s * yy[1]))
                max_step = 0.25 * vs / max(abs(F), 1e-300)
        atol = _scales(y, F, rtol, model.tracks_position)
        sol = solve_ivp(rhs, (t, min(t_target, 1e300)), y, method="Radau", jac=jac, rtol=rtol, atol=atol,
                        events=events, max_step=max_step)
        steps += int(sol.t.size - 1)
        if sol.status < 0:
            raise run._failure(f"the implicit Radau method failed ({sol.message})")
        F_max = max(F_max, max(abs(float(model.force(col[2:].tolist(), m, col[1], s, ql))) for col in sol.y.T))
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        k_ev = min((te[0], k) for k, te in enumerate(sol.t_events) if te.size)[1] if sol.status == 1 else -1
        if k_ev == n_model or (sol.status == 0 and not math.isfinite(t_target)):  # died out: at rest
            if not math.isfinite(t_target):
                st.update(t=t, x=float(y[0]), v=0.0, F=0.0)
                raise run._failure("its amplitude fell below 1e-250 normalised units (on the implicit method)")
            t, y[1] = t_target, 0.0
            break
        if sol.status == 0:  # reached t_target
            break
        z = y[2:].tolist()
        if k_ev > n_model:  # the edge of the Stribeck band: the next phase
            inside = not inside
            continue
        if k_ev == 0:  # a reversal: the force after the model's reset, the next branch
            y[1] = 0.0
            zr, mr = model.reverse(z, m, -s, ql, run.snap)
            F = float(model.force(list(zr), list(mr), 0.0, -s, ql))
            if not abs(F) > EPS_DIED * run.eps * F_max:  # the velocity crosses zero at the error level: rest
                if not math.isfinite(t_target):
                    st.update(t=t, x=float(y[0]), v=0.0, F=F)
                    raise run._failure("its velocity crosses zero only at the level of the integration error "
                                       "(on the implicit method)")
                t = t_target
                break
            run.rev.extend_columns(np.array([t]), np.array([y[0]]), np.array([F]))
            run.rev_events.append(ne)
            ne, s, m, inside = 0, -s, [float(v) for v in mr], vs is not None
            y[2:] = [float(v) for v in zr]
            F_max = abs(F)
        else:  # a model event: its transition
            zn, mn = model.on_event(k_ev - 1, z, m, s, ql)
            mn = [float(v) for v in mn]
            ne += max(int(float(event_count(m, mn))), 1)
            y[2:] = [float(v) for v in zn]
            m = mn
    run.steps = (run.steps or 0) + steps
    st.update(t=t, x=float(y[0]), v=float(y[1]), s=s, z=y[2:].tolist(), m=m, ne=ne,
              F=float(model.force(y[2:].tolist(), m, float(y[1]), s, ql)))
    return len(run.rev) >= n_target
