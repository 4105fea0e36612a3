"""Fit a friction model to force measured along a prescribed displacement (:class:`ForceDisplacement`).

The model's normalised state is carried sample by sample along the measured displacement by
the interval step that :func:`prefriction.friction_along` uses
(:func:`prefriction.identify.stepping.interval_function`: the model's exact step, else RK4
sub-steps), repeated with CasADi ``mapaccum``;
the force at every sample is an expression of the parameters, and the least-squares problem is
solved by scipy's trust-region reflective method with the Jacobian from CasADi's automatic
differentiation. The built problem depends only on the model's structure, the free parameters
and the number of samples: data, start values and fixed values are inputs, so refits (other
noise, other start values) reuse it.

The state at the first sample is on the virgin curve (``docs/models.md#state``): reached from
the unloaded state by a virtual monotone displacement ``d0`` (normalised), a nuisance
parameter fitted with the others. For Dahl every state is of this kind (the state is the force).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import casadi as ca
import numpy as np
from scipy import sparse
from scipy.optimize import brentq, least_squares

from prefriction._blas_threads import one_blas_thread
from prefriction.identify.data import ForceDisplacement
from prefriction.identify.parameters import ParameterSpace, symbolic_units
from prefriction.identify.stepping import has_exact_step, interval_function
from prefriction.models.base import FrictionModel

__all__ = ["PrescribedProblem", "fit_prescribed", "path_covariance", "substeps_for"]

_VIRGIN_CALLS = 4
"""Interval calls that make up the virtual virgin loading to the initial state."""
_CACHE: dict[Any, "PrescribedProblem"] = {}


@dataclass(frozen=True)
class _Series:
    """The numeric rows the problem takes for one data set (normalised by the scales' inputs)."""

    dt: np.ndarray      # interval durations [s]
    v: np.ndarray       # interval velocities [m/s]
    s: np.ndarray       # interval directions (+-1; the previous one where dx = 0)
    v_end: np.ndarray   # velocities at the samples [m/s] (central differences)
    v_ref: float        # typical speed [m/s], for the virtual virgin loading

    @classmethod
    def of(cls, data: ForceDisplacement) -> "_Series":
        t, x = data.t, data.path  # the estimated true path under declared position noise
        dt, dx = np.diff(t), np.diff(x)
        s = np.sign(dx)
        first = np.flatnonzero(s)
        s[: first[0]] = s[first[0]]
        for i in range(1, s.size):  # at rest: keep the previous direction
            if s[i] == 0.0:
                s[i] = s[i - 1]
        v = dx / dt
        v_end = np.gradient(x, t)
        moving = np.abs(v[v != 0.0])
        return cls(dt, v, s, v_end, float(np.median(moving)))


def substeps_for(model: FrictionModel, data: ForceDisplacement, requested: int | None) -> int:
    """RK4 sub-steps per sample interval: ``requested``; 1 (unused) for a model with an exact
    interval step (:meth:`FrictionModel.advance`: Dahl, Maxwell-slip, LuGre, GMS, Viscous and
    their sums); otherwise enough that one sub-step moves at most 0.25 (a quarter of the force unit
    ``Fc / sigma``) at the start values, times a margin of 4 for the fit to move, between 1 and 64."""
    if requested is not None:
        return requested
    if has_exact_step(model):
        return 1
    step = float(np.max(np.abs(np.diff(data.path)))) * model.sigma / model.Fc
    return int(min(64, max(2, math.ceil(4.0 * step / 0.25))))


class PrescribedProblem:
    """The least-squares residual of one model structure over ``n`` samples (CasADi Functions).

    Call :meth:`residual` and :meth:`jacobian` with the optimisation vector ``w`` (scaled free
    parameters, then ``d0``), the parameter inputs and the data rows.
    """

    def __init__(self, model: FrictionModel, space: ParameterSpace, n: int, n_sub: int) -> None:
        nf, nx = space.n_free, len(space.fixed)
        w = ca.MX.sym("w", nf + 1)
        scale = ca.MX.sym("scale", nf)
        fixed = ca.MX.sym("fixed", nx)
        rows = ca.MX.sym("rows", 5, n - 1)       # v, dt, s, s_prev (unused: rebuilt), v_end
        v_end0 = ca.MX.sym("v_end0")
        v_ref = ca.MX.sym("v_ref")
        F_data = ca.MX.sym("F", n)
        values = space.symbols(w, fixed, scale)
        sigma, Fc, q = symbolic_units(model, values, 1.0)
        T = ca.sqrt(1.0 / sigma)      # time unit for a unit mass (the mass drops out of F(x))
        V = Fc / ca.sqrt(sigma)       # velocity unit
        step = interval_function(model, n_sub)
        z0, m0 = model.initial_state(0.0, 1.0)
        X = ca.DM([*z0, *m0])
        d0 = w[nf]
        s_v = ca.if_else(d0 >= 0.0, 1.0, -1.0)
        v_virtual = s_v * v_ref / V
        dt_virtual = ca.fabs(d0) / (v_ref / V) / _VIRGIN_CALLS
        for _ in range(_VIRGIN_CALLS):
            X, _F = step(X, v_virtual, dt_virtual, s_v, s_v, v_virtual, q)
        nz = model.n_states
        z, m = [X[i] for i in range(nz)], [X[nz + i] for i in range(model.n_flags)]
        F0 = model.force(z, m, v_end0 / V, s_v, [q[i] for i in range(q.shape[0])])
        s_prev = ca.horzcat(s_v, rows[2, : n - 2]) if n > 2 else s_v
        run = step.mapaccum("run", n - 1)
        _X, F_rest = run(X, rows[0, :] / V, rows[1, :] / T, s_prev, rows[2, :], rows[4, :] / V, q)
        F_model = Fc * ca.vertcat(F0, F_rest.T) + values.get("offset", 0.0)  # force offset [N], if fitted
        r = F_model - F_data
        args = [w, scale, fixed, rows, v_end0, v_ref, F_data]
        self.residual = ca.Function("residual", args, [r])
        self.jacobian = ca.Function("jacobian", args, [ca.jacobian(r, w)])
        self.force = ca.Function("force", args, [F_model])
        self.n = n
        self._symbols = (args, r, rows, v_end0)
        self._path_vjp: ca.Function | None = None

    def path_vjp(self) -> ca.Function:
        """``(args..., seed) -> (d(seed . r)/d rows, d(seed . r)/d v_end0)``: how the residuals move
        with the velocities the path gives (reverse mode; built on first use)."""
        if self._path_vjp is None:
            args, r, rows, v_end0 = self._symbols
            seed = ca.MX.sym("seed", self.n)
            dot = ca.dot(seed, r)
            self._path_vjp = ca.Function("path_vjp", [*args, seed], [ca.gradient(dot, rows), ca.gradient(dot, v_end0)])
        return self._path_vjp

    @classmethod
    def get(cls, model: FrictionModel, space: ParameterSpace, n: int, n_sub: int) -> "PrescribedProblem":
        """The problem for this structure, built once per process."""
        key = (type(model), model.structure_key(), tuple(space.free), tuple(space.fixed), n, n_sub)
        if key not in _CACHE:
            _CACHE[key] = cls(model, space, n, n_sub)
        return _CACHE[key]


def _inputs(space: ParameterSpace, series: _Series, data: ForceDisplacement) -> list[Any]:
    rows = np.vstack([series.v, series.dt, series.s, series.s, series.v_end[1:]])
    return [space.scale, space.fixed_values(), rows, series.v_end[0], series.v_ref, data.F]


def _start_d0(problem: PrescribedProblem, space: ParameterSpace, series: _Series, data: ForceDisplacement) -> float:
    """The virgin distance ``d0`` whose force at the first sample is the measured one (start values)."""
    args = _inputs(space, series, data)

    def f0(d: float) -> float:
        w = np.append(space.theta0, d)
        return float(problem.force(w, *args)[0]) - float(data.F[0])

    lo, hi = -30.0, 30.0
    while not np.isfinite(f0(lo)) and lo < -1e-6:  # a model that diverges running far backwards
        lo *= 0.5
    while not np.isfinite(f0(hi)) and hi > 1e-6:
        hi *= 0.5
    if f0(lo) > 0.0:
        return lo
    if f0(hi) < 0.0:
        return hi
    return float(brentq(f0, lo, hi, xtol=1e-12))


@dataclass(frozen=True)
class PrescribedSolution:
    """What :func:`fit_prescribed` returns to :func:`prefriction.identify.fit`."""

    w: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    prediction: np.ndarray
    nfev: int
    message: str
    success: bool
    extra_covariance: Callable[[np.ndarray], np.ndarray] | None = None  # errors in the positions


def fit_prescribed(model: FrictionModel, data: ForceDisplacement, space: ParameterSpace, *,
                   n_sub: int | None, max_iter: int, tol: float) -> PrescribedSolution:
    """Least-squares fit of ``space``'s free parameters to ``data`` (trust-region reflective).

    A run that reaches ``max_iter`` evaluations returns with ``success = False``.

    Raises
    ------
    prefriction.SolverError
        If the model's force is not finite at the start values or at the end; the message
        names the parameters reached and what to try.
    """
    from prefriction.errors import SolverError

    n_sub = substeps_for(model, data, n_sub)
    problem = PrescribedProblem.get(model, space, len(data), n_sub)
    series = _Series.of(data)
    args = _inputs(space, series, data)
    d0 = _start_d0(problem, space, series, data)
    w0 = np.append(space.theta0, d0)
    lo, hi = space.theta_bounds()
    lo, hi = np.append(lo, -50.0), np.append(hi, 50.0)

    def fun(w: np.ndarray) -> np.ndarray:
        return np.asarray(problem.residual(w, *args)).ravel()

    def jac(w: np.ndarray) -> np.ndarray:
        return np.asarray(problem.jacobian(w, *args))

    r0 = fun(w0)
    if not np.all(np.isfinite(r0)):
        i = int(np.flatnonzero(~np.isfinite(r0))[0])
        raise SolverError(f"the start model's force is not finite at sample {i} (t = {data.t[i]!r} s, "
                          f"x = {data.x[i]!r} m); give start values closer to the data or more substeps")
    with one_blas_thread():
        sol = least_squares(fun, w0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac",
                            xtol=tol, ftol=tol, gtol=tol, max_nfev=max_iter)
    if sol.status < 0 or not np.all(np.isfinite(sol.fun)):
        vals = space.values(sol.x[:-1])
        raise SolverError(f"the least-squares fit failed ({sol.message}) after {sol.nfev} evaluations, "
                          f"at {', '.join(f'{n} = {vals[n]:.6g}' for n in space.free)}; try other start values, "
                          f"bounds, fixing a parameter or more substeps")
    pred = np.asarray(problem.force(sol.x, *args)).ravel()
    message = str(sol.message) if sol.status > 0 else (
        f"stopped without converging after {sol.nfev} evaluations (max_iter = {max_iter}): {sol.message}")
    extra = path_covariance(problem, sol.x, args, data) if data.noisy_positions else None
    return PrescribedSolution(sol.x, sol.fun.copy(), jac(sol.x), pred, int(sol.nfev), message, sol.status > 0, extra)


def _gradient_operator(t: np.ndarray) -> sparse.csr_matrix:
    """The sparse matrix of ``numpy.gradient(x, t)`` (second order inside, first order at the ends)."""
    n = t.size
    h = np.diff(t)
    h1, h2 = h[:-1], h[1:]
    i = np.arange(1, n - 1)
    rows = np.r_[0, 0, np.repeat(i, 3), n - 1, n - 1]
    cols = np.r_[0, 1, np.c_[i - 1, i, i + 1].ravel(), n - 2, n - 1]
    vals = np.r_[-1.0 / h[0], 1.0 / h[0],
                 np.c_[-h2 / (h1 * (h1 + h2)), (h2 - h1) / (h1 * h2), h1 / (h2 * (h1 + h2))].ravel(),
                 -1.0 / h[-1], 1.0 / h[-1]]
    return sparse.csr_matrix((vals, (rows, cols)), shape=(n, n))


def path_covariance(problem: PrescribedProblem, w: np.ndarray, args: list[Any],
                    data: ForceDisplacement) -> Callable[[np.ndarray], np.ndarray]:
    """The covariance the estimated path's error adds to the estimates (errors in variables).

    With the parameters' influence weights ``W = dtheta/dr`` (shape ``(k, n)``) and the residuals'
    sensitivity ``D = dr/dx`` to the path samples (through the interval velocities and the sample
    velocities, reverse mode), the estimates move by ``G e`` with ``G = -W D`` for a path error
    ``e = S_w eps`` (``S_w`` the smoother, ``eps`` white with the declared variance ``s^2``):
    ``Cov = s^2 (G S_w)(G S_w)^T`` (``docs/identify.md#positions``, eq. P2), plus for each reversal
    the rounding error common to the samples that dwell within one encoder step of it,
    ``s_q^2 (G 1_dwell)(G 1_dwell)^T`` (eq. P3, :func:`prefriction.identify.positions.dwell_error_sd`).

    Parameters
    ----------
    problem : PrescribedProblem
        The problem fitted.
    w : numpy.ndarray
        The optimum.
    args : list
        The problem's inputs (:func:`_inputs`).
    data : ForceDisplacement
        The data, with ``x_noise`` or ``quantum`` declared.

    Returns
    -------
    callable
        ``W -> Cov`` [physical units].
    """
    from prefriction.identify.positions import dwell_error_sd, dwell_sets, noise_sd, smoothed_covariance_factor

    vjp = problem.path_vjp()
    t = data.t
    dt = np.diff(t)
    grad_t = _gradient_operator(t).T.tocsr()
    s = noise_sd(data.x_noise, data.quantum)
    s_dwell = dwell_error_sd(data.x_noise, data.quantum)
    dwells = dwell_sets(data.path, data.quantum) if s_dwell > 0.0 else []

    def extra(W: np.ndarray) -> np.ndarray:
        G = np.empty_like(W)
        for a in range(W.shape[0]):
            g_rows, g_v0 = vjp(w, *args, W[a])
            g_rows = np.asarray(g_rows)
            gv = g_rows[0] / dt                       # v_k = (x_{k+1} - x_k) / dt_k
            dx = np.zeros(t.size)
            dx[:-1] -= gv
            dx[1:] += gv
            g_end = np.r_[float(g_v0), g_rows[4]]     # v_end = gradient(x, t)
            G[a] = -(dx + grad_t @ g_end)
        GS = smoothed_covariance_factor(G, data.path_window)
        cov = s * s * (GS @ GS.T)
        for idx in dwells:                            # eq. P3: one common error per reversal
            g = G[:, idx].sum(axis=1)
            cov += s_dwell**2 * np.outer(g, g)
        return cov

    return extra
