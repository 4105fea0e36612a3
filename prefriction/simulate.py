"""Time simulation of the pre-sliding oscillator (2.1) with reversal handling, through CasADi.

Between two velocity reversals the branch direction ``s`` is fixed and the Dahl right-hand side
(3.2) is smooth. The integrator (``casadi.integrator``, plugin ``erk``: adaptive explicit
Runge-Kutta 5(4), compiled with gcc and cached on disk by :mod:`prefriction._jit`) locates every
zero of ``s v`` on its dense output (to round-off) and restarts on the new branch through an
event transition; saturation (gamma < 1), touches and rest of a forced mass are events too
(see :mod:`prefriction._plant`). One call covers up to ``K = 2`` reversals and is made through a
persistent argument buffer, so the cost per reversal is the integration itself (about 50 steps
at ``rtol = 1e-8``), the same for 50 or 1e4 reversals.

The model is integrated in normalised units (:mod:`prefriction.units`), with the branch distance
``p`` (``p' = s v``) as the force state and every state scaled per call by the current
amplitude, so the relative accuracy does not depend on ``sigma``, ``Fc``, the mass or the energy
(1e-20 to 1e6 times ``Fc^2 / sigma`` in the first excursion); results are converted to SI.
The internal tolerance is ``rtol`` times a calibration factor such that the error of reversal
times, positions and forces over 50 reversals stays below ``rtol`` (``prefriction bench``);
global errors grow linearly with the number of cycles, as for any one-step method.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Any, Optional, Union

import casadi as ca
import numpy as np

from ._branch import branch_potential
from ._feedback import LinearFeedback
from ._jit import compiled
from ._plant import EPS_REST, Layout, PlantSpec, build_integrator, force_of_p, p_of_force, trace_signal
from ._validation import check_count, check_finite, check_positive
from .errors import SolverError
from .models import Dahl, Oscillator
from .reversals import ReversalTable
from .units import Scales

__all__ = ["METHODS", "RunStats", "SimulationResult", "simulate"]

METHODS = ("erk",)
"""Integrator plugins exposed by :func:`simulate` (each tested on the whole case set)."""

_K = 2  # reversals recorded per integrator call (register length)
_N_DENSE = 16  # output times per call of the dense-output integrator
_CAL = 0.07  # calibration of the internal tolerance: global error over 50 reversals ~ 0.7 rtol
_DENSE_STEP = 2.0 * math.pi / 64.0  # normalised spacing of dense=True samples (64 per small cycle)
_CACHE: dict = {}
_INTEGRATOR_FAILED = (
    "the integrator stopped with an error before the end of its interval (a non-finite right-hand "
    "side such as a NaN input, a step below its minimum, or more steps or events than allowed)"
)


@dataclass(frozen=True)
class RunStats:
    """Run statistics of one :func:`simulate` call.

    Attributes
    ----------
    wall_time : float
        Wall time of the integration loop [s], without building or compiling the integrator.
    setup_time : float
        Wall time spent building, compiling or loading the integrator [s] (0 when reused).
    calls : int
        Number of integrator calls.
    steps : int or None
        Number of accepted integrator steps (None for compiled code, which keeps no statistics).
    jit : str
        ``"compiled"``, ``"cached"`` (compiled code loaded from disk or memory) or ``"interpreted"``.
    """

    wall_time: float
    setup_time: float
    calls: int
    steps: Optional[int]
    jit: str


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Result of :func:`simulate`, in SI units.

    Attributes
    ----------
    reversals : ReversalTable
        States at the velocity reversals, in the form of :func:`prefriction.exact_reversals`.
        For a forced system ``E_d[k] = E_p[k-1] + W_u[k] - E_p[k]``.
    status : str
        ``"reversals"`` (stopped at the requested number of reversals) or ``"t_end"``.
    stats : RunStats
        Wall time, integrator calls and steps.
    work_input : numpy.ndarray
        Work of the external and feedback forces [J] over each half-cycle ending at a reversal
        (zeros for the unforced system).
    t, x, v, F : numpy.ndarray or None
        Samples [s, m, m/s, N] at the requested times (``dense``); None if not requested.
    E_k, E_f : numpy.ndarray or None
        Kinetic energy ``m v^2 / 2`` [J] and the work of the friction force
        ``E_f = int_0^t F v dt`` [J] by integrated power (2.8), at the sample times.
    u : numpy.ndarray or None
        Total applied force (input plus feedback) [N] at the sample times.
    xc : numpy.ndarray or None
        Controller states at the sample times, shape ``(len(t), n)`` (feedback only).
    """

    reversals: ReversalTable
    status: str
    stats: RunStats
    work_input: np.ndarray
    t: Optional[np.ndarray] = None
    x: Optional[np.ndarray] = None
    v: Optional[np.ndarray] = None
    F: Optional[np.ndarray] = None
    E_k: Optional[np.ndarray] = None
    E_f: Optional[np.ndarray] = None
    u: Optional[np.ndarray] = None
    xc: Optional[np.ndarray] = None


def _signal_kind(value: Any, what: str) -> str:
    """Kind of an input or reference signal: none, const, callable or samples."""
    if value is None:
        return "none"
    if callable(value):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            trace_signal(value, what)
        return "callable"
    if isinstance(value, tuple):
        return "samples"
    return "const"


def _eval_signal(value: Any, kind: str, t: np.ndarray) -> np.ndarray:
    """Numeric value of a signal at times ``t`` [s] (samples: linear, held outside the range)."""
    t = np.asarray(t, dtype=float)
    if kind == "none":
        return np.zeros_like(t)
    if kind == "const":
        return np.full_like(t, float(value))
    if kind == "samples":
        return np.interp(t, value[0], value[1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        return np.array([float(ca.DM(value(float(ti)))) for ti in t.ravel()]).reshape(t.shape)


def _segment(value: Any, t: float, t_next: float) -> tuple[float, float, float]:
    """(left time, value, slope) of the linear piece of sampled ``value`` on ``[t, t_next]`` [SI]."""
    ts, vs = value
    if t_next <= ts[0] or t >= ts[-1]:
        return t, float(np.interp(t, ts, vs)), 0.0
    mid = 0.5 * (t + t_next)  # robust to round-off when t is a sample time
    k = int(np.clip(np.searchsorted(ts, mid, side="right") - 1, 0, len(ts) - 2))
    slope = (vs[k + 1] - vs[k]) / (ts[k + 1] - ts[k])
    return float(ts[k]), float(vs[k]), float(slope)


def _force_scale(system: Oscillator, u_kind: str, fb: Optional[LinearFeedback], r_kind: str,
                 x0: float, t_end: float) -> float:
    """Size [N] of the applied force: input samples, or 257 evaluations over [0, t_end], plus the
    feedback force ``|D| max |r - x0| + |C xc0|``; used for the error-control scale."""
    t = np.linspace(0.0, t_end, 257)
    with np.errstate(invalid="ignore"):
        scale = float(np.nanmax(np.abs(_eval_signal(system.u, u_kind, t)), initial=0.0)) if system.forced else 0.0
        if fb is not None:
            r = _eval_signal(fb.reference, r_kind, t)
            scale += abs(fb.D[0, 0]) * float(np.nanmax(np.abs(r - x0), initial=0.0))
            scale += float(np.abs(fb.C[0] @ fb.xc0))
    return scale


def _integrator(spec: PlantSpec, tol: float, atol: float, jit: bool) -> tuple["_Buffered", float, str]:
    """Build (or reuse) the integrator of ``spec``; returns it, the setup time and the JIT mode."""
    key = (spec, tol, atol, jit)
    if key in _CACHE:
        return _CACHE[key][0], 0.0, _CACHE[key][1] if _CACHE[key][1] == "interpreted" else "cached"
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        fun = build_integrator(spec, tol, atol)
    mode = "interpreted"
    if jit:
        fun, info = compiled(fun)
        mode = info.mode
    call = _Buffered(fun, Layout(spec), spec.n_out)
    setup = time.perf_counter() - start
    _CACHE[key] = (call, mode)
    return call, setup, mode


class _Buffered:
    """A CasADi integrator with persistent argument and result arrays (calls cost ~2 us, not ~50 us)."""

    def __init__(self, fun: ca.Function, L: Layout, n_out: int) -> None:
        self.fun = fun
        self.X0 = np.zeros(L.nx)
        self.P = np.zeros(L.np)
        self.U = np.zeros((n_out, L.nu))  # row j = column j of CasADi's column-major u
        self.out = np.zeros(n_out * L.nx)
        self.buf, self.trigger = fun.buffer()
        self.buf.set_arg(0, memoryview(self.X0))
        self.buf.set_arg(2, memoryview(self.P))
        self.buf.set_arg(3, memoryview(self.U.reshape(-1)))
        self.buf.set_res(0, memoryview(self.out))


class _Run:
    """The integration loop of one :func:`simulate` call (normalised units inside)."""

    def __init__(self, system: Oscillator, spec: PlantSpec, fb: Optional[LinearFeedback],
                 tol: float, atol: float, jit: bool) -> None:
        self.system, self.spec, self.fb = system, spec, fb
        self.sc = Scales.of(system)
        self.gamma = system.friction.gamma
        self.L = Layout(spec)
        self.Ld = Layout(PlantSpec(**{**spec.__dict__, "n_out": _N_DENSE})) if spec.n_out > 1 else None
        one = PlantSpec(**{**spec.__dict__, "n_out": 1})
        self.f1, s1, mode = _integrator(one, tol, atol, jit)
        self.fd, sd = None, 0.0
        if spec.n_out > 1:
            self.fd, sd, _ = _integrator(PlantSpec(**{**spec.__dict__, "n_out": _N_DENSE}), tol, atol, jit)
        self.setup_time = s1 + sd
        self.mode = mode
        self.calls = 0
        self.steps: Optional[int] = 0
        self.rev: list[tuple] = []  # (t~, x~, F~, W~)
        self.st: dict = {}  # current state, normalised (set by simulate)
        self.snap = 0.0  # reversal-saturation coincidence tolerance (gamma < 1)
        self.force_scale = 0.0  # size of the applied force / Fc
        self.A_max = 0.0  # largest amplitude seen (forced)
        self.breaks = np.zeros(0)  # sample times of sampled signals (normalised)
        self.u_kind = self.r_kind = "none"
        self.S = np.ones(spec.n_c)  # controller state scales
        self.P0 = np.zeros(self.L.np)  # parameters fixed during the run

    # --- state conversion -------------------------------------------------------------
    def _scales(self) -> dict:
        """Amplitude scales of the next call (normalised units): the state and, if forced, the
        force scale of the input and the largest amplitude so far (a motion can grow)."""
        v, F = self.st["v"], self.st["F"]
        A = math.hypot(v, F)
        if self.spec.forced:
            self.A_max = max(self.A_max, A)
            A = max(A, self.force_scale, 0.1 * self.A_max)
        A = max(A, 1e-300)
        Ax = max(A, 0.5 * A * A, min(abs(self.st["x"]), 1.0))  # positions: relative to |x| (<= 1)
        return {"Ax": Ax, "Av": A, "AF": min(A, 1.0), "AE": A * A}

    def _constant_params(self, L: Layout) -> np.ndarray:
        """Parameter vector with the entries that stay fixed during the run."""
        sc, fb = self.sc, self.fb
        P = np.zeros(L.np)
        P[L.param["snap"]] = self.snap
        P[L.param["tunit"]] = sc.t
        P[L.param["xunit"]] = sc.x
        P[L.param["Fc"]] = sc.F
        if "r" in L.param:
            P[L.param["r"]] = float(fb.reference)
        if self.spec.fb == "continuous":
            Ct = fb.C[0] / sc.F
            self.S = np.where(Ct != 0, 1.0 / np.where(Ct == 0, 1.0, np.abs(Ct)), 1.0)
            P[L.p_A:L.p_B] = (fb.A * sc.t).T.ravel()  # column-major, as ca.reshape reads it
            P[L.p_B:L.p_C] = fb.B[:, 0] * sc.t * sc.x
            P[L.p_C:L.p_D] = Ct
            P[L.p_D] = fb.D[0, 0] * sc.x / sc.F
            P[L.p_S:L.np] = self.S
        return P

    def _params(self, call: "_Buffered", L: Layout, a: dict, nstop: float) -> None:
        """Write the parameters of the next call into ``call.P``."""
        P, ix = call.P, L.param
        np.copyto(P, self.P0)
        P[ix["Ax"]], P[ix["Av"]], P[ix["AF"]], P[ix["AE"]] = a["Ax"], a["Av"], a["AF"], a["AE"]
        P[ix["xref"]], P[ix["Efref"]], P[ix["nstop"]] = self.st["x"], self.st["Ef"], nstop

    def _pack(self, call: "_Buffered", L: Layout, a: dict) -> None:
        """Write the scaled state into ``call.X0`` (the register is output only)."""
        st, ix, X = self.st, L.state, call.X0
        X[0] = 0.0  # xh: positions relative to xref
        X[1] = st["v"] / a["Av"]
        X[2] = st["p"] / a["AF"]
        X[3] = st["s"]
        X[4] = len(self.rev)
        if "sat" in ix:
            X[ix["sat"]] = st["sat"]
        if "rest" in ix:
            X[ix["rest"]] = st["rest"]
            X[ix["Wh"]] = st["W"] / a["AE"]
        if "Eh" in ix:
            X[ix["Eh"]] = 0.0
        if self.spec.fb == "continuous":
            X[L.xc] = st["xc"] / self.S

    def _unpack(self, L: Layout, col: np.ndarray, a: dict, n_before: int, nstop: float) -> dict:
        """State of one output column; ``t`` is the stop time if the call stopped at ``nstop``."""
        ix = L.state
        c = col.tolist()  # Python floats: cheaper to index than numpy scalars
        n = int(c[4] + 0.5)
        s = c[3]
        p = a["AF"] * c[2]
        out = {
            "x": a["xref"] + a["Ax"] * c[0],
            "v": a["Av"] * c[1],
            "p": p,
            "F": s * force_of_p(p, self.gamma),
            "s": s,
            "n": n,
            "frozen": n >= nstop,
            "sat": c[ix["sat"]] if "sat" in ix else 0.0,
            "rest": c[ix["rest"]] if "rest" in ix else 0.0,
            "W": a["AE"] * c[ix["Wh"]] if "Wh" in ix else 0.0,
            "Ef": a["Efref"] + a["AE"] * c[ix["Eh"]] if "Eh" in ix else 0.0,
            "xc": col[L.xc] * self.S if self.spec.fb == "continuous" else self.st["xc"],
        }
        new = n - n_before
        w, r0 = L.reg_width, L.reg
        regs = []
        for j in range(min(new, self.spec.K) - 1, -1, -1):
            k = r0 + j * w
            regs.append((c[k], c[k + 1], c[k + 2], c[k + 3] if w == 4 else 0.0))
        out["new"] = regs
        out["overflow"] = new > self.spec.K
        out["t"] = regs[-1][0] if out["frozen"] and regs else None
        return out

    # --- one call -----------------------------------------------------------------------
    def _controls(self, t0: float, t1: float, j: int) -> list[float]:
        """Controls of the output interval [t0, t1] (normalised times)."""
        L, sc, sys, fb = self.L, self.sc, self.system, self.fb
        U = [0.0] * L.nu
        U[L.control["dur"]] = t1 - t0
        U[L.control["t0"]] = t0 - (t1 - t0) * j  # t~ = t0 + dur * tau, tau in [j, j + 1]
        if "tl" in L.control:
            ta, tb = t0 * sc.t, t1 * sc.t
            tl = ta
            if self.spec.u_kind == "samples":
                tl, ua, ub = _segment(sys.u, ta, tb)
                U[L.control["ua"]], U[L.control["ub"]] = ua + ub * (ta - tl), ub
            if self.spec.r_kind == "samples":
                tl2, ra, rb = _segment(fb.reference, ta, tb)
                U[L.control["ra"]], U[L.control["rb"]] = ra + rb * (ta - tl2), rb
            U[L.control["tl"]] = ta
        if "uhold" in L.control:
            U[L.control["uhold"]] = self.st["uhold"]
        return U

    def _net_force(self) -> float:
        """Normalised net force ``u~ - F~`` on the mass in the current state."""
        st, sc = self.st, self.sc
        t_si = np.array([st["t"] * sc.t])
        u = float(_eval_signal(self.system.u, self.u_kind, t_si)[0]) if self.system.forced else 0.0
        if self.spec.fb == "continuous":
            e = float(_eval_signal(self.fb.reference, self.r_kind, t_si)[0]) - st["x"] * sc.x
            u += float(self.fb.C[0] @ st["xc"] + self.fb.D[0, 0] * e)
        elif self.spec.fb == "sampled":
            u += st["uhold"]
        return u / sc.F - st["F"]

    def _leave_rest(self) -> None:
        """End a rest at the start of a call if the net force no longer vanishes (the input or the
        held force jumped at a sample time; inside a call the rest-exit event does this)."""
        acc = self._net_force()
        if abs(acc) <= EPS_REST * self._scales()["Av"]:
            return
        st = self.st
        new_s = 1.0 if acc > 0 else -1.0
        if new_s != st["s"]:  # leaves backwards: a reversal at this instant
            self.rev.append((st["t"], st["x"], st["F"], st["W"]))
            st["W"] = 0.0
            st["p"] = p_of_force(new_s * st["F"], self.gamma)
            st["sat"] = 0.0
            st["s"] = new_s
        st["rest"] = 0.0

    def _call(self, call: "_Buffered", L: Layout, times: list[float], nstop: float) -> tuple[np.ndarray, dict]:
        """One integrator call over the output ``times`` (normalised), stopping at ``nstop`` reversals."""
        if self.spec.forced and self.st["rest"] > 0.5:
            self._leave_rest()
        a = self._scales()
        a["xref"], a["Efref"] = self.st["x"], self.st["Ef"]
        self._params(call, L, a, nstop)
        self._pack(call, L, a)
        t_prev = self.st["t"]
        for j, t1 in enumerate(times):
            call.U[j] = self._controls(t_prev, t1, j)
            t_prev = t1
        self.calls += 1
        try:
            call.trigger()
            failed = call.buf.ret() != 0
        except RuntimeError as exc:
            raise self._failure(str(exc).strip().splitlines()[-1]) from None
        if failed:
            raise self._failure(_INTEGRATOR_FAILED)
        if self.steps is not None:
            try:  # statistics exist for the interpreted integrator only (memory 1: the buffer's)
                self.steps += int(call.fun.stats(1)["n_steps"])
            except (RuntimeError, KeyError):
                self.steps = None
        xf = call.out.reshape(len(times), L.nx).T
        if not math.isfinite(float(call.out.sum())):
            raise self._failure("the integrator returned non-finite values")
        return xf, a

    def _failure(self, why: str) -> SolverError:
        sc, st = self.sc, self.st
        return SolverError(
            f"simulate failed after t = {st['t'] * sc.t:.9g} s (state there: x = {st['x'] * sc.x:.6g} m, "
            f"v = {st['v'] * sc.v:.6g} m/s, F = {st['F'] * sc.F:.6g} N, direction {int(st['s']):+d}, "
            f"{len(self.rev)} reversals so far): {why}. Try a looser rtol, a shorter t_end or fewer "
            f"reversals, or a smoother input force (samples closer together)."
        )

    def _accept(self, out: dict, t: float) -> None:
        """Take the unpacked state ``out``, at normalised time ``t`` unless the call stopped early."""
        self.rev.extend(out["new"])
        for k in ("x", "v", "F", "p", "s", "sat", "rest", "W", "Ef", "xc"):
            self.st[k] = out[k]
        self.st["t"] = t if out["t"] is None else out["t"]

    # --- loops --------------------------------------------------------------------------
    def _advance_unforced(self, t_target: float, n_target: float) -> bool:
        """:meth:`advance` for the unforced oscillator without dense output: the same steps with
        local variables instead of dictionaries (the Python work per call is ~5 us, not ~13 us)."""
        call, L, K, g = self.f1, self.L, self.spec.K, self.gamma
        X0, P, U, out = call.X0, call.P, call.U, call.out
        np.copyto(P, self.P0)
        ip = L.param
        iAx, iAv, iAF, iAE, ixr, ins = ip["Ax"], ip["Av"], ip["AF"], ip["AE"], ip["xref"], ip["nstop"]
        isat = L.state.get("sat")
        r0, w = L.reg, L.reg_width
        st, rev = self.st, self.rev
        x, v, p, s, t, sat = st["x"], st["v"], st["p"], st["s"], st["t"], st["sat"]
        grow = 1.0
        done = False
        while True:
            n = len(rev)
            if n >= n_target:
                done = True
                break
            if t >= t_target * (1 - 1e-15) and t_target < math.inf:
                break
            if n >= 2:
                chunk = (K + 0.6) * (rev[-1][0] - rev[-2][0]) * 1.25 * grow
            else:  # F rises over a distance ~1 (time ~1/|v|): the first step must not skip it
                chunk = 2.0 * math.pi / max(1.0, abs(v)) * grow
            t1 = min(t_target, t + chunk)
            nstop = min(n + (K if n else 1), n_target)
            F = s * force_of_p(p, g)
            A = max(math.hypot(v, F), 1e-300)
            Ax = max(A, 0.5 * A * A, min(abs(x), 1.0))
            AF = min(A, 1.0)
            P[iAx], P[iAv], P[iAF], P[iAE], P[ixr], P[ins] = Ax, A, AF, A * A, x, nstop
            X0[0], X0[1], X0[2], X0[3], X0[4] = 0.0, v / A, p / AF, s, n
            if isat is not None:
                X0[isat] = sat
            U[0, 0], U[0, 1] = t1 - t, t
            self.calls += 1
            try:
                call.trigger()
                failed = call.buf.ret() != 0
            except RuntimeError as exc:
                raise self._failure(str(exc).strip().splitlines()[-1]) from None
            c = out.tolist()
            if failed or not math.isfinite(math.fsum(c)):
                raise self._failure(_INTEGRATOR_FAILED)
            if self.steps is not None:
                try:
                    self.steps += int(call.fun.stats(1)["n_steps"])
                except (RuntimeError, KeyError):
                    self.steps = None
            n1 = int(c[4] + 0.5)
            for j in range(min(n1 - n, K) - 1, -1, -1):
                k = r0 + j * w
                rev.append((c[k], c[k + 1], c[k + 2], 0.0))
            x, v, p, s = x + Ax * c[0], A * c[1], AF * c[2], c[3]
            if isat is not None:
                sat = c[isat]
            frozen = n1 >= nstop
            t = rev[-1][0] if frozen and n1 > n else t1
            grow = 1.0 if frozen or n1 > n else 2.0 * grow
            # state for error messages and the caller
            st.update(x=x, v=v, p=p, s=s, t=t, sat=sat, F=s * force_of_p(p, g))
        return done

    def advance(self, t_target: float, n_target: float) -> bool:
        """Integrate to normalised time ``t_target`` or ``n_target`` reversals; True if the latter."""
        if not self.spec.forced and not self.spec.energy:
            return self._advance_unforced(t_target, n_target)
        grow = 1.0
        while True:
            if len(self.rev) >= n_target:
                return True
            if self.st["t"] >= t_target * (1 - 1e-15) and t_target < math.inf:
                return False
            # call length: K half-cycles as long as the last one, with a margin. A call that
            # stops at its K-th reversal integrates a zero right-hand side to its end, which is
            # cheap but not free; one that ends early is followed by another.
            rev = self.rev
            if len(rev) >= 2:
                chunk = (self.spec.K + 0.6) * (rev[-1][0] - rev[-2][0]) * 1.25
            else:  # about one small cycle (shorter at high speed: F rises over a distance ~1),
                # doubled while no reversal comes (gross sliding)
                chunk = 2.0 * math.pi / max(1.0, abs(self.st["v"]))
            chunk *= grow
            t1 = min(t_target, self.st["t"] + chunk)
            t1 = min(t1, self._next_break(self.st["t"]))
            # the first call stops at the first reversal: the amplitude scales of the first
            # excursion (possibly gross sliding) do not fit the pre-sliding cycles after it
            nstop = min(len(self.rev) + (self.spec.K if self.rev else 1), n_target)
            n0 = len(self.rev)
            xf, a = self._call(self.f1, self.L, [t1], nstop)
            out = self._unpack(self.L, xf[:, 0], a, n0, nstop)
            self._accept(out, t1)
            grow = 1.0 if out["frozen"] or len(self.rev) > n0 else 2.0 * grow

    def _next_break(self, t: float) -> float:
        """Next sample time of a sampled input or reference after normalised time ``t``."""
        b = self.breaks
        if b.size == 0:
            return math.inf
        k = np.searchsorted(b, t * (1 + 1e-15) + 1e-300, side="right")
        return float(b[k]) if k < b.size else math.inf

    def sample(self) -> tuple:
        """Current state as a sample (t~, x~, v~, F~, E_f~, xc)."""
        st = self.st
        return (st["t"], st["x"], st["v"], st["F"], st["Ef"], np.array(st["xc"], dtype=float))

    def dense(self, times: np.ndarray, t_end: float, n_target: float) -> tuple[list, bool]:
        """Integrate through the sorted normalised ``times``; returns the samples and the stop flag."""
        samples = []
        grid = np.union1d(times, self.breaks[(self.breaks > self.st["t"]) & (self.breaks < t_end)])
        is_sample = np.isin(grid, times)
        i = 0
        if grid.size and grid[0] <= self.st["t"]:
            samples.append(self.sample())
            i = 1
        while i < grid.size:
            if len(self.rev) >= n_target:
                return samples, True
            pts = list(grid[i:i + _N_DENSE])
            m = len(pts)
            while len(pts) < _N_DENSE:  # padding outputs, discarded
                pts.append(pts[-1] + 1e-3 * (pts[-1] - self.st["t"]) + 1e-9)
            nstop = min(n_target, 1e18)
            xf, a = self._call(self.fd, self.Ld, pts, nstop)
            used = m
            for j in range(m):
                out = self._unpack(self.Ld, xf[:, j], a, len(self.rev), nstop)
                if out["overflow"]:  # more than K reversals between two outputs: redo that piece
                    if self.advance(pts[j], n_target):
                        return samples, True
                    used = j + 1
                    if is_sample[i + j]:
                        samples.append(self.sample())
                    break
                self._accept(out, pts[j])
                if out["frozen"]:
                    return samples, True
                if is_sample[i + j]:
                    samples.append(self.sample())
            i += used
        return samples, False


def simulate(
    system: Oscillator,
    v0: float,
    *,
    x0: float = 0.0,
    F0: float = 0.0,
    reversals: Optional[int] = None,
    t_end: Optional[float] = None,
    rtol: float = 1e-8,
    atol: Optional[float] = None,
    method: str = "erk",
    dense: Union[bool, np.ndarray, list] = False,
    feedback: Optional[LinearFeedback] = None,
    jit: bool = True,
) -> SimulationResult:
    """Simulate the oscillator (2.1) ``m x'' = u - F`` with Dahl friction (3.2), every reversal located.

    Parameters
    ----------
    system : Oscillator
        Mass, friction model (:class:`prefriction.Dahl`) and optional input force ``u(t)`` [N]
        (a callable that accepts a CasADi symbol, or samples ``(t, u)``, linear between samples
        and held constant outside them; the integration is broken at the sample times).
    v0 : float
        Initial velocity [m/s]. If ``v0 = 0`` the motion starts in direction ``-sign(F0)``
        (unforced) or ``sign(u(0) - F0)`` (forced); with no net force the mass rests.
    x0, F0 : float, default 0.0
        Initial position [m] and friction force [N], ``|F0| <= Fc``.
    reversals : int, optional
        Stop at this many reversals (>= 1).
    t_end : float, optional
        Stop at this time [s] (> 0). At least one of ``reversals`` and ``t_end`` is required;
        a forced system or a closed loop needs ``t_end``.
    rtol : float, default 1e-8
        Relative tolerance, ``1e-13 <= rtol <= 1e-2``; reversal times, positions and forces come
        out with a relative error of about ``rtol`` (see ``prefriction bench``).
    atol : float, optional
        Absolute tolerance relative to the current amplitude of the motion (dimensionless);
        defaults to ``rtol``.
    method : str, default "erk"
        CasADi integrator plugin; one of :data:`METHODS`. Only ``"erk"`` is exposed: it passes
        every case of ``prefriction bench``. (``"rosenbrock"`` works with the same events but is
        5-10 times slower on these non-stiff problems; ``cvodes``/``idas`` events and
        ``collocation`` fail, DESIGN.md section 3.)
    dense : bool or array_like, default False
        ``False``: reversal table only (no dense output is computed). ``True``: samples every
        ``2 pi / 64`` normalised time units (64 per small oscillation). An array: samples at
        these times [s], increasing, within ``[0, t_end]``.
    feedback : LinearFeedback, optional
        Closed loop ``u = C xc + D (r - x)`` added to the input force (see
        :class:`prefriction._feedback.LinearFeedback`). A sampled controller also returns
        samples at its sample instants.
    jit : bool, default True
        Compile the integrator with the C compiler (cached on disk); the environment variable
        ``PREFRICTION_NO_JIT=1`` or a missing compiler selects the interpreted integrator.

    Returns
    -------
    SimulationResult
        Reversal table (SI), stop status, run statistics and, if requested, samples.

    Raises
    ------
    TypeError
        For arguments of the wrong type, or an input/reference callable that cannot be traced.
    ValueError
        For values out of range, or neither ``reversals`` nor ``t_end``.
    SolverError
        If the integrator fails; the message names the time, the state and what to try.
    """
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r}")
    if not isinstance(system.friction, Dahl):
        raise TypeError(f"simulate supports the Dahl friction model, got {type(system.friction).__name__}")
    v0 = check_finite("v0", v0)
    x0 = check_finite("x0", x0)
    F0 = check_finite("F0", F0)
    Fc = system.friction.Fc
    if abs(F0) > Fc:
        raise ValueError(f"F0 must lie in [-Fc, Fc] = [{-Fc!r}, {Fc!r}], got {F0!r}")
    if reversals is None and t_end is None:
        raise ValueError("give reversals (number of reversals) or t_end (end time [s]) or both; got neither")
    n_target = math.inf if reversals is None else check_count("reversals", reversals, 1)
    t_end_si = math.inf if t_end is None else check_positive("t_end", t_end)
    rtol = check_positive("rtol", rtol)
    if not 1e-13 <= rtol <= 1e-2:
        raise ValueError(f"rtol must lie in [1e-13, 1e-2], got {rtol!r}")
    atol = rtol if atol is None else check_positive("atol", atol)
    if not 1e-16 <= atol <= 1e-2:
        raise ValueError(f"atol must lie in [1e-16, 1e-2], got {atol!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if feedback is not None and not isinstance(feedback, LinearFeedback):
        raise TypeError(f"feedback must be a prefriction LinearFeedback or None, got {feedback!r}")
    if not isinstance(jit, bool):
        raise TypeError(f"jit must be True or False, got {jit!r}")
    forced = system.forced or feedback is not None
    if forced and t_end is None:
        raise ValueError("t_end is required for a forced system or a closed loop (a reversal may never come)")

    sc = Scales.of(system)
    u_kind = _signal_kind(system.u, "system.u")
    fb_kind, r_kind, n_c = "none", "none", 0
    if feedback is not None:
        fb_kind = "sampled" if feedback.sampled else "continuous"
        n_c = feedback.n_states if fb_kind == "continuous" else 0
        r_kind = _signal_kind(feedback.reference, "feedback.reference")
    want_dense = not (dense is False or dense is None)
    if want_dense and not isinstance(dense, bool):
        times_si = np.asarray(dense, dtype=float)
        if times_si.ndim != 1 or times_si.size < 1 or not np.all(np.isfinite(times_si)):
            raise ValueError("dense must be True, False or a 1-D array of finite sample times [s]")
        if np.any(np.diff(times_si) <= 0) or times_si[0] < 0 or times_si[-1] > t_end_si:
            raise ValueError(f"dense sample times must increase and lie in [0, t_end] = [0, {t_end_si!r}] s")
    elif want_dense:
        times_si = None
    if want_dense and fb_kind == "sampled":
        raise ValueError("dense samples are not available with a sampled controller: its samples are at k Ts")
    spec = PlantSpec(
        u_kind=u_kind if u_kind != "const" else "callable",
        u_fun=(system.u if u_kind == "callable" else None),
        fb=fb_kind, n_c=n_c,
        r_kind=r_kind if fb_kind == "continuous" else "none",
        r_fun=(feedback.reference if r_kind == "callable" and fb_kind == "continuous" else None),
        energy=want_dense, K=_K, n_out=_N_DENSE if want_dense else 1, method=method,
        gamma=system.friction.gamma,
    )
    L = Layout(spec)
    tol = rtol * _CAL * math.sqrt(L.n_active / L.nx)
    tol_abs = atol * _CAL * math.sqrt(L.n_active / L.nx)
    run = _Run(system, spec, feedback, tol, tol_abs, jit)
    run.snap = rtol
    run.u_kind, run.r_kind = u_kind, r_kind
    run.P0 = run._constant_params(run.L)
    run.force_scale = _force_scale(system, u_kind, feedback, r_kind, x0, t_end_si) / Fc if forced else 0.0

    # initial state (normalised)
    u0 = _eval_signal(system.u, u_kind, np.array([0.0]))[0] if system.forced else 0.0
    xc0 = np.array(feedback.xc0, dtype=float) if feedback is not None else np.zeros(0)
    if feedback is not None:
        r0 = _eval_signal(feedback.reference, r_kind, np.array([0.0]))[0]
        e0 = r0 - x0
        u0 += float(feedback.C[0] @ xc0 + feedback.D[0, 0] * e0)
    acc0 = (u0 - F0) / Fc
    rest = 0.0
    if v0 != 0.0:
        s0 = 1.0 if v0 > 0 else -1.0
    elif abs(acc0) > 1e-14:
        s0 = 1.0 if acc0 > 0 else -1.0
    else:
        s0, rest = (-1.0 if F0 > 0 else 1.0), 1.0
        if not forced and t_end is None:
            raise ValueError("v0 = 0 and F0 = 0 without input: the mass rests, no reversal will come; give t_end")
    gamma = system.friction.gamma
    if s0 * F0 >= Fc and gamma >= 1.0:
        raise ValueError(
            f"F0 = {F0!r} is the Coulomb force Fc in the direction of motion, which the Dahl branch "
            f"reaches only asymptotically for gamma = {gamma!r} >= 1; use |F0| < Fc"
        )
    run.st = {"x": x0 / sc.x, "v": v0 / sc.v, "F": F0 / sc.F, "p": p_of_force(s0 * F0 / Fc, gamma),
              "t": 0.0, "s": s0, "sat": 1.0 if s0 * F0 >= Fc else 0.0, "rest": rest,
              "W": 0.0, "Ef": 0.0, "xc": xc0, "uhold": 0.0}
    breaks = []
    if u_kind == "samples":
        breaks.append(np.asarray(system.u[0]) / sc.t)
    if r_kind == "samples" and fb_kind == "continuous":
        breaks.append(np.asarray(feedback.reference[0]) / sc.t)
    run.breaks = np.unique(np.concatenate(breaks)) if breaks else np.zeros(0)
    run.breaks = run.breaks[run.breaks > 0]
    t_end_n = t_end_si / sc.t

    start = time.perf_counter()
    samples: list = []
    u_hist: list = []
    if fb_kind == "sampled":
        Ts = feedback.Ts / sc.t
        xc = xc0.copy()
        k = 0
        while True:
            tk = min(k * Ts, t_end_n)
            t_si = tk * sc.t
            e = _eval_signal(feedback.reference, r_kind, np.array([t_si]))[0] - run.st["x"] * sc.x
            uk = float(feedback.C[0] @ xc + feedback.D[0, 0] * e)
            run.st["uhold"] = uk
            run.st["xc"] = xc.copy()
            samples.append(run.sample())
            u_hist.append(uk + _eval_signal(system.u, u_kind, np.array([t_si]))[0])
            if tk >= t_end_n * (1 - 1e-12):
                break
            xc = feedback.A @ xc + feedback.B[:, 0] * e
            if run.advance(min((k + 1) * Ts, t_end_n), n_target):
                break
            k += 1
        status = "reversals" if len(run.rev) >= n_target else "t_end"
    elif want_dense:
        if times_si is None:
            stop_t = t_end_n
            stopped = False
            t0 = 0.0
            while not stopped and t0 <= stop_t:
                block = t0 + _DENSE_STEP * np.arange(0, 256)
                block = block[block <= stop_t]
                if block.size == 0:
                    break
                got, stopped = run.dense(block, stop_t, n_target)
                samples.extend(got)
                t0 = block[-1] + _DENSE_STEP
        else:
            got, stopped = run.dense(times_si / sc.t, t_end_n, n_target)
            samples.extend(got)
            if not stopped and t_end is not None:
                stopped = run.advance(t_end_n, n_target)
            elif not stopped:
                stopped = run.advance(math.inf, n_target)
        status = "reversals" if len(run.rev) >= n_target else "t_end"
    else:
        stopped = run.advance(t_end_n, n_target)
        status = "reversals" if stopped else "t_end"
    wall = time.perf_counter() - start

    # reversal table (SI)
    rev = run.rev[: int(min(len(run.rev), n_target))]
    R = np.array(rev, dtype=float).reshape(-1, 4)
    t_r, x_r, F_r, W_r = R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F, R[:, 3] * sc.E
    s_after = s0 * (-1.0) ** (np.arange(1, len(R) + 1))
    E_p = branch_potential(np.clip(s_after * R[:, 2], -1.0, 1.0), gamma) * sc.E if len(R) else np.zeros(0)
    E0 = 0.5 * system.mass * v0 * v0 + float(branch_potential(np.array([s0 * F0 / Fc]), gamma)[0]) * sc.E
    E_d = np.empty(len(R))
    if len(R):
        E_d[0] = E0 - E_p[0] + W_r[0]
        E_d[1:] = E_p[:-1] + W_r[1:] - E_p[1:]
    table = ReversalTable(t=t_r, x=x_r, F=F_r, E_p=E_p, E_d=E_d, E_0=E0)
    stats = RunStats(wall_time=wall, setup_time=run.setup_time, calls=run.calls, steps=run.steps, jit=run.mode)
    extra: dict = {}
    if samples:
        S = list(zip(*samples))
        ts = np.array(S[0]) * sc.t
        if want_dense and times_si is not None:
            ts = times_si[: len(ts)].copy()  # the requested times exactly (no unit round trip)
        extra = {
            "t": ts, "x": np.array(S[1]) * sc.x, "v": np.array(S[2]) * sc.v, "F": np.array(S[3]) * sc.F,
        }
        extra["E_k"] = 0.5 * system.mass * extra["v"] ** 2
        if want_dense:
            extra["E_f"] = np.array(S[4]) * sc.E
        if forced:
            if fb_kind == "sampled":
                extra["u"] = np.array(u_hist)
            else:
                uu = _eval_signal(system.u, u_kind, ts)
                if feedback is not None:
                    xcs = np.array(S[5]).reshape(len(ts), -1)
                    e = _eval_signal(feedback.reference, r_kind, ts) - extra["x"]
                    uu = uu + (xcs @ feedback.C[0] if n_c else 0.0) + feedback.D[0, 0] * e
                extra["u"] = uu
        if feedback is not None:
            extra["xc"] = np.array(S[5]).reshape(len(ts), -1)
    return SimulationResult(reversals=table, status=status, stats=stats, work_input=W_r, **extra)
