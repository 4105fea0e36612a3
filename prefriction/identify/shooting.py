"""Fit a friction model to the motion of a mass (:class:`Motion`) by multiple shooting with IPOPT.

The record is cut into segments at the velocity reversals located in the data
(:func:`prefriction.identify.reversals.locate_reversals`). Each segment has a fixed direction
``s`` and starts at its reversal time ``tau_j`` (a free variable within a sample and a half of
its estimate) with zero velocity, a free position and a free model state; the first segment
starts at the first sample with free position, velocity and state. Inside a segment the
oscillator ``m x'' + F = u`` (2.1) and the model's state are integrated in the model's
normalised units (``docs/models.md#protocol``) by RK4 sub-steps between the samples (from the
reversal to the first sample, possibly backwards by a fraction of a sample: near a reversal
the velocity is small and the branch direction matters only at fourth order in the time
offset). Continuity at every reversal: position, zero velocity, and the state after
``reverse``. The objective is the sum of squared position residuals.

The nonlinear program depends on the model structure, the free parameters, the number of
samples and the segment layout; the data, start values and fixed values are its parameters,
so refits of data with the same layout reuse it.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from prefriction.errors import SolverError
from prefriction.identify.data import Motion
from prefriction.identify.parameters import ParameterSpace, symbolic_units
from prefriction.identify.reversals import locate_reversals
from prefriction.identify.stepping import rk4
from prefriction.models.base import FrictionModel

__all__ = ["MotionSolution", "fit_motion"]

_SLACK = 1.5
"""Half-width of a reversal time's bracket, in samples around its estimate."""
_CACHE: dict[Any, "_ShootingProblem"] = {}
_SOLVE_LOCK = threading.Lock()
"""One IPOPT solve at a time per process: fits from several threads take turns (they crashed the process)."""


@dataclass(frozen=True)
class MotionSolution:
    """What :func:`fit_motion` returns to :func:`prefriction.identify.fit`."""

    w: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    constraints: np.ndarray
    prediction: np.ndarray
    nuisance: dict
    message: str


class _ShootingProblem:
    """The multiple-shooting NLP of one structure and segment layout (built once, then reused)."""

    def __init__(self, model: FrictionModel, space: ParameterSpace, n: int, cuts: tuple[int, ...], n_sub: int,
                 mass_free: bool, max_iter: int, tol: float) -> None:
        nz, nf, nx = model.n_states, space.n_free, len(space.fixed)
        nr = len(cuts)
        P = {name: ca.SX.sym(name, size) for name, size in
             (("t", n), ("x", n), ("u", n), ("scale", nf), ("fixed", nx), ("mass", 1), ("tau0", nr),
              ("htau", nr), ("s0", 1), ("xs", 1))}
        theta = ca.SX.sym("theta", nf)
        values = {name: theta[i] * P["scale"][i] for i, name in enumerate(space.free)}
        values.update({name: P["fixed"][i] for i, name in enumerate(space.fixed)})
        mass = values["mass"] if mass_free else P["mass"]
        sigma, Fc, q = symbolic_units(model, values, mass)
        ql = [q[i] for i in range(q.shape[0])]
        T = ca.sqrt(mass / sigma)
        X = Fc / sigma
        first = ca.SX.sym("first", 2 + nz)                   # x~, v~, z at t0
        nodes = [ca.SX.sym(f"node{j}", 2 + nz) for j in range(nr)]   # dtau, x~, z at each reversal
        t, x, u = P["t"], P["x"], P["u"]

        piece = _piece_function(model, n_sub, q.shape[0])

        def advance(y: list[Any], s: Any, t_from: Any, t_to: Any, i: int) -> list[Any]:
            """From ``t_from`` to ``t_to`` with u linear on the data interval ``[t[i-1], t[i]]`` (extended)."""
            a, b = max(i - 1, 0), max(i, 1)
            slope = (u[b] - u[a]) / (t[b] - t[a])
            out = piece(ca.vertcat(*y), s, t_from, t_to, u[a], t[a], slope, T, Fc, q)
            return [out[k] for k in range(2 + nz)]

        pred, cons = [], []
        starts = [0] + [k + 1 for k in cuts]
        ends = [k + 1 for k in cuts] + [n]
        s = P["s0"]
        y = [first[0], first[1], *[first[2 + i] for i in range(nz)]]
        t_prev: Any = t[0]
        for j, (a_idx, b_idx) in enumerate(zip(starts, ends)):
            for i in range(a_idx, b_idx):
                if not (j == 0 and i == 0):
                    y = advance(y, s, t_prev, t[i], i)
                pred.append(y[0] * X)
                t_prev = t[i]
            if j < nr:
                tau = P["tau0"][j] + P["htau"][j] * nodes[j][0]
                y = advance(y, s, t_prev, tau, b_idx)
                s = -s
                z_new, _m = model.reverse(y[2:], [], s, ql, 1e-12)
                node = nodes[j]
                cons += [y[0] - node[1], y[1], *[zz - node[2 + i] for i, zz in enumerate(z_new)]]
                y = [node[1], 0.0 * node[1], *[node[2 + i] for i in range(nz)]]
                t_prev = tau
        w = ca.vertcat(theta, first, *nodes)
        r = ca.vertcat(*pred) - x
        p = ca.vertcat(*P.values())
        g = ca.vertcat(*cons) if cons else ca.SX(0, 1)
        self.n_w, self.n_g, self.n_theta, self.nz = w.shape[0], g.shape[0], nf, nz
        nlp = {"x": w, "p": p, "f": 0.5 * ca.sumsqr(r / P["xs"]), "g": g}
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": max_iter,
                "ipopt.tol": tol}
        self.solver = ca.nlpsol("motion_fit", "ipopt", nlp, opts)
        self.parts = ca.Function("parts", [w, p], [r, ca.jacobian(r, w), g, ca.jacobian(g, w),
                                                   ca.vertcat(*pred), sigma, Fc, T])
        self.param_names = list(P)

    @classmethod
    def get(cls, model: FrictionModel, space: ParameterSpace, n: int, cuts: tuple[int, ...], n_sub: int,
            mass_free: bool, max_iter: int, tol: float) -> "_ShootingProblem":
        key = (type(model), model.structure_key(), tuple(space.free), tuple(space.fixed), n, cuts, n_sub, mass_free,
               max_iter, tol)
        if key not in _CACHE:
            _CACHE[key] = cls(model, space, n, cuts, n_sub, mass_free, max_iter, tol)
        return _CACHE[key]


def _piece_function(model: FrictionModel, n_sub: int, nq: int) -> ca.Function:
    """``n_sub`` RK4 sub-steps of the normalised oscillator ``x~' = v~``, ``v~' = u~ - F~``, with
    the model's state, from ``t_from`` to ``t_to`` [s] (SX ``Function``, inlined where called).

    Inputs ``(y, s, t_from, t_to, u_a, t_a, slope, T, Fc, q)``: state ``[x~, v~, z]``, direction,
    the interval, the applied force ``u = u_a + slope (t - t_a)`` [N], the time unit ``T`` [s],
    the force unit ``Fc`` [N] and the run-time numbers ``q``.
    """
    nz = model.n_states
    y = ca.SX.sym("y", 2 + nz)
    s, t_from, t_to, u_a, t_a, slope, T, Fc = (ca.SX.sym(n) for n in ("s", "t_from", "t_to", "u_a", "t_a",
                                                                         "slope", "T", "Fc"))
    qs = ca.SX.sym("q", nq)
    ql = [qs[i] for i in range(nq)]

    def rhs(yy: list[Any], ut: Any) -> list[Any]:
        z = yy[2:]
        F = model.force(z, [], yy[1], s, ql)
        return [yy[1], ut / Fc - F, *model.rate(z, [], yy[1], s, ql)]

    h = (t_to - t_from) / n_sub
    yl = [y[i] for i in range(2 + nz)]
    for k in range(n_sub):
        ut = u_a + slope * (t_from + (k + 0.5) * h - t_a)  # u linear: RK4 uses it at the midpoint
        yl = rk4(lambda yy, ut=ut: rhs(yy, ut), yl, h / T)
    return ca.Function("piece", [y, s, t_from, t_to, u_a, t_a, slope, T, Fc, qs], [ca.vertcat(*yl)])


def _substeps(model: FrictionModel, data: Motion, mass: float, v_max: float, requested: int | None) -> int:
    """RK4 sub-steps per sample: a normalised sub-step of at most 0.1 (and 0.2 / |v~| for a
    rate-dependent model, whose state relaxes at a rate ~ |v~|), at the start values, 1 to 64."""
    if requested is not None:
        return requested
    T = math.sqrt(mass / model.sigma)
    h = float(np.max(np.diff(data.t))) / T
    v = v_max / (model.Fc / math.sqrt(mass * model.sigma))
    limit = 0.1 if model.rate_independent else min(0.1, 0.2 / max(v, 1e-300))
    return int(min(64, max(1, math.ceil(h / limit))))


def fit_motion(model: FrictionModel, data: Motion, space: ParameterSpace, *, n_sub: int | None,
               max_iter: int, tol: float, reversals: Any = None) -> MotionSolution:
    """Multiple-shooting least-squares fit of ``space``'s free parameters to ``data`` (IPOPT).

    Raises
    ------
    ValueError
        If the model has in-branch events (not supported for motion data) or the data's
        reversals cannot be located.
    prefriction.SolverError
        If IPOPT fails; the message gives its status and the parameters reached.
    """
    if model.n_events or model.n_flags:
        raise ValueError(f"Motion fits support models without in-branch events or flags (Dahl with gamma >= 1, "
                         f"LuGre); {type(model).__name__} has {model.n_events} events: fit it to "
                         f"ForceDisplacement data")
    mass_free = "mass" in space.start
    mass = space.start["mass"] if mass_free else float(data.mass)
    rev = locate_reversals(data.t, data.x, reversals)
    n_sub = _substeps(model, data, mass, float(np.max(np.abs(rev.v))), n_sub)
    cuts = tuple(int(k) for k in rev.index)
    prob = _ShootingProblem.get(model, space, len(data), cuts, n_sub, mass_free, max_iter, tol)
    h = np.diff(data.t)
    htau = _SLACK * h[rev.index] if cuts else np.zeros(0)
    xs = max(float(np.ptp(data.x)) * 1e-3, 1e-300)
    p = np.concatenate([data.t, data.x, data.u, space.scale, space.fixed_values(), [mass], rev.time, htau,
                        [rev.s0], [xs]])
    w0, lbw, ubw = _start(model, data, space, rev, mass)
    with _SOLVE_LOCK:  # IPOPT with MUMPS is not thread-safe, and stats() reports the solver's last call
        sol = prob.solver(x0=w0, p=p, lbx=lbw, ubx=ubw, lbg=0.0, ubg=0.0)
        stats = prob.solver.stats()
    w = np.asarray(sol["x"]).ravel()
    if not stats.get("success", False):
        vals = space.values(w[: space.n_free])
        raise SolverError(f"IPOPT did not converge ({stats.get('return_status')}) after {stats.get('iter_count')} "
                          f"iterations, at {', '.join(f'{n} = {vals[n]:.6g}' for n in space.free)}; try start "
                          f"values closer to the data, bounds, fixing a parameter, or cutting the record where "
                          f"the motion sinks into the noise")
    r, J, g, A, pred, sigma, Fc, T = (np.asarray(v) for v in prob.parts(w, p))
    nz = model.n_states
    Fc, sigma, T = Fc.item(), sigma.item(), T.item()
    v_unit = Fc / sigma / T  # Fc / sqrt(m sigma)
    nuisance: dict[str, Any] = {"initial velocity v0 [m/s]": float(w[space.n_free + 1]) * v_unit}
    z0 = w[space.n_free + 2: space.n_free + 2 + nz].tolist()
    nuisance["initial force F0 [N]"] = float(model.force(z0, [], float(w[space.n_free + 1]), rev.s0,
                                                         _runtime(space, model, w, mass_free, mass))) * Fc
    base = space.n_free + 2 + nz
    dtau = w[base::2 + nz][: len(cuts)]
    nuisance["reversal times [s]"] = rev.time + htau * dtau
    return MotionSolution(w, r.ravel(), J, A, pred.ravel(), nuisance,
                          f"IPOPT: {stats.get('return_status')} after {stats.get('iter_count')} iterations")


def _runtime(space: ParameterSpace, model: FrictionModel, w: np.ndarray, mass_free: bool, mass: float) -> list[float]:
    """The run-time numbers of the fitted values (floats), for the reported initial force."""
    from prefriction.units import Scales

    vals = space.values(w[: space.n_free])
    fitted = space.build(vals)
    m = vals["mass"] if mass_free else mass
    V = fitted.Fc / math.sqrt(m * fitted.sigma)
    scales = Scales(x=fitted.Fc / fitted.sigma, F=fitted.Fc, t=math.sqrt(m / fitted.sigma), v=V,
                    E=fitted.Fc**2 / fitted.sigma)
    return [float(v) for v in fitted.runtime_params_for(scales)]


def _start(model: FrictionModel, data: Motion, space: ParameterSpace, rev: Any, mass: float) -> tuple[np.ndarray, ...]:
    """Start values and bounds of the optimisation vector from the data (smoothed) and the start model."""
    sigma, Fc = model.sigma, model.Fc
    X, V = Fc / sigma, Fc / math.sqrt(mass * sigma)
    lo, hi = space.theta_bounds()

    def state(i: int, s: float) -> list[float]:
        f = float(np.clip((data.u[i] - mass * rev.a[i]) / Fc, -0.9, 0.9))
        return list(model.initial_state(f, s)[0])

    w0 = list(np.ones(space.n_free)) + [rev.x[0] / X, rev.v[0] / V, *state(0, rev.s0)]
    lbw, ubw = list(lo), list(hi)
    lbw += [-np.inf] * (2 + model.n_states)
    ubw += [np.inf] * (2 + model.n_states)
    s = rev.s0
    for k, tau in zip(rev.index, rev.time):
        s = -s
        i = int(k) if abs(tau - data.t[k]) <= abs(tau - data.t[k + 1]) else int(k) + 1
        w0 += [0.0, rev.x[i] / X, *state(i, s)]
        lbw += [-1.0] + [-np.inf] * (1 + model.n_states)
        ubw += [1.0] + [np.inf] * (1 + model.n_states)
    return np.array(w0), np.array(lbw), np.array(ubw)
