"""Sampled-data loop with a force limit and back-calculation anti-windup.

``prefriction.simulate``'s :class:`~prefriction.simulation.feedback.LinearFeedback` is a linear law and
cannot saturate, so this path steps the sampled loop itself: at each sample instant ``t_k``

    e[k]  = r(t_k) - x(t_k)
    v[k]  = C xc[k] + D e[k]                       (unsaturated controller output)
    u[k]  = clip(v[k], -u_max, u_max)              (force applied, held over the interval)
    xc[k+1] = A xc[k] + B e[k] + Ts k_aw (u[k] - v[k])   (back-calculation, Euler in Ts)

and integrates the plant over ``[t_k, t_k + Ts]`` with :func:`prefriction.simulate` (constant
input force, every reversal inside the interval located). ``k_aw`` is
:meth:`controllers.PID.back_calculation_gain`. The reversal table is assembled across the
intervals; the work of the piecewise-constant force is exact (``u[k]`` times the displacement).
A mass that rests at a sample instant and is pushed back the way it came makes a reversal at
that instant, recorded as such; an interval that starts at rest with ``u[k] = F`` is skipped
(the mass stays put). One simulator call per sample costs about 1 ms, several times the
linear path.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import control
import numpy as np

import prefriction
from prefriction.analysis.branch import branch_potential
from prefriction.models import Oscillator
from prefriction.reversals import ReversalTable


def simulate_saturated(
    system: Oscillator,
    C: control.StateSpace,
    k_aw: np.ndarray,
    u_max: float,
    reference_at: Callable[[np.ndarray], np.ndarray],
    t_end: float,
    Ts: float,
    *,
    x0: float,
    v0: float,
    F0: float,
    xc0: Any,
    rtol: float,
    jit: bool,
) -> dict[str, Any]:
    """Run the saturated sampled-data loop; return the arrays and the reversal table (SI)."""
    if system.forced:
        raise ValueError(
            "a force limit u_max needs an oscillator without its own input force (system.u = None), "
            f"got system.u = {system.u!r}"
        )
    A, B, Cc, D = (np.asarray(M, dtype=float) for M in (C.A, C.B, C.C, C.D))
    n = A.shape[0]
    xc = np.zeros(n) if xc0 is None else np.array(xc0, dtype=float).reshape(-1)
    if xc.shape != (n,) or not np.all(np.isfinite(xc)):
        raise ValueError(f"xc0 must be a finite vector of length {n}, got {xc0!r}")
    Fc = system.friction.Fc
    n_int = max(int(math.ceil(t_end / Ts * (1 - 1e-12))), 1)
    tk = Ts * np.arange(n_int)
    r = reference_at(tk)
    rows = {key: np.empty(n_int) for key in ("x", "v", "F", "u")}
    xcs = np.empty((n_int, n))
    rev_t, rev_x, rev_F, rev_Ep, rev_W = [], [], [], [], []
    x, v, F = float(x0), float(v0), float(F0)
    W = 0.0  # work of the applied force since the last reversal [J]
    E_0 = None
    s_prev = 0.0  # direction of the last motion (0: none yet)
    gamma, E_unit = system.friction.gamma, Fc * Fc / system.friction.sigma
    for k in range(n_int):
        e = r[k] - x
        raw = float(Cc[0] @ xc + D[0, 0] * e)
        u = min(max(raw, -u_max), u_max)
        rows["x"][k], rows["v"][k], rows["F"][k], rows["u"][k] = x, v, F, u
        xcs[k] = xc
        xc = A @ xc + B[:, 0] * e + Ts * k_aw * (u - raw)
        if v == 0.0 and u == F:  # at rest with no net force: Dahl friction keeps the mass there
            continue
        h = min(Ts, t_end - tk[k])
        times = np.array([0.0, h])
        plant = prefriction.Oscillator(system.friction, mass=system.mass, u=(times, np.array([u, u])))
        sim = prefriction.simulate(plant, v, x0=x, F0=F, t_end=h, rtol=rtol, dense=times[1:], jit=jit)
        if E_0 is None:
            E_0 = sim.reversals.E_0
        # first direction of motion in this interval (0: the mass stays put)
        x_first = sim.reversals.x[0] if len(sim.reversals) else float(sim.x[-1])
        d = 0.0 if x_first == x else math.copysign(1.0, x_first - x)
        if v == 0.0 and s_prev != 0.0 and d == -s_prev:
            # the mass rested at t_k and leaves backwards: a reversal at t_k
            rev_t.append(tk[k])
            rev_x.append(x)
            rev_F.append(F)
            f_new = np.clip(d * F / Fc, -1.0, 1.0)
            rev_Ep.append(float(branch_potential(np.array([f_new]), gamma)[0]) * E_unit)
            rev_W.append(W)
            W = 0.0
        x_prev = x
        for tr, xr, Fr, Ep in zip(sim.reversals.t, sim.reversals.x, sim.reversals.F, sim.reversals.E_p):
            W += u * (xr - x_prev)
            rev_t.append(tk[k] + tr)
            rev_x.append(xr)
            rev_F.append(Fr)
            rev_Ep.append(Ep)
            rev_W.append(W)
            W, x_prev = 0.0, xr
        x, v, F = float(sim.x[-1]), float(sim.v[-1]), float(np.clip(sim.F[-1], -Fc, Fc))
        W += u * (x - x_prev)
        if v != 0.0:
            s_prev = math.copysign(1.0, v)
        elif x != x_prev:  # came to rest: direction of the motion since the last reversal
            s_prev = math.copysign(1.0, x - x_prev)
    if E_0 is None:  # the mass never moved: v0 = 0 and u = F0 at every sample
        E_0 = float(branch_potential(np.array([-abs(F0) / Fc]), gamma)[0]) * E_unit
    E_p = np.array(rev_Ep)
    E_d = np.empty(len(E_p))
    if len(E_p):
        W_r = np.array(rev_W)
        E_d[0] = E_0 + W_r[0] - E_p[0]
        E_d[1:] = E_p[:-1] + W_r[1:] - E_p[1:]
    table = ReversalTable(t=np.array(rev_t), x=np.array(rev_x), F=np.array(rev_F), E_p=E_p, E_d=E_d, E_0=E_0)
    return {"t": tk, "reference": r, "xc": xcs, "reversals": table, **rows}
