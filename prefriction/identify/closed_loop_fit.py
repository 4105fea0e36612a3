"""The closed-loop output-error route: the model simulated inside the known digital loop.

A record taken under feedback (the EMPS stage under its PD loop) is simulated the way it was
measured: at each sample ``k`` the loop reads the simulated position ``x_k``, computes

    u_k = Kp (r_k - x_k) + Ki dt sum_{j<=k} (r_j - x_j) - Kd sum_j c_j (x_{k-j} - x_{k-j-1}) / dt + e_k   (1)

(``r`` the recorded reference, ``c_j`` the velocity filter's taps, ``e`` an optional recorded
additive force, e.g. EMPS's pulses), or any linear law on the error ``r - x``
(:class:`prefriction.identify.DigitalLoop`, e.g. from a :class:`prefriction.controllers.PID`),
and applies ``u_{k-d}`` (``d`` samples of delay) held over the
next sample interval to the stage ``m x'' + F + F_off = u`` (2.1) with any friction model
(one sample of :func:`prefriction.identify.motion_step.step_function`: Runge-Kutta sub-steps
cut at the reversals). The feedback keeps the simulation on the record, so it cannot drift
however long the record (unlike the open-loop Motion fit, which integrates the recorded force
through the mass).

The fit has two stages, each a ``scipy.optimize.least_squares`` (trust-region reflective) with
the exact Jacobian from forward sensitivities carried along the record (CasADi ``mapaccum``: time
and memory linear in the samples; in-branch events located inside the sub-steps, their time's
derivative carried, :mod:`prefriction.identify.motion_step`):

1. *the loop*: the parameters (model, mass, offset) minimise ``sum (x_k - x_meas_k)^2 / w_x^2 +
   (u_k - u_meas_k)^2 / w_u^2`` with the loop above, the channel weights ``w`` the residual
   standard deviations of the start model, updated once after a first fit. The loop holds the
   simulation on the record from rough starts, but its controller reads the simulated positions,
   while the real one read the encoder: on a stiff loop its rounding error is in the recorded
   force and biases these estimates by several standard errors;
2. *the recorded force*: the stage driven by the recorded force ``u_meas`` (what the controller
   computed from the encoder; it is known exactly), fitted to the positions with the initial
   position profiled out (a replay from ``x0 + c`` is the replay from ``x0`` plus ``c``),
   from stage 1's estimates with continuation over the record's length (an eighth, a quarter, a
   half, all of it), then, if that fails, from the start values. It is the output-error
   estimator of a deterministic plant with a known input, consistent under the encoder's error;
   it is kept when it converges and its position residuals are no larger than stage 1's (a
   record whose force does not carry its motion, e.g. a model that misses some of the
   physics, keeps stage 1 with a ``ConvergenceWarning``).

Uncertainty: Newey-West standard errors (:mod:`prefriction.identify.hac`) on the per-sample
scores; with the encoder declared (``Motion(quantum=, x_noise=)``) stage 2 adds the covariance
of the rounding error that samples at the same place on the grid share
(:mod:`prefriction.identify.encoder`).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, Sequence

import casadi as ca
import numpy as np

from prefriction._blas_threads import one_blas_thread
from prefriction._validation import check_count, check_positive
from prefriction.errors import SolverError
from prefriction.identify.data import Motion
from prefriction.identify.digital_loop import DigitalLoop
from prefriction.identify.encoder import grid_step, rounding_covariance, widened
from prefriction.identify.hac import sandwich
from prefriction.identify.options import check_solver
from prefriction.identify.result import FitResult
from prefriction.identify.statistics import (ConvergenceWarning, IdentifiabilityWarning, NoisyPositionsWarning,
                                             at_bounds, gauss_newton)
from prefriction.identify.substep_check import STEP_SHIFT, step_shift
from prefriction.models.base import FrictionModel

__all__ = ["fit_closed_loop", "simulate_closed_loop"]

_CACHE: dict[Any, tuple[ca.Function, int]] = {}
COMPILE_FROM = 5000
"""Records of this many samples or more run the loop's step compiled (``prefriction.simulation.compiled``);
shorter ones interpreted (the compilation would take longer than it saves)."""


def _controller(loop: DigitalLoop, x: Any, mem: Any, r: Any, e: Any) -> tuple[Any, list[Any]]:
    """The force at a sample and the controller's memory after it (CasADi SX).

    Memory: the law (1)'s last ``len(taps)`` positions and the error's sum; the law (2)'s last
    ``len(num) - 1`` errors and ``len(den) - 1`` unsaturated outputs.
    """
    if not loop.linear:
        nt = len(loop.taps)
        xs = [x] + [mem[j] for j in range(nt)]
        v = sum(c * (xs[j] - xs[j + 1]) for j, c in enumerate(loop.taps)) / loop.dt
        total = mem[nt] + (r - x)
        return loop.Kp * (r - x) + loop.Ki * loop.dt * total - loop.Kd * v + e, xs[:nt] + [total]
    nb, na = len(loop.num) - 1, len(loop.den) - 1
    eps = [r - x] + [mem[j] for j in range(nb)]
    outs = [mem[nb + j] for j in range(na)]
    lin = (sum(b * ej for b, ej in zip(loop.num, eps)) - sum(a * uj for a, uj in zip(loop.den[1:], outs))) / loop.den[0]
    return lin + e, eps[:nb] + ([lin] + outs[:na - 1] if na else [])


def _memory(loop: DigitalLoop, x0: float) -> np.ndarray:
    """The controller's memory before the record: at rest at ``x0``, no error, no force."""
    if not loop.linear:
        return np.concatenate((np.full(len(loop.taps), x0), [0.0]))
    return np.zeros(len(loop.num) + len(loop.den) - 2)


def _loop_function(model: FrictionModel, loop: DigitalLoop, space: Any, n_sub: int, mass_free: bool
                   ) -> tuple[ca.Function, int]:
    """One sample of the loop with forward sensitivities: ``(c, [r, e], theta, scale, fixed, mass) -> c+, out``."""
    from prefriction.identify.motion_step import _units_function, step_function

    ny, nd, nm = 2 + model.n_states + model.n_flags, loop.delay, _memory(loop, 0.0).size   # [x, v, z, flags]
    step = step_function(model, n_sub)
    units = _units_function(model, space, mass_free)
    nth = space.n_free
    y = ca.SX.sym("y", ny)
    s = ca.SX.sym("s")
    mem = ca.SX.sym("mem", nm)       # the controller's memory
    uh = ca.SX.sym("uh", nd)         # u_{k-1}, ..., u_{k-d}
    r, e = ca.SX.sym("r"), ca.SX.sym("e")
    theta, scale = ca.SX.sym("theta", nth), ca.SX.sym("scale", nth)
    fixed, mass = ca.SX.sym("fixed", len(space.fixed)), ca.SX.sym("mass")
    pp = units(theta, scale, fixed, mass)
    u, mem1 = _controller(loop, y[0], mem, r, e)
    if math.isfinite(loop.limit):
        u = ca.fmin(ca.fmax(u, -loop.limit), loop.limit)
    applied = uh[nd - 1] if nd else u
    y1 = step(ca.vertcat(y, s), applied, applied, loop.dt, pp)
    cont = ca.vertcat(y, mem, uh)
    cont1 = ca.vertcat(y1[:ny], *mem1, *([u] + [uh[j] for j in range(nd - 1)] if nd else []))
    S = ca.SX.sym("S", cont.numel(), nth)
    S1 = ca.mtimes(ca.jacobian(cont1, cont), S) + ca.jacobian(cont1, theta)
    out = ca.vertcat(y[0], u)
    dout = ca.mtimes(ca.jacobian(out, cont), S) + ca.jacobian(out, theta)
    c = ca.vertcat(cont, s, ca.vec(S))
    c1 = ca.vertcat(cont1, y1[ny], ca.vec(S1))
    f = ca.Function("loop_step", [c, ca.vertcat(r, e), theta, scale, fixed, mass],
                    [c1, ca.vertcat(out, ca.vec(dout.T))])
    return f, cont.numel()


class _Simulator:
    """The record-long loop simulation with sensitivities (cached per model structure)."""

    def __init__(self, model: FrictionModel, loop: DigitalLoop, space: Any, n: int, n_sub: int,
                 mass_free: bool) -> None:
        key = (model.structure_key(), loop, tuple(space.free), tuple(space.fixed), n_sub, mass_free,
               n >= COMPILE_FROM)
        if key not in _CACHE:
            from prefriction.simulation.compiled import compiled
            f, nc = _loop_function(model, loop, space, n_sub, mass_free)
            # compiling costs about 10 s once per structure and saves about 150 us a sample per evaluation
            _CACHE[key] = (compiled(f, "closed-loop fit step")[0] if n >= COMPILE_FROM else f, nc)
        f, self.nc = _CACHE[key]
        self.acc = f.mapaccum("loop_record", n)
        self.model, self.loop, self.space, self.n = model, loop, space, n

    def run(self, theta: np.ndarray, x0: float, r: np.ndarray, e: np.ndarray, mass: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Simulated positions and forces at every sample and their derivatives in ``theta``."""
        vals = self.space.values(theta)
        start = self.space.build(vals)
        z0, m0 = start.initial_state(0.0, 1.0)
        nd, nth = self.loop.delay, self.space.n_free
        cont = np.concatenate(([x0, 0.0], np.asarray(z0, dtype=float), np.asarray(m0, dtype=float),
                               _memory(self.loop, x0), np.zeros(nd)))
        c0 = np.concatenate((cont, [1.0], np.zeros(self.nc * nth)))
        _, O = self.acc(c0, np.vstack((r, e)), theta, self.space.scale, self.space.fixed_values(), mass)
        O = np.asarray(O)
        return O[0], O[1], O[2:2 + nth].T, O[2 + nth:2 + 2 * nth].T


def _series(name: str, value: Any, n: int, unit: str) -> np.ndarray:
    """A finite 1-D array of ``n`` samples, or a ValueError naming it."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite [{unit}] with one value per sample ({n}), got shape {arr.shape}")
    return arr


def _check_spacing(t: np.ndarray, loop: DigitalLoop) -> None:
    dts = np.diff(t)
    if dts.size == 0 or np.max(np.abs(dts - loop.dt)) > 1e-3 * loop.dt:
        raise ValueError(f"the sample interval of t ({dts.min(initial=0.0):.6g} to {dts.max(initial=0.0):.6g} s) "
                         f"is not loop.dt = {loop.dt!r} s")


def simulate_closed_loop(model: FrictionModel, loop: DigitalLoop, t: Any, r: Any, *, mass: float, offset: float = 0.0,
                         x0: float | None = None, extra: Any = None, substeps: int = 2
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Positions [m] and forces [N] of ``model`` on a mass in ``loop`` following the reference ``r``.

    Parameters
    ----------
    model : FrictionModel
        Friction of the stage (started on a virgin branch at zero force).
    loop : DigitalLoop
        The controller.
    t, r : array_like
        Sample times [s] (spaced ``loop.dt``) and reference positions [m].
    mass : float
        Moving mass [kg].
    offset : float, default 0.0
        Force offset [N] (``m x'' + F + offset = u``).
    x0 : float, optional
        Initial position [m] (at rest); default ``r[0]``.
    extra : array_like, optional
        Force [N] added to the controller's output at each sample.
    substeps : int, default 2
        Runge-Kutta sub-steps per sample (1 to 64).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Positions and forces at every sample.
    """
    from prefriction.identify.parameters import ParameterSpace

    if not isinstance(loop, DigitalLoop):
        raise TypeError(f"loop must be a DigitalLoop (the known controller), got {type(loop).__name__}")
    t = np.asarray(t, dtype=float)
    r = _series("r", r, t.size, "m")
    _check_spacing(t, loop)
    e = np.zeros_like(r) if extra is None else _series("extra", extra, t.size, "N")
    space = ParameterSpace(model, [], None, None, offset=1.0)   # the offset the only column: values only
    sim = _Simulator(model, loop, space, r.size, check_count("substeps", substeps, 1, 64), False)
    theta = space.theta0.copy()
    theta[space.free.index("offset")] = offset
    x, u, _, _ = sim.run(theta, float(r[0] if x0 is None else x0), r, e, check_positive("mass", mass))
    return x, u


def _loop_substeps(model: FrictionModel, data: Motion, mass: float, requested: int | None) -> int:
    """RK4 sub-steps per sample: ``requested`` (checked), or the Motion fit's step rule
    (:func:`prefriction.identify.shooting._substeps`) at the start values and the record's
    finite-difference velocity, at least 2 (2 for a model without a friction state)."""
    if requested is not None:
        return check_count("substeps", requested, 1, 64)
    if not model.n_states:
        return 2
    from prefriction.identify.shooting import _substeps

    v = np.gradient(np.asarray(data.x, dtype=float), np.asarray(data.t, dtype=float))
    return max(2, _substeps(model, data, mass, v, None))


def _require_finite(dx: np.ndarray, du: np.ndarray, t: np.ndarray, theta: np.ndarray, space: Any,
                    n_sub: int) -> None:
    """Raise :class:`SolverError` where the loop's sensitivities stop being finite (an RK4 step
    outside its stability region for the model's fastest rate at ``theta``)."""
    bad = ~(np.isfinite(dx).all(axis=1) & np.isfinite(du).all(axis=1))
    if bad.any():
        k = int(np.argmax(bad))
        vals = space.values(theta)
        raise SolverError(f"fit_closed_loop: the loop's sensitivities are not finite from sample {k} "
                          f"(t = {t[k]:.6g} s) at {', '.join(f'{n} = {vals[n]:.6g}' for n in space.free)}: "
                          f"{n_sub} RK4 sub-steps per sample are too coarse for the friction state's fastest "
                          f"rate there; give substeps= larger (up to 64), or start nearer the data")


def fit_closed_loop(model: FrictionModel, data: Motion, loop: DigitalLoop, reference: Any, *, offset: bool = True,
                    extra: Any = None, free: Sequence[str] | None = None, fixed: Sequence[str] | None = None,
                    bounds: dict | None = None, mass0: float | None = None, offset0: float = 0.0,
                    forces: bool = True, substeps: int | None = None, max_iter: int = 100, tol: float = 1e-8,
                    identifiability_limit: float = 0.5, recorded: bool = True) -> FitResult:
    """Fit a friction model (and mass, offset) to a closed-loop record by simulating the loop.

    Parameters
    ----------
    model : FrictionModel
        The friction model; its values are the start values (as given; see
        :func:`prefriction.identify.inverse.inverse_start` for start values from the record).
    data : Motion
        Measured positions [m] and the recorded controller force [N]; ``data.mass`` known holds
        the mass, ``None`` fits it (``mass0`` its start).
    loop : DigitalLoop
        The known controller (1).
    reference : array_like
        Reference positions [m] at the samples.
    offset : bool, default True
        Fit the force offset ``"offset"`` [N] (started at ``offset0``).
    extra : array_like, optional
        Recorded force [N] added to the controller's output (pulses).
    free, fixed, bounds :
        As :func:`prefriction.identify.fit`.
    mass0 : float, optional
        Start of a fitted mass [kg] (required when ``data.mass`` is None).
    offset0 : float, default 0.0
        Start of the offset [N].
    forces : bool, default True
        Fit the recorded forces too (both channels weighted by their residual spread).
    substeps : int, optional
        Runge-Kutta sub-steps per sample (1 to 64). Default: the Motion fit's step rule at the
        start values and the record's top speed (at least 2), so that the friction state's fastest
        decay stays inside RK4's stability region (LuGre sliding at ``|v|`` relaxes at
        ``sigma0 |v| / g(v)``); refined after the fit while halving the step moves an estimate.
    max_iter : int, default 100
        Most solver evaluations (per pass; two passes).
    tol : float, default 1e-8
        Solver tolerance.
    identifiability_limit : float, default 0.5
        Relative standard error above which a parameter is reported as not identifiable.
    recorded : bool, default True
        Run stage 2 (the stage driven by the recorded force) after the loop fit; ``False`` keeps
        the loop fit's estimates.

    Returns
    -------
    FitResult
        Estimates with 95 % intervals (Newey-West, plus the encoder's rounding covariance when
        ``data.quantum`` is declared); ``fitted`` the simulated positions, ``residuals`` the
        position residuals [m]; ``nuisance["force"]`` the simulated forces (the recorded ones
        after stage 2); ``notes`` say which stage gave the estimates.

    Warns
    -----
    ConvergenceWarning
        If stage 2 was not kept (the estimates are the loop fit's), or the solver stopped
        without converging.

    Raises
    ------
    TypeError, ValueError
        For arguments of the wrong kind or out of range (named).
    """
    from prefriction.identify.parameters import ParameterSpace, name_list
    from scipy.optimize import least_squares

    if not isinstance(model, FrictionModel):
        raise TypeError(f"model must be a prefriction.FrictionModel, got {type(model).__name__}")
    if not isinstance(data, Motion):
        raise TypeError(f"data must be prefriction.identify.Motion, got {type(data).__name__}")
    check_solver(max_iter, tol, identifiability_limit)
    if not isinstance(loop, DigitalLoop):
        raise TypeError(f"loop must be a DigitalLoop (the known controller), got {type(loop).__name__}")
    r = _series("reference", reference, data.t.size, "m")
    _check_spacing(data.t, loop)
    if data.mass is None and mass0 is None:
        raise ValueError("data.mass is None: give mass0 (e.g. from identify.inverse.inverse_start)")
    e = np.zeros_like(r) if extra is None else _series("extra", extra, data.t.size, "N")
    fscale = max(float(np.std(data.u)), 1e-300)
    space = ParameterSpace(model, name_list("free", free), name_list("fixed", fixed), bounds,
                           mass=mass0 if data.mass is None else None, offset=fscale if offset else None)
    n_sub = _loop_substeps(model, data, mass0 if data.mass is None else float(data.mass), substeps)
    sim = _Simulator(model, loop, space, data.t.size, n_sub, data.mass is None)
    theta0 = space.theta0.copy()
    if offset:
        theta0[space.free.index("offset")] = offset0 / fscale
    mass = float(data.mass) if data.mass is not None else 0.0
    x0, xm, um = float(data.x[0]), data.x, data.u
    lo, hi = space.theta_bounds()

    def solve(run: Any, theta: np.ndarray, w: list[float], both: bool, shift: bool = False) -> tuple[Any, Any, Any]:
        """One least-squares fit of the simulation ``run(theta) -> (x, u, dx, du)`` to the record's first
        ``x.size`` samples; ``shift``: the initial position free (profiled out of the positions)."""
        memo: dict[bytes, tuple[np.ndarray, ...]] = {}

        def channels(th: np.ndarray) -> tuple[np.ndarray, ...]:
            key = np.asarray(th, dtype=float).tobytes()
            if key not in memo:   # the solver asks the Jacobian where it evaluated the residuals
                memo.clear()
                x, u, dx, du = run(th)
                _require_finite(dx, du, data.t, th, space, n_sub)
                rx = x - xm[:x.size]
                if shift:   # an open-loop replay from x0 + c is the replay from x0 plus c
                    rx, dx = rx - rx.mean(), dx - dx.mean(axis=0)
                memo[key] = (rx, u - um[:x.size], dx, du)
            return memo[key]

        def res(th: np.ndarray) -> np.ndarray:
            a, b, _, _ = channels(th)
            return np.concatenate((a / w[0], b / w[1])) if both else a / w[0]

        def jac(th: np.ndarray) -> np.ndarray:
            _, _, dx, du = channels(th)
            return np.vstack((dx / w[0], du / w[1])) if both else dx / w[0]

        with one_blas_thread():
            sol = least_squares(res, theta, jac=jac, bounds=(lo, hi), method="trf", x_scale=1.0, xtol=tol,
                                ftol=tol, gtol=tol, max_nfev=max_iter)
        return sol, channels, (res, jac)

    def spread(ch: Any, th: np.ndarray) -> list[float]:
        rx, ru, _, _ = ch(th)
        return [max(float(np.std(rx)), 1e-15), max(float(np.std(ru)), 1e-12)]

    # 1. the loop simulated with the model's own positions (drift-free from rough starts)
    loop_run = lambda th: sim.run(th, x0, r, e, mass)   # noqa: E731
    xs0, us0, _, _ = loop_run(theta0)
    w = [max(float(np.std(xs0 - xm)), 1e-15), max(float(np.std(us0 - um)), 1e-12)]
    theta, sol = theta0, None
    for _ in range(2):   # weights from the start, then from the first fit
        sol, ch, fns = solve(loop_run, theta, w, forces)
        theta = sol.x
        w = spread(ch, theta)
    route, both, steps = "loop", forces, [f"the loop simulated on its own positions: {sol.message}"]
    # 2. the stage driven by the recorded force (the force the controller computed from the encoder)
    if recorded:
        free_loop = DigitalLoop(loop.dt, delay=loop.delay)
        rms_l = float(np.sqrt(np.mean(ch(theta)[0] ** 2)))

        def replay_fit(th: np.ndarray) -> tuple[Any, Any, Any]:
            n_all = data.t.size
            for n in sorted({min(max(n_all // 2 ** j, 200), n_all) for j in range(3, -1, -1)}):
                # continuation over the record's length: a replay drifts more the longer it runs from a start
                opened = _Simulator(model, free_loop, space, n, n_sub, data.mass is None)
                out = solve(lambda t_, o=opened, n=n: o.run(t_, x0, r[:n], um[:n], mass), th, w, False, True)
                th = out[0].x
            return out

        why = ""
        for origin, th in (("the loop fit's estimates", theta), ("the start values", theta0)):
            sol_o, ch_o, fns_o = replay_fit(th)
            rms_o = float(np.sqrt(np.mean(ch_o(sol_o.x)[0] ** 2)))
            if sol_o.status > 0 and rms_o <= rms_l + 1e-9 * float(np.ptp(xm)):   # (a round-off's slack)
                theta, sol, ch, fns, route, both = sol_o.x, sol_o, ch_o, fns_o, "recorded", False
                steps.append(f"the stage driven by the recorded force, from {origin}: {sol.message}")
                k_sub = n_sub
                while k_sub < 64:   # sub-steps fine enough that halving them moves no estimate
                    fine = _Simulator(model, free_loop, space, data.t.size, 2 * k_sub, data.mass is None)
                    run = lambda t_, f=fine: f.run(t_, x0, r, um, mass)   # noqa: E731
                    J = fns[1](theta)
                    shift = step_shift(J, fns[0](theta), (run(theta)[0] - xm) / w[0], centred=True)
                    if shift <= STEP_SHIFT:
                        break
                    k_sub *= 2
                    sol, ch, fns = solve(run, theta, w, False, True)
                    theta = sol.x
                    steps.append(f"{k_sub} sub-steps per sample (halving the step moved an estimate by {shift:.2g} "
                                 f"standard errors): {sol.message}")
                break
            why += (f"; from {origin}: " + (sol_o.message if not sol_o.status > 0 else
                                           f"position residuals of rms {rms_o:.3g} m, more than the loop's "
                                           f"{rms_l:.3g} m"))
        else:
            steps.append(f"the stage driven by the recorded force not kept{why}: the record's force does not "
                         f"carry its motion (or the loop fit is far off); the estimates and intervals are the "
                         f"loop simulation's, which does not see the encoder's rounding")
            warnings.warn(f"fit_closed_loop: {steps[-1]}", ConvergenceWarning, stacklevel=2)
    res, jac = fns
    rx, ru, _, _ = ch(theta)
    rr, vals, names = res(theta), space.values(theta), list(space.free)
    est = np.array([vals[n] for n in names])   # physical values: Fs, not its excess over Fc; z_ba, not its fraction
    J, scale = space.physical_jacobian(jac(theta), theta)
    stats = gauss_newton(J, rr, names, est, scale, limit=identifiability_limit)
    stats, lag = sandwich(J, rr, stats, est, scale, channels=2 if both else 1, names=names,
                          limit=identifiability_limit)
    if route == "recorded" and data.quantum == 0.0 and (q := grid_step(xm)) > 0.0:
        warnings.warn(f"the positions lie on a grid of {q:.3g} m (an encoder) that data does not declare: the "
                      f"intervals leave out the rounding error that samples at the same place on the grid share; "
                      f"declare it, Motion(..., quantum={q:.3g}, x_noise=...) (docs/identify_closed_loop.md)",
                      NoisyPositionsWarning, stacklevel=2)
    if route == "recorded" and data.quantum > 0.0:   # the rounding error shared by samples on the same grid place
        W = np.linalg.pinv(J.T @ J) @ J.T * (scale[:, None] / w[0])
        stats = widened(stats, rounding_covariance(W, rx + xm, float(data.x_noise), float(data.quantum)), est)
    for name, reason in stats.unidentifiable:
        warnings.warn(f"the data cannot identify {name}: {reason}; fix it or excite it", IdentifiabilityWarning,
                      stacklevel=2)
    lows, highs = space.limits(vals)
    floor = {hi: max(float(stats.low[names.index(lo)]), lows[lo]) for hi, lo in space.excess.items()}
    low, high, flags = at_bounds(names, est, stats.low, stats.high, space.scale, lows, highs,
                                 {n: space.why_low.get(n, "the declared range") for n in names},
                                 {n: space.why_high.get(n, "the declared range") for n in names}, floor)
    if not sol.status > 0:
        warnings.warn(f"fit_closed_loop stopped without converging ({sol.message}); the estimates are its last: "
                      f"raise max_iter or start closer (identify.inverse_start)", ConvergenceWarning, stacklevel=2)
    fitted_mass = vals["mass"] if data.mass is None else float(data.mass)
    x_sim, u_sim = rx + xm, ru + um
    stats = dataclasses.replace(stats, sigma_hat=float(np.sqrt(np.sum(rx ** 2) / stats.dof)))
    kept = {"loop": f"the loop simulated on its own positions, fitted to positions{' and forces' if both else ''}"
                    f" with channel weights {w[0]:.3g} m and {w[1]:.3g} N",
            "recorded": "the stage driven by the recorded force, fitted to positions"}[route]
    notes = ("route: closed-loop output error", *steps,
             f"estimates and intervals: {kept} (the residual sd shown is of the positions; forces: rms "
             f"{np.sqrt(np.mean(ru ** 2)):.4g} N)", f"Newey-West standard errors, lag {lag}")
    return FitResult(space.build(vals), fitted_mass, tuple(names), tuple(space.units[n] for n in names), est,
                     stats.stderr, low, high, stats.correlation, xm - x_sim, x_sim, data, stats,
                     {"force": u_sim, "force_rms": float(np.sqrt(np.mean(ru ** 2)))},
                     f"least_squares: {sol.message}", success=bool(sol.status > 0), flags=flags, notes=notes)
