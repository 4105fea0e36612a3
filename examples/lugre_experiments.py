"""The simulation experiments of the LuGre paper, with :class:`prefriction.LuGre`.

C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, "A new model for control of systems
with friction", IEEE Trans. Automatic Control 40(3), 419-425, 1995. Parameters of the paper:
``sigma0 = 1e5 N/m``, ``sigma1 = sqrt(1e5) N s/m``, ``sigma2 = 0.4 N s/m``, ``Fc = 1 N``,
``Fs = 1.5 N``, ``vs = 1e-3 m/s``, unit mass ``m = 1 kg``.

1. ``lugre_presliding.png``: pre-sliding displacement. The applied force is ramped to
   ``0.95 Fs = 1.425 N`` in 10 s, held 5 s, ramped to ``-1.425 N`` in 20 s, held 5 s and ramped
   back to ``1.425 N`` in 20 s (``signals.Samples``); friction force against displacement [um].
   In the holds the mass comes to rest after a few damped reversals; the simulator's rest test
   (net force below the integration error of the net force) finds that rest, and the run stays
   within 1 rtol of the reference (displacement 0.66 rtol, force 0.43 rtol at rtol 1e-8;
   ``tests/test_lugre.py``).
2. ``lugre_friction_lag.png``: friction lag. The velocity is prescribed,
   ``v = 1e-3 (cos(w t) + 1.5) m/s`` for ``w = 1, 10, 25 rad/s``; the bristle state alone is
   integrated along it (CasADi ``cvodes`` on the model's own ``rate`` and ``force``, no mass);
   friction force against velocity over the second period, with the steady-state curve.
3. ``lugre_breakaway.png``: break-away force against the force rate. The applied force is
   ``u = rate * t`` (``signals.Ramp``) for rates 1-50 N/s; the break-away force is the first
   maximum of the friction force in time (where the mass breaks loose and the Stribeck drop
   begins).
4. ``lugre_stick_slip.png``: stick-slip. The mass is pulled through a spring ``k = 2 N/m``
   whose end moves at 0.1 m/s: ``u = k (0.1 t - x)`` is ``LinearFeedback(D=k)`` with the
   reference ``signals.Ramp(0, 0.1)``.
5. ``lugre_hunting.png``: hunting of a PID position loop, ``u = -Kv x' + Kp (1 - x) + Ki int (1 - x) dt``
   with ``Kp = 3 N/m``, ``Ki = 4 N/(m s)``, ``Kv = 6 N s/m``. The velocity feedback ``-Kv x'`` acts
   on the mass exactly as viscous friction, so the loop is a PI ``LinearFeedback`` around
   ``LuGre(sigma2 = 0.4 + Kv)`` (no derivative filter: the paper's loop exactly); the
   friction force shown is the LuGre force, ``F - Kv x'``.
6. ``lugre_work_precision.png`` (:func:`benchmark`): error against run time of
   :func:`prefriction.simulate` (``erk``) and of scipy's Radau, BDF and LSODA restarted at every
   reversal, on experiments 1, 3, 4 and 5.

Experiments 1, 3, 4 and 5 run through :func:`prefriction.simulate`, which locates every
velocity reversal (the kink of ``|v|``) and switches the LuGre branch there. All five are
checked against an independent scipy Radau reference in ``tests/test_lugre.py``. The numbers
of each figure, and how they compare with the paper's figures, are in ``docs/lugre.md``.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Any, Callable, Optional

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import signals
from prefriction.plotting import COLORS, add_note, new_figure, save

PARAMS = dict(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3)
"""Table I of the paper: [N/m], [N s/m], [N s/m], [N], [N], [m/s]."""
MASS = 1.0  # [kg]
RTOL = 1e-8  # tolerance of the simulations
F_PRE = 0.95 * PARAMS["Fs"]  # largest force of the pre-sliding experiment [N]
OMEGAS = (1.0, 10.0, 25.0)  # friction lag [rad/s]
RATES = (1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0)  # [N/s]
K_SPRING, V_PULL = 2.0, 0.1  # stick-slip [N/m], [m/s]
KP, KI, KV, X_SET = 3.0, 4.0, 6.0, 1.0  # hunting [N/m], [N/(m s)], [N s/m], [m]


def model(**changes: float) -> pf.LuGre:
    """The LuGre model of the paper (``changes`` replace parameters)."""
    return pf.LuGre(**{**PARAMS, **changes})


# ---------------------------------------------------------------------- experiment cases
class Case:
    """One forced experiment: the system for :func:`prefriction.simulate` and, for the scipy
    runs of :func:`benchmark`, the applied force ``u(t, y)`` on ``y = [x, v, z, extra...]`` (SI).

    ``extra(t, y)`` gives the derivatives of the extra states (an integrator), ``breaks`` the
    kinks of the input; ``kv`` is a velocity feedback folded into the model's viscous
    coefficient (hunting): the simulator's friction force includes ``kv v``.
    """

    def __init__(self, name: str, system: pf.Oscillator, t_end: float, *, feedback: Optional[pf.LinearFeedback] = None,
                 u: Callable[[float, np.ndarray], float] = lambda t, y: 0.0,
                 extra: Optional[Callable[[float, np.ndarray], list]] = None, y0: tuple = (0.0, 0.0, 0.0),
                 breaks: tuple = (), kv: float = 0.0) -> None:
        self.name, self.system, self.t_end, self.feedback = name, system, t_end, feedback
        self.u, self.extra, self.y0, self.breaks, self.kv = u, extra, y0, breaks, kv
        self.params = {k: getattr(system.friction, k) for k in PARAMS}  # for scipy: without the folded kv
        self.params["sigma2"] -= kv

    def simulate(self, times: np.ndarray, rtol: float = RTOL, **kw: Any) -> pf.SimulationResult:
        """:func:`prefriction.simulate` from rest (``x = 0``, ``F = 0``) with samples at ``times`` [s]."""
        return pf.simulate(self.system, 0.0, t_end=self.t_end, dense=times, rtol=rtol,
                           feedback=self.feedback, **kw)


def presliding_input(hold: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Samples ``(t [s], u [N])`` of the pre-sliding force: up to ``F_PRE`` in 10 s, down to
    ``-F_PRE`` in 20 s and up again in 20 s, with 5-s holds at the extremes if ``hold``."""
    h = 5.0 if hold else 0.0
    t = np.cumsum([0.0, 10.0, h, 20.0, h, 20.0])
    u = np.array([0.0, F_PRE, F_PRE, -F_PRE, -F_PRE, F_PRE])
    keep = np.concatenate([[True], np.diff(t) > 0])
    return t[keep], u[keep]


def presliding_case(hold: bool = True) -> Case:
    """Experiment 1: pre-sliding displacement under a force below break-away, reversed."""
    t, u = presliding_input(hold)
    return Case("pre-sliding" + ("" if hold else " (no holds)"), pf.Oscillator(model(), MASS, signals.Samples(t, u)),
                float(t[-1]), u=lambda tt, y: float(np.interp(tt, t, u)), breaks=tuple(t))


def breakaway_case(rate: float) -> Case:
    """Experiment 3: the applied force ``u = rate t`` [N], up to ``1.8 N`` (past the break-away)."""
    return Case(f"break-away {rate:g} N/s", pf.Oscillator(model(), MASS, signals.Ramp(0.0, rate)), 1.8 / rate,
                u=lambda tt, y: rate * tt)


def stick_slip_case(t_end: float = 20.0) -> Case:
    """Experiment 4: the spring ``u = k (V_PULL t - x)`` as the feedback ``D = k``, reference ``V_PULL t``."""
    fb = pf.LinearFeedback(D=K_SPRING, reference=signals.Ramp(0.0, V_PULL))
    return Case("stick-slip", pf.Oscillator(model(), MASS), t_end, feedback=fb,
                u=lambda tt, y: K_SPRING * (V_PULL * tt - y[0]))


def hunting_case(t_end: float = 100.0) -> Case:
    """Experiment 5: PI feedback on ``LuGre(sigma2 + Kv)`` (the ``-Kv x'`` term as viscous friction).

    For scipy (:func:`scipy_run`) the paper's loop as written: ``y[3] = int (X_SET - x) dt``.
    """
    fb = pf.LinearFeedback(A=[[0.0]], B=[[1.0]], C=[[KI]], D=KP, reference=X_SET)
    return Case("hunting", pf.Oscillator(model(sigma2=PARAMS["sigma2"] + KV), MASS), t_end, feedback=fb,
                u=lambda tt, y: KP * (X_SET - y[0]) + KI * y[3] - KV * y[1],
                extra=lambda tt, y: [X_SET - y[0]], y0=(0.0, 0.0, 0.0, 0.0), kv=KV)


# ---------------------------------------------------------------------- experiments
def presliding(*, hold: bool = True, rtol: float = RTOL, n: int = 6001) -> dict:
    """Experiment 1 through :func:`prefriction.simulate`: samples ``t, u, x, F`` [s, N, m, N]."""
    case = presliding_case(hold)
    t = np.linspace(0.0, case.t_end, n)
    res = case.simulate(t, rtol)
    tu, uu = presliding_input(hold)
    return {"t": res.t, "u": np.interp(res.t, tu, uu), "x": res.x, "v": res.v, "F": res.F, "result": res}


def friction_lag(omegas: tuple = OMEGAS, *, n: int = 2000, rtol: float = 1e-10) -> dict:
    """Experiment 2: the LuGre state along the prescribed velocity ``1e-3 (cos(w t) + 1.5)`` m/s.

    CasADi ``cvodes`` on the model's own :meth:`~prefriction.LuGre.rate` and
    :meth:`~prefriction.LuGre.force` (normalised units, direction ``s = +1``: the velocity stays
    positive), from ``z = 0`` over two periods. Returns ``{w: {"t", "v", "F"}}`` [s, m/s, N] for
    the second period.
    """
    lg = model()
    sc = pf.Scales.of(pf.Oscillator(lg, MASS))  # units; the mass cancels in F(t)
    q = lg.runtime_params_for(sc)
    zeta, t, w = ca.SX.sym("zeta"), ca.SX.sym("t"), ca.SX.sym("w")
    v = 1e-3 * (ca.cos(w * t) + 1.5) / sc.v  # normalised velocity
    rate = lg.rate([zeta], [], v, 1.0, q)[0] / sc.t  # d zeta / dt [1/s]
    Ffun = ca.Function("F", [zeta, t, w], [lg.force([zeta], [], v, 1.0, q) * sc.F])
    out = {}
    for om in omegas:
        T = 2.0 * math.pi / om
        grid = np.linspace(T, 2.0 * T, n)
        opts = {"reltol": rtol, "abstol": rtol * 1e-2}
        integ = ca.integrator("lag", "cvodes", {"x": zeta, "t": t, "p": w, "ode": rate}, 0.0, grid, opts)
        z = np.array(integ(x0=0.0, p=om)["xf"]).ravel()
        out[om] = {"t": grid, "v": 1e-3 * (np.cos(om * grid) + 1.5), "F": np.array(Ffun(z, grid, om)).ravel()}
    return out


def loop_width(v: np.ndarray, F: np.ndarray, v_at: float = 1.5e-3) -> float:
    """Width of a friction-lag loop [N]: the friction force at ``v_at`` while the velocity
    rises minus that while it falls (one period of samples, increasing time); positive when the
    friction lags the velocity."""
    dv = np.gradient(v)
    up, down = dv > 0, dv < 0
    o_up, o_dn = np.argsort(v[up]), np.argsort(v[down])
    return float(np.interp(v_at, v[up][o_up], F[up][o_up]) - np.interp(v_at, v[down][o_dn], F[down][o_dn]))


def peak(t: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """Time and value of the first local maximum of the samples ``F`` (the largest sample if
    there is none), refined by the parabola through it and its neighbours."""
    rise = np.diff(F)
    first = np.flatnonzero((rise[:-1] > 0) & (rise[1:] <= 0))
    k = int(first[0] + 1) if first.size else int(np.clip(np.argmax(F), 1, len(F) - 2))
    y0, y1, y2 = F[k - 1], F[k], F[k + 1]
    den = y0 - 2.0 * y1 + y2
    d = 0.5 * (y0 - y2) / den if den < 0 else 0.0
    h = t[k + 1] - t[k]
    return float(t[k] + d * h), float(y1 - 0.25 * (y0 - y2) * d)


def breakaway(rates: tuple = RATES, *, rtol: float = RTOL, n: int = 4001) -> dict:
    """Experiment 3: the break-away force [N] for each force rate [N/s]: the first maximum of
    the friction force in time (:func:`peak`), where the mass breaks loose and the Stribeck drop
    begins. From about 35 N/s on there is no stiction peak: the friction rises to about ``Fc``
    and the first maximum (1.001-1.008 N) is a small overshoot of the sliding friction.

    Returns ``rates``, ``F_break`` [N], ``t_break`` [s], ``u_break`` (applied force there) [N] and
    the samples ``runs[rate]`` (dicts of ``t, x, v, F``).
    """
    F_b, t_b, runs = [], [], {}
    for rate in rates:
        case = breakaway_case(rate)
        res = case.simulate(np.linspace(0.0, case.t_end, n), rtol)
        tp, Fp = peak(res.t, res.F)
        F_b.append(Fp)
        t_b.append(tp)
        runs[rate] = {"t": res.t, "x": res.x, "v": res.v, "F": res.F}
    t_b = np.array(t_b)
    return {"rates": np.array(rates, dtype=float), "F_break": np.array(F_b), "t_break": t_b,
            "u_break": np.array(rates) * t_b, "runs": runs}


def stick_slip(t_end: float = 20.0, *, rtol: float = RTOL, n: int = 4001) -> dict:
    """Experiment 4: samples ``t, x, y`` (spring end), ``v, F`` and the spring force ``u``."""
    case = stick_slip_case(t_end)
    res = case.simulate(np.linspace(0.0, t_end, n), rtol)
    return {"t": res.t, "x": res.x, "y": V_PULL * res.t, "v": res.v, "F": res.F, "u": res.u, "result": res}


def hunting(t_end: float = 100.0, *, rtol: float = RTOL, n: int = 4001) -> dict:
    """Experiment 5: samples ``t, x, v``, the LuGre friction force ``F`` and the controller force
    ``u`` (PI part plus ``-Kv v``)."""
    case = hunting_case(t_end)
    res = case.simulate(np.linspace(0.0, t_end, n), rtol)
    return {"t": res.t, "x": res.x, "v": res.v, "F": res.F - KV * res.v, "u": res.u - KV * res.v,
            "xi": res.xc[:, 0], "result": res}


def hunting_cycle(t: np.ndarray, x: np.ndarray, t_from: float) -> tuple[float, float, float]:
    """Period [s] and extremes [m] of the hunting cycle after ``t_from``: the period from the
    mean spacing of the upward crossings of the set point."""
    sel = t >= t_from
    tt, xx = t[sel], x[sel] - X_SET
    k = np.flatnonzero((xx[:-1] < 0) & (xx[1:] >= 0))
    t_up = tt[k] - xx[k] * (tt[k + 1] - tt[k]) / (xx[k + 1] - xx[k])
    period = float(np.mean(np.diff(t_up))) if len(t_up) > 1 else math.nan
    return period, float(np.min(x[sel])), float(np.max(x[sel]))


# ---------------------------------------------------------------------- scipy with restarts
def scipy_run(case: Case, times: np.ndarray, method: str = "Radau", rtol: float = 1e-10,
              scale: tuple = (1.0, 1.0), rest_tol: float = 1e-12) -> dict:
    """The experiment ``case`` by scipy ``solve_ivp(method)`` in SI, restarted at every velocity
    reversal (and at the breaks of the input), on the branch ``|v| = s v`` in between.

    At a zero of ``v`` the direction follows the net force ``u - sigma0 z``; if that is below
    ``rest_tol Fc`` the mass rests (``x, v, z`` frozen) until it exceeds it. ``scale`` = typical
    ``(|x|, |v|)`` for the absolute tolerances (``atol = rtol * scale``). Returns ``x, v, F``
    at ``times`` (``F`` without the folded ``kv v``), the reversals ``(t, x, F)``, ``nfev``.
    ``RuntimeError`` if the solver fails or makes no progress (its first step after a restart
    turns back again and again, as BDF does at loose tolerances in the hunting loop).
    """
    p = case.params
    s0, s1, s2, Fc, Fs, vs = (p[k] for k in ("sigma0", "sigma1", "sigma2", "Fc", "Fs", "vs"))
    m, u, extra = case.system.mass, case.u, case.extra
    y = np.array(case.y0, dtype=float)
    n = y.size
    atol = rtol * np.array([scale[0], scale[1], Fs / s0] + [scale[0] * case.t_end] * (n - 3))
    tol = rest_tol * Fc

    def branch(y: np.ndarray, s: float) -> tuple[float, float]:
        v, z = y[1], y[2]
        zd = v - s0 * s * v * z / (Fc + (Fs - Fc) * math.exp(-(v / vs) ** 2))
        return zd, s0 * z + s1 * zd + s2 * v

    def extras(t: float, y: np.ndarray) -> list:
        return list(extra(t, y)) if extra is not None else []

    t, stalls = 0.0, 0
    out = np.full((n, len(times)), np.nan)
    revs, nfev = [], 0
    a0 = u(0.0, y) - s0 * y[2]
    s = math.copysign(1.0, y[1] if y[1] != 0.0 else a0)
    rest = y[1] == 0.0 and abs(a0) <= tol
    for stop in sorted(b for b in case.breaks if 0.0 < b < case.t_end) + [case.t_end]:
        while t < stop:
            if rest:
                def rhs(tt: float, yy: np.ndarray) -> list:
                    return [0.0, 0.0, 0.0] + extras(tt, yy)

                def event(tt: float, yy: np.ndarray) -> float:
                    return tol - abs(u(tt, yy) - s0 * yy[2])
            else:
                def rhs(tt: float, yy: np.ndarray, s: float = s) -> list:
                    zd, F = branch(yy, s)
                    return [yy[1], (u(tt, yy) - F) / m, zd] + extras(tt, yy)

                def event(tt: float, yy: np.ndarray, s: float = s) -> float:
                    return s * yy[1] + 1e-300  # positive at the start of the branch (v = 0)
            event.terminal, event.direction = True, -1.0
            try:
                sol = solve_ivp(rhs, (t, stop), y, method=method, rtol=rtol, atol=atol, events=[event],
                                dense_output=True)
            except ValueError as exc:  # event root finding on an inconsistent dense output (LSODA)
                raise RuntimeError(f"{method} failed at t = {t} s: {exc}") from None
            nfev += sol.nfev
            if sol.status < 0:
                raise RuntimeError(f"{method} failed at t = {t}: {sol.message}")
            hit = sol.status == 1
            t_last = float(sol.t_events[0][0]) if hit else float(sol.t[-1])
            k = np.flatnonzero((times >= t) & (times <= t_last))
            if k.size:
                out[:, k] = sol.sol(times[k])
            if not hit:
                t, y = stop, sol.y[:, -1].copy()
                continue
            stalls = stalls + 1 if t_last <= t + 1e-14 * case.t_end else 0
            if stalls > 20:  # the solver's first step keeps turning back: no progress
                raise RuntimeError(f"{method} makes no progress at t = {t} s (rtol {rtol:g})")
            t, y = t_last, np.array(sol.y_events[0][0], dtype=float)
            a = u(t, y) - s0 * y[2]
            if rest:  # leaves the rest in the direction of the net force
                rest, new = False, math.copysign(1.0, a)
            else:  # v = 0: a reversal, or rest if the net force vanishes
                y[1] = 0.0
                rest = abs(a) <= tol
                new = s if rest else math.copysign(1.0, a)
            if new != s:
                revs.append((t, y[0], s0 * y[2]))
                s = new
    F = np.array([branch(out[:, j], 1.0 if out[1, j] >= 0 else -1.0)[1] for j in range(len(times))])
    return {"t": np.asarray(times), "x": out[0], "v": out[1], "F": F, "reversals": np.array(revs).reshape(-1, 3),
            "nfev": nfev}


def motion_error(ref: dict, x: np.ndarray, v: np.ndarray, F: np.ndarray, system: pf.Oscillator) -> float:
    """Largest error of ``x, v, F`` against ``ref`` in the simulator's norm: ``x`` relative to
    the largest ``|x|``, ``v`` and ``F`` relative to the amplitude of the motion, the largest
    ``hypot(v / V, F / Fc)`` with the velocity unit ``V = Fc / sqrt(m sigma0)``."""
    sc = pf.Scales.of(system)
    amp = float(np.max(np.hypot(ref["v"] / sc.v, ref["F"] / sc.F)))
    ex = np.max(np.abs(x - ref["x"])) / np.max(np.abs(ref["x"]))
    ev = np.max(np.abs(v - ref["v"])) / sc.v / amp
    eF = np.max(np.abs(F - ref["F"])) / sc.F / amp
    return float(max(ex, ev, eF))


def benchmark(*, quick: bool = False, rtols: Optional[tuple] = None, repeat: int = 3,
              log: Callable[[str], None] = lambda s: None) -> dict:
    """Error against run time: :func:`prefriction.simulate` (``erk``, compiled, warm) and scipy
    Radau, BDF, LSODA with restarts at the reversals, against Radau at ``rtol = 1e-12``.

    Cases: pre-sliding without holds (50 s), break-away at 10 N/s, stick-slip (20 s), hunting
    (30 s). Returns ``{case: {solver: [(rtol, seconds, error), ...]}}``; the error is
    :func:`motion_error` at 1001 samples, the time the best of ``repeat`` calls.
    """
    cases = [presliding_case(hold=False), breakaway_case(10.0), stick_slip_case(20.0), hunting_case(30.0)]
    scales = {cases[0].name: (5e-5, 3e-5), cases[1].name: (1e-4, 1e-2), cases[2].name: (1.0, 0.3),
              cases[3].name: (1.0, 0.3)}
    if quick:
        cases = cases[1:3]
    rtols = rtols or ((1e-5, 1e-7, 1e-9) if quick else (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10))
    table: dict = {}
    for case in cases:
        times = np.linspace(0.0, case.t_end, 1001)
        ref = scipy_run(case, times, "Radau", 1e-12, scales[case.name])
        ref_F = ref["F"] + case.kv * ref["v"]  # the simulator's friction force includes kv v
        ref_cmp = {**ref, "F": ref_F}
        rows: dict = {"simulate (erk)": []}
        for rtol in rtols:
            case.simulate(times, rtol)  # compile / warm up
            best, res = math.inf, None
            for _ in range(repeat):
                start = time.perf_counter()
                res = case.simulate(times, rtol)
                best = min(best, time.perf_counter() - start)
            rows["simulate (erk)"].append((rtol, best, motion_error(ref_cmp, res.x, res.v, res.F, case.system)))
        for method in ("Radau", "BDF", "LSODA"):
            rows[method] = []
            for rtol in rtols:
                start = time.perf_counter()
                try:
                    run = scipy_run(case, times, method, rtol, scales[case.name])
                except RuntimeError:
                    continue
                sec = time.perf_counter() - start
                err = motion_error(ref_cmp, run["x"], run["v"], run["F"] + case.kv * run["v"], case.system)
                rows[method].append((rtol, sec, err))
        table[case.name] = rows
        for solver, pts in rows.items():
            log(f"{case.name:28s} {solver:15s} " + "  ".join(f"{r:.0e}:{s * 1e3:.0f}ms/{e:.1e}" for r, s, e in pts))
    return table


# ---------------------------------------------------------------------- figures
def _fig_presliding(outdir: Path, d: dict) -> Path:
    fig, axes = new_figure(1, 2, size=(12.0, 4.6))
    ax = axes[0, 0]
    ax.plot(d["x"] * 1e6, d["F"], color=COLORS[0], lw=1.5, label="friction force $F$")
    ax.plot(d["x"] * 1e6, d["u"], color=COLORS[1], lw=1.0, ls="--", label="applied force $u$")
    ax.set_xlabel(r"displacement $x$ [$\mu$m]")
    ax.set_ylabel("force [N]")
    ax.set_title("pre-sliding displacement: force below break-away, reversed", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax = axes[0, 1]
    ax.plot(d["t"], d["x"] * 1e6, color=COLORS[0], lw=1.5, label="displacement $x$")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel(r"displacement $x$ [$\mu$m]")
    ax.grid(True, alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(d["t"], d["u"], color=COLORS[1], lw=1.0, ls="--", label="applied force $u$")
    ax2.set_ylabel("applied force $u$ [N]")
    ax2.set_ylim(-1.6, 3.0)
    ax.set_ylim(np.min(d["x"]) * 1e6 - 2.0, np.max(d["x"]) * 1e6 + 0.6 * np.ptp(d["x"]) * 1e6)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper center", fontsize=8, ncol=2)
    ax.set_title("displacement and applied force over time", fontsize=10)
    add_note(fig, f"m = {MASS:g} kg; force ramped to 0.95 Fs = {F_PRE:g} N, held 5 s, to -{F_PRE:g} N, held, back; "
                  f"prefriction.simulate (rtol {RTOL:g}), every reversal located.")
    return save(fig, outdir, "lugre_presliding.png")


def _fig_lag(outdir: Path, lag: dict) -> Path:
    fig, axes = new_figure(1, 1, size=(7.5, 5.0))
    ax = axes[0, 0]
    for c, (om, d) in zip(COLORS, lag.items()):
        ax.plot(d["v"] * 1e3, d["F"], color=c, lw=1.5,
                label=rf"$\omega$ = {om:g} rad/s (loop width {loop_width(d['v'], d['F']) * 1e3:.0f} mN at 1.5 mm/s)")
    vv = np.linspace(0.4e-3, 2.6e-3, 300)
    ax.plot(vv * 1e3, model().steady_force(vv), color="0.3", ls="--", lw=1.0, label="steady state $g(v) + \\sigma_2 v$")
    ax.set_xlabel(r"velocity $v$ [mm/s]")
    ax.set_ylabel("friction force $F$ [N]")
    ax.set_title("friction lag: prescribed $v = 10^{-3}(\\cos\\omega t + 1.5)$ m/s", fontsize=10)
    ax.grid(True, alpha=0.3)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.45 * (hi - lo))
    ax.legend(loc="upper right", fontsize=8)
    add_note(fig, "Prescribed motion: the bristle state alone, CasADi cvodes (rtol 1e-10) on LuGre.rate/force; "
                  "second period shown (from z = 0).")
    return save(fig, outdir, "lugre_friction_lag.png")


def _fig_breakaway(outdir: Path, b: dict) -> Path:
    fig, axes = new_figure(1, 2, size=(12.0, 4.6))
    ax = axes[0, 0]
    ax.plot(b["rates"], b["F_break"], "o-", color=COLORS[0], lw=1.3, ms=4, label="first maximum of $F(t)$")
    ax.axhline(PARAMS["Fs"], color="0.5", ls=":", lw=1.0, label="$F_s$")
    ax.axhline(PARAMS["Fc"], color="0.5", ls="--", lw=1.0, label="$F_c$")
    ax.set_xlabel("force rate $du/dt$ [N/s]")
    ax.set_ylabel("break-away force [N]")
    ax.set_ylim(0.9, 1.6)
    ax.set_title("varying break-away force", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="center right", fontsize=8)
    ax = axes[0, 1]
    for c, rate in zip(COLORS, (1.0, 10.0, 50.0)):
        if rate not in b["runs"]:
            continue
        r = b["runs"][rate]
        ax.plot(rate * r["t"], r["F"], color=c, lw=1.4, label=f"{rate:g} N/s")
    ax.set_xlabel("applied force $u$ = rate $t$ [N]")
    ax.set_ylabel("friction force $F$ [N]")
    ax.set_title("friction force during the ramps", fontsize=10)
    ax.set_ylim(0.0, 1.6)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    add_note(fig, "u = rate t on a resting unit mass; break-away force = first maximum of F(t) (the mass breaks loose). "
                  f"prefriction.simulate, rtol {RTOL:g}.")
    return save(fig, outdir, "lugre_breakaway.png")


def _fig_stick_slip(outdir: Path, d: dict) -> Path:
    fig, axes = new_figure(2, 1, size=(9.0, 6.8), sharex=True)
    ax = axes[0, 0]
    ax.plot(d["t"], d["y"], color=COLORS[1], lw=1.0, ls="--", label="spring end $y = 0.1 t$")
    ax.plot(d["t"], d["x"], color=COLORS[0], lw=1.6, label="mass $x$")
    ax.set_ylabel("position [m]")
    ax.set_title("stick-slip: mass pulled through a spring k = 2 N/m at 0.1 m/s", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax = axes[1, 0]
    # while the mass sticks F = u: the spring force is drawn wide and light beneath the friction force
    ax.plot(d["t"], d["u"], color=COLORS[3], lw=5.0, alpha=0.35, solid_capstyle="butt",
            label="spring force $u$ (= $F$ while stuck)")
    ax.plot(d["t"], d["F"], color=COLORS[0], lw=1.2, label="friction force $F$")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel("force [N]")
    ax.set_ylim(0.0, 2.4)
    ax.grid(True, alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(d["t"], d["v"], color=COLORS[2], lw=1.2, label="velocity $v$")
    ax2.set_ylabel("velocity $v$ [m/s]")
    ax2.set_ylim(-0.02, 0.6)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper left", fontsize=8, ncol=2)
    add_note(fig, "u = k (0.1 t - x) as LinearFeedback(D = k, reference = Ramp(0, 0.1)); "
                  f"prefriction.simulate, rtol {RTOL:g}.")
    return save(fig, outdir, "lugre_stick_slip.png")


def _fig_hunting(outdir: Path, d: dict) -> Path:
    fig, axes = new_figure(2, 1, size=(9.0, 6.8), sharex=True)
    ax = axes[0, 0]
    ax.axhline(X_SET, color="0.4", ls="--", lw=1.0, label="set point")
    ax.plot(d["t"], d["x"], color=COLORS[0], lw=1.6, label="position $x$")
    ax.set_ylabel("position $x$ [m]")
    ax.set_ylim(-0.05, 1.85)
    ax.set_title(f"hunting of a PID position loop: Kp = {KP:g} N/m, Ki = {KI:g} N/(m s), Kv = {KV:g} N s/m", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8, ncol=2)
    ax = axes[1, 0]
    ax.plot(d["t"], d["u"], color=COLORS[3], lw=5.0, alpha=0.35, solid_capstyle="butt",
            label="control force $u$ (= $F$ while stuck)")
    ax.plot(d["t"], d["F"], color=COLORS[0], lw=1.2, label="friction force $F$")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel("force [N]")
    top = float(max(np.max(d["F"]), np.max(d["u"])))
    bottom = float(min(np.min(d["F"]), np.min(d["u"])))
    ax.set_ylim(bottom - 0.1 * (top - bottom), top + 0.35 * (top - bottom))  # room for the legend above the data
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8, ncol=2)
    add_note(fig, "u = Kp (1 - x) + Ki int (1 - x) dt - Kv dx/dt: PI LinearFeedback on LuGre(sigma2 + Kv) "
                  f"(exact); prefriction.simulate, rtol {RTOL:g}.")
    return save(fig, outdir, "lugre_hunting.png")


def _fig_bench(outdir: Path, table: dict) -> Path:
    n = len(table)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = new_figure(rows, cols, size=(5.6 * cols, 4.0 * rows + 0.6))
    marks = {"simulate (erk)": "o-", "Radau": "s--", "BDF": "^--", "LSODA": "v--"}
    for ax, (name, rows_) in zip(axes.ravel(), table.items()):
        for c, (solver, pts) in zip(COLORS, rows_.items()):
            if pts:
                ax.loglog([p[1] for p in pts], [p[2] for p in pts], marks[solver], color=c, ms=4, lw=1.2, label=solver)
        ax.set_xlabel("run time [s]")
        ax.set_ylabel("max. error [-]")
        ax.set_title(name, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=len(labels), fontsize=9)
    add_note(fig, "Points: rtol 1e-4 ... 1e-10 (left to right for scipy). Error: x relative to max |x|; v, F relative to the "
                  "amplitude max hypot(v/V, F/Fc),\nV = Fc/sqrt(m sigma0). Reference: scipy Radau at rtol 1e-12. scipy runs restart "
                  "at every reversal (Python right-hand side); simulate is compiled and warm.", lines=2)
    return save(fig, outdir, "lugre_work_precision.png")


def main(outdir: str | Path = ".", *, quick: bool = False, bench: Optional[bool] = None) -> dict:
    """Run the five experiments (and :func:`benchmark` unless ``quick``); draw the figures.

    Parameters
    ----------
    outdir : str or Path
        Output directory (created if needed).
    quick : bool, default False
        Fewer rates, shorter horizons, no benchmark (for tests).
    bench : bool, optional
        Run :func:`benchmark` (default: ``not quick``).

    Returns
    -------
    dict
        ``presliding``, ``lag``, ``breakaway``, ``stick_slip``, ``hunting`` (the data),
        ``bench`` (the benchmark table or None) and ``pngs`` (paths).
    """
    outdir = Path(outdir)
    bench = (not quick) if bench is None else bench
    pre = presliding(n=2001 if quick else 6001)
    lag = friction_lag(n=500 if quick else 2000)
    brk = breakaway((1.0, 10.0, 50.0) if quick else RATES, n=1001 if quick else 4001)
    ss = stick_slip(10.0 if quick else 20.0)
    hunt = hunting(40.0 if quick else 100.0)
    pngs = [_fig_presliding(outdir, pre), _fig_lag(outdir, lag), _fig_breakaway(outdir, brk),
            _fig_stick_slip(outdir, ss), _fig_hunting(outdir, hunt)]
    table = None
    if bench:
        table = benchmark(quick=quick, log=print)
        pngs.append(_fig_bench(outdir, table))
    return {"presliding": pre, "lag": lag, "breakaway": brk, "stick_slip": ss, "hunting": hunt,
            "bench": table, "pngs": pngs}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print("\n".join(str(p) for p in main(outdir, quick=quick)["pngs"]))
