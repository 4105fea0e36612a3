"""The implicit path of a forced run: branches too stiff for the explicit Runge-Kutta method.

The forced native driver (``native/forced.c``) tests every step for stiffness as the unforced
one does (:mod:`prefriction.simulation.stiff`: Hairer and Wanner's test of ``h |lambda|``) and
stops with code 6 when more than 20,000 steps have passed since the last reversal and 15 steps
were held by the method's stability. :func:`advance_stiff_forced` continues the run with scipy's
Radau IIA on the normalised forced oscillator

    x~' = v~,  v~' = u~(t~) - F~,  z' = rate(z, m, v~, s),  W~' = u~ v~

(the input ``u~ = u / Fc`` read from the user's signal, the run broken at its break times), with
the events of the native driver (``docs/simulator.md#native-forced``): the zero of
``s v~ + EPS_START A`` is a reversal, a touch or a rest by the net force (``EPS_TOUCH eps A``), a
resting mass leaves when ``|u~ - F~|`` exceeds ``EPS_REST eps A`` (located by Brent's method on
the input), and the model's events with their transitions. Open-loop runs without dense output
only; the others stay on the explicit method.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from prefriction.simulation.plant import EPS_REST, EPS_START, EPS_TOUCH, event_count
from prefriction.simulation.stiff import _BAND, _MIN_RTOL, _event, _scales, stiff_functions

if TYPE_CHECKING:
    from prefriction.simulation.run_state import RunState

__all__ = ["advance_stiff_forced"]

_SCAN = 2.0 * math.pi / 16.0  # normalised time between checks of a resting mass's net force (forced.c)


def _rhs(model: Any, u: Callable[[float], float], t: float, y: np.ndarray, m: list, s: float,
         q: list) -> list[float]:
    """``(v~, u~ - F~, z', u~ v~)`` of the normalised forced oscillator, on floats."""
    z, v = y[2:-1].tolist(), float(y[1])
    uu = u(t)
    return [v, uu - float(model.force(z, m, v, s, q)), *(float(r) for r in model.rate(z, m, v, s, q)), uu * v]


class _Input:
    """The input force ``u~(t~)`` of ``run`` (normalised) and its break times."""

    def __init__(self, run: "RunState") -> None:
        sig, sc = run.system.u, run.sc
        self.breaks = run.breaks
        self.u = lambda t: float(sig(t * sc.t)) / sc.F

    def next_break(self, t: float, t_end: float) -> float:
        k = int(np.searchsorted(self.breaks, t * (1 + 1e-15) + 1e-300, side="right"))
        return min(float(self.breaks[k]), t_end) if k < self.breaks.size else t_end


def _rest_exit(inp: _Input, F: float, thr: float, t: float, t_end: float) -> float:
    """The first time after ``t`` where ``|u~ - F~| > thr`` (``t_end`` if none)."""
    g = lambda tt: thr - abs(inp.u(tt) - F)
    if g(t) < 0.0:
        return t
    while t < t_end:
        t1 = min(t + _SCAN, inp.next_break(t, t_end))
        if g(t1) < 0.0:
            return brentq(g, t, t1, xtol=1e-15 * max(abs(t1), 1e-300), rtol=4.5e-16)
        t = t1
    return t_end


def advance_stiff_forced(run: "RunState", t_end: float, n_target: float) -> None:
    """Continue the forced open-loop ``run`` (state ``run.st``, normalised) with Radau to the
    normalised time ``t_end`` or ``n_target`` reversals, appending reversals ``(t, x, F, W)`` and
    their half-cycles' event counts as the native driver does."""
    model, st = run.model, run.st
    fn, inp = stiff_functions(model), _Input(run)
    ql, qd = run.q.tolist(), ca.DM(run.q)
    nz = model.n_states
    y = np.array([st["x"], st["v"], *st["z"], st["W"]], dtype=float)
    m, s, t, ne, rest = list(st["m"]), float(st["s"]), float(st["t"]), int(st.get("ne", 0)), st["rest"] > 0.5
    rtol = max(run.eps_native, _MIN_RTOL)
    vs = model.velocity_scale(ql)
    inside = vs is not None and s * y[1] <= _BAND * vs
    steps = 0
    while len(run.rev) < n_target and t < t_end:
        z = y[2:-1].tolist()
        F = float(model.force(z, m, float(y[1]), s, ql))
        A = math.hypot(y[1], F)
        run.A_max = max(run.A_max, A)
        A = max(A, run.force_scale, 0.1 * run.A_max, 1e-150)
        if rest:  # frozen until the net force passes the threshold
            t = _rest_exit(inp, F, EPS_REST * run.eps * A, t, t_end)
            if t >= t_end:
                break
            rest = False
            a = inp.u(t) - F
            if (1.0 if a > 0 else -1.0) != s:  # leaves backwards: a reversal at this instant (its force before the reset)
                s = _reverse(run, model, y, m, s, t, ne, ql, F)
                m, ne = list(run.st["m"]), 0
            continue
        md = ca.DM(m)
        rhs = lambda tt, yy, m=m, s=s: _rhs(model, inp.u, tt, yy, m, s, ql)

        def jac(tt: float, yy: np.ndarray, md: Any = md, s: float = s) -> np.ndarray:
            J = np.zeros((nz + 3, nz + 3))
            J[:nz + 2, :nz + 2] = np.asarray(fn.jac(yy[:-1], md, s, qd))
            J[-1, 1] = inp.u(tt)
            return J

        off = EPS_START * A
        events: list[Any] = [_event(lambda _t, yy, s=s, off=off: s * yy[1] + off)]
        for k in range(fn.n_events):
            events.append(_event(lambda _t, yy, k=k, m=m, s=s: float(model.events(yy[2:-1].tolist(), m, yy[1], s, ql)[k])))
        n_model = len(events)
        max_step = math.inf
        if vs is not None:  # a narrow Stribeck curve: as stiff.advance_stiff
            if not inside:
                events.append(_event(lambda _t, yy, s=s: s * yy[1] - _BAND * vs))
            else:
                events.append(_event(lambda _t, yy, s=s: _BAND * vs - s * yy[1]))
                max_step = 0.25 * vs / max(abs(inp.u(t) - F), 1e-300)
        atol = np.r_[_scales(y[:-1], F, rtol, model.tracks_position), A * A * rtol]
        t_seg = inp.next_break(t, t_end)
        sol = solve_ivp(rhs, (t, t_seg), y, method="Radau", jac=jac, rtol=rtol, atol=atol, events=events,
                        max_step=max_step)
        steps += int(sol.t.size - 1)
        if sol.status < 0:
            raise run._failure(f"the implicit Radau method failed ({sol.message})")
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 0:  # the next piece of the input, or the end
            continue
        k_ev = min((te[0], k) for k, te in enumerate(sol.t_events) if te.size)[1]
        z = y[2:-1].tolist()
        if k_ev >= n_model:  # the edge of the Stribeck band
            inside = not inside
            continue
        if k_ev == 0:  # s v = 0: a touch, a rest or a reversal by the net force
            y[1] = 0.0
            a = inp.u(t) - float(model.force(z, m, 0.0, s, ql))
            thr = EPS_TOUCH * run.eps * A
            if s * a > thr:  # a touch: the speed keeps its sign
                continue
            if s * a >= -thr:
                rest = True
                continue
            s = _reverse(run, model, y, m, s, t, ne, ql)
            m, ne, inside = list(run.st["m"]), 0, vs is not None
            continue
        zn, mn = model.on_event(k_ev - 1, z, m, s, ql)  # a model event: its transition
        mn = [float(v) for v in mn]
        ne += max(int(float(event_count(m, mn))), 1)
        y[2:-1] = [float(v) for v in zn]
        m = mn
    run.steps = (run.steps or 0) + steps
    z = y[2:-1].tolist()
    v = 0.0 if rest else float(y[1])
    st.update(t=min(t, t_end), x=float(y[0]), v=v, s=s, z=z, m=m, ne=ne, rest=1.0 if rest else 0.0,
              W=float(y[-1]), F=float(model.force(z, m, v, s, ql)))


def _reverse(run: "RunState", model: Any, y: np.ndarray, m: list, s: float, t: float, ne: int, ql: list,
             F: float | None = None) -> float:
    """Record the reversal at ``t`` (the force ``F``, by default the force after the model's reset,
    as forced.c; the input's work ``y[-1]``), start the branch of direction ``-s`` in ``y`` and
    ``run.st["m"]``; returns ``-s``."""
    zr, mr = model.reverse(y[2:-1].tolist(), m, -s, ql, run.snap)
    if F is None:
        F = float(model.force(list(zr), list(mr), 0.0, -s, ql))
    run.rev.extend_columns(np.array([t]), np.array([y[0]]), np.array([F]), np.array([y[-1]]))
    run.rev_events.append(ne)
    y[1], y[-1] = 0.0, 0.0
    y[2:-1] = [float(v) for v in zr]
    run.st["m"] = [float(v) for v in mr]
    return -s
