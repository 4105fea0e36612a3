"""Drive the compiled sampled-data loop block by block (Python only between blocks).

:func:`run_sampled` prepares the per-sample inputs (sample times, reference samples) and the
run-time parameters, calls the compiled block Function of :mod:`.compiled_loop` over
``BLOCK`` samples at a time through persistent buffers, and assembles the samples and the
reversal table in SI. A period with more reversals than the plant's register holds
(``NSTOP``) is finished by :class:`prefriction.simulation.run.Run`, the loop of
:func:`prefriction.simulate`, and the next block starts after it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Optional

import casadi as ca
import numpy as np

from prefriction._memory import check_memory
from prefriction.models import Oscillator
from prefriction.signals import Constant
from prefriction.simulation.compiled import compiled, jit_available
from prefriction.simulation.feedback import LinearFeedback, sample_count
from prefriction.simulation.force_scale import applied_force_scale
from prefriction.simulation.per_thread import PerThread
from prefriction.simulation.plant import Layout, PlantSpec
from prefriction.simulation.result import RunStats, SimulationResult
from prefriction.simulation.lazy_table import reversal_table
from prefriction.simulation.plant import EPS_CAL as _CAL
from prefriction.units import Scales

from .compiled_loop import NSTOP, LoopLayout, LoopSpec, NoCompensation, loop_function
from .loop_inputs import loop_params, padded as _padded, sample_inputs
from .native_loop import loop_driver, run_blocks
from .records import collect, failure, finish_in_python, initial_state

__all__ = ["BLOCK", "NATIVE_BLOCK", "LoopStats", "Measurement", "Compensation", "run_sampled"]

BLOCK = 256
"""Sample periods per compiled call (a structure; the last block of a run is padded)."""
NATIVE_BLOCK = 4096
"""Sample periods per call of the native loop (bounds its records' buffers, not a structure)."""
_MIN_ORDER = 2  # controllers are padded to this order: P, PD and PID loops share one Function
_K = 2  # the plant's register length, as in prefriction.simulate
_CACHE = PerThread()  # one Function per structure and process, its buffers per thread


@dataclass(frozen=True)
class LoopStats:
    """Statistics of one compiled loop run.

    Attributes
    ----------
    samples : int
        Sample instants (periods + 1).
    blocks : int
        Calls of the compiled block Function.
    integrated : int
        Periods in which the plant was integrated (the others rested: skipped).
    finished_in_python : int
        Periods with more than ``NSTOP`` reversals, finished by the Python loop.
    wall_time, setup_time : float
        Wall time of the loop and of building, compiling or loading the Function [s].
    compiled_time : float
        Wall time spent inside the compiled block calls [s] (the rest of ``wall_time`` is Python).
    jit : str
        ``"compiled"``, ``"cached"`` or ``"interpreted"``.
    """

    samples: int
    blocks: int
    integrated: int
    finished_in_python: int
    wall_time: float
    setup_time: float
    compiled_time: float
    jit: str

    def summary(self) -> str:
        """One line: samples, blocks, integrated periods, time per sample and its compiled share."""
        per = self.wall_time / max(self.samples - 1, 1)
        return (f"{self.samples} samples in {self.blocks} blocks ({self.jit}), {self.integrated} periods integrated, "
                f"{self.finished_in_python} finished in Python; {per * 1e6:.3g} us per sample, "
                f"{100 * self.compiled_time / max(self.wall_time, 1e-300):.0f} % in compiled code")


def _function(spec: LoopSpec, jit: bool) -> tuple[ca.Function, str, float]:
    """The block Function of ``spec`` (compiled or loaded if ``jit``), its mode and setup time [s]."""
    start = time.perf_counter()
    LL = LoopLayout(spec)
    mapped = loop_function(spec)
    S0 = ca.MX.sym("S0", LL.nS)
    W = ca.MX.sym("W", LL.nw, spec.block)
    par = ca.MX.sym("par", LL.npar)
    S, R = mapped(S0, W, ca.repmat(par, 1, spec.block))
    fun = ca.Function(mapped.name(), [S0, W, par], [S[:, -1], R])
    mode = "interpreted"
    if jit:
        what = (f"{spec.plant.model_key[2]}, sampled loop, controller of order {spec.n_c}, "
                f"{spec.block} samples per call")
        fun, info = compiled(fun, what)
        mode = info.mode
    return fun, mode, time.perf_counter() - start


class _Block:
    """The block Function of a structure with this thread's argument and result buffers."""

    def __init__(self, spec: LoopSpec, fun: ca.Function) -> None:
        self.LL = LL = LoopLayout(spec)
        self.comp_fun = spec.comp.function()
        self.S0 = np.zeros(LL.nS)
        self.W = np.zeros((spec.block, LL.nw))  # row j = column j of CasADi's column-major W
        self.par = np.zeros(LL.npar)
        self.S = np.zeros(LL.nS)
        self.R = np.zeros((spec.block, LL.nrec))
        self.buf, self.trigger = fun.buffer()
        for i, arr in enumerate((self.S0, self.W, self.par)):
            self.buf.set_arg(i, memoryview(arr.reshape(-1)))
        self.buf.set_res(0, memoryview(self.S))
        self.buf.set_res(1, memoryview(self.R.reshape(-1)))


def _block(spec: LoopSpec, jit: bool) -> tuple[_Block, float, str]:
    """The block Function of ``spec`` (built once per process and structure) with this thread's
    buffers, the setup time and the mode."""
    jit = jit and jit_available()
    blk, (_, mode, setup), built = _CACHE.get(
        (spec, jit), lambda: _function(spec, jit), lambda made: _Block(spec, made[0]))
    if built:
        return blk, setup, mode
    return blk, 0.0, "interpreted" if mode == "interpreted" else "cached"


@dataclass(frozen=True)
class Measurement:
    """What the loop's controller sees of the position: ``y_k = round_q(x(t_{k-d}) + n_{k-d})``.

    Attributes
    ----------
    quantization : float
        Encoder step ``q`` [m], ``>= 0`` (0: no rounding).
    delay : int
        Delay ``d`` in whole samples, ``0 <= d <= MAX_DELAY``.
    noise : numpy.ndarray or None
        Noise ``n_k`` [m] at each sample instant, or ``None`` (no noise).
    """

    quantization: float = 0.0
    delay: int = 0
    noise: Optional[np.ndarray] = None


@dataclass(frozen=True)
class Compensation:
    """A compensator in the compiled loop: its structure (``NoCompensation``'s interface), its
    numbers, its initial state and the reference velocity [m/s] at the sample instants (one more
    entry, the instant after the last, makes the last sample's force the controller's there)."""

    structure: object
    params: np.ndarray
    state0: np.ndarray
    velocity: np.ndarray


def run_sampled(
    system: Oscillator, fb: LinearFeedback, t_end: float, *, x0: float, v0: float, F0: float,
    rtol: float, jit: bool, u_max: Optional[float] = None, k_aw: Optional[np.ndarray] = None,
    block: int = BLOCK, measurement: Measurement = Measurement(), compensation: Optional[Compensation] = None,
    native: bool = True,
) -> tuple[SimulationResult, LoopStats]:
    """Run the sampled loop ``fb`` (``fb.Ts`` set) on ``system`` (no input force) up to ``t_end`` [s].

    Parameters
    ----------
    system : Oscillator
        The plant, without an input force (``system.u is None``).
    fb : LinearFeedback
        Discrete controller (SI), its reference and initial state.
    t_end : float
        End time [s].
    x0, v0, F0 : float
        Initial position [m], velocity [m/s], friction force [N].
    rtol : float
        Tolerance of the plant, as in :func:`prefriction.simulate`.
    jit : bool
        Compile the block Function (cached on disk).
    u_max : float, optional
        Force limit [N]; ``None``: no limit.
    k_aw : numpy.ndarray, optional
        Back-calculation gains per controller state [1/(N s)] (with ``u_max``).
    block : int, default BLOCK
        Sample periods per compiled call.
    measurement : Measurement
        Encoder step, delay and noise of the measured position (default: the exact position).
    compensation : Compensation, optional
        A compensator whose force is added to the controller's (default: none).
    native : bool, default True
        Run the periods on the native loop (:mod:`prefriction.simulation.loops.native_loop`: blocks of
        :data:`NATIVE_BLOCK` periods per C call) where it can be built; False: the CasADi block
        Function (the reference it is tested against).

    Returns
    -------
    (SimulationResult, LoopStats, dict)
        Samples at the sample instants (``t, x, v, F, E_k, u, xc``), the reversal table, the
        loop's statistics, and the measured positions ``y`` [m] and compensation forces
        ``comp`` [N] at the sample instants.
    """
    if system.forced:
        raise ValueError("the compiled sampled loop needs an oscillator without an input force (system.u = None)")
    model, sc, Fc = system.friction, Scales.of(system), system.friction.Fc
    n_user = fb.n_states
    n = max(n_user, _MIN_ORDER)
    plant = PlantSpec.of(model, Constant(0.0), None, fb="none", n_c=0, energy=False, K=_K, n_out=1,
                         method="erk", compact=True)
    comp = compensation.structure if compensation is not None else NoCompensation()
    spec = LoopSpec(plant, n, block, comp)
    L = Layout(plant)
    eps = rtol * _CAL * math.sqrt(L.n_active / L.nx)
    Ts_n, t_end_n = fb.Ts / sc.t, t_end / sc.t
    n_s = sample_count(t_end_n, Ts_n, t_end / fb.Ts)
    lay = LoopLayout(spec)  # before any compile: the inputs and records of every sample
    check_memory(f"the sampled loop of {type(model).__name__}", n_s, lay.nw + lay.nrec + 12 + n_user,
                 "sample instants", "increase Ts or split the run")
    tk = np.minimum(np.arange(n_s) * Ts_n, t_end_n)
    drv, setup = loop_driver(spec) if native and jit else (None, 0.0)
    if drv is None:
        blk, setup, mode = _block(spec, jit)
        LL, par, comp_fun = blk.LL, blk.par, blk.comp_fun
    else:
        mode = drv.info.mode if setup else "cached"
        LL, comp_fun = LoopLayout(spec), comp.function()
        par = np.zeros(LL.npar)
    # run-time parameters: the plant's constants, the controller (SI, padded), limit, scales
    P0 = loop_params(par, LL, L, model, sc, fb, eps, rtol, applied_force_scale(system, fb, x0, t_end) / Fc)
    if k_aw is not None:
        par[LL.p_kaw.start: LL.p_kaw.start + len(k_aw)] = k_aw
    par[LL.param["umax"]] = 1e300 if u_max is None else u_max
    par[LL.param["quant"]] = measurement.quantization
    par[LL.p_delay] = 0.0
    par[LL.p_delay.start + measurement.delay] = 1.0
    if compensation is not None:
        par[LL.p_comp] = compensation.params
    # per-sample inputs
    Wall = sample_inputs(LL, fb, sc, tk, t_end_n, Ts_n, block)
    ii = LL.inp
    if compensation is not None:
        Wall[:n_s, ii["vr"]] = compensation.velocity[:n_s]
        Wall[: n_s - 1, ii["vrn"]] = compensation.velocity[1:n_s]
        if len(compensation.velocity) > n_s:
            Wall[n_s - 1, ii["vrn"]] = compensation.velocity[n_s]
    if measurement.noise is not None:
        Wall[:n_s, ii["noise"]] = measurement.noise
    xc0 = _padded(fb.xc0.reshape(1, -1), n, (1, n))[0]
    comp0 = compensation.state0 if compensation is not None else np.zeros(0)
    u0 = _first_force(LL, comp_fun, Wall[0], par, xc0, comp0, x0, measurement, u_max)
    y0 = x0 if measurement.quantization == 0.0 else measurement.quantization * math.floor(x0 / measurement.quantization + 0.5)
    S, s0 = initial_state(system, LL, x0, v0, F0, xc0, u0, comp0, y0)
    rev: "list | tuple" = []
    blocks = finished = 0
    inside = 0.0
    steps: Optional[int] = None
    start = time.perf_counter()
    k = n_s if drv is not None else 0
    if drv is not None:  # every period in C, NATIVE_BLOCK per call
        cfg = np.array([rtol * _CAL, eps, rtol, sc.t, 1.0 / sc.F, par[LL.param["force_scale"]], 0.0, 1.0, 0.0])
        recs, rev, blocks, steps, _ = run_blocks(drv, LL, S, Wall, n_s, par, np.ascontiguousarray(P0[L.q]), cfg,
                                                 NATIVE_BLOCK)
        rev = rev[:4]  # t~, x~, F~, W~
        inside = time.perf_counter() - start
    else:
        recs = np.empty((n_s, LL.nrec))
    while k < n_s:
        blk.S0[:] = S
        blk.W[:] = Wall[k: k + block]
        t_call = time.perf_counter()
        try:
            blk.trigger()
            inside += time.perf_counter() - t_call
            failed = blk.buf.ret() != 0
        except RuntimeError as exc:
            failed, why = True, str(exc).strip().splitlines()[-1]
        else:
            why = "the integrator stopped with an error (a step below its minimum, or more steps or events than allowed)"
        blocks += 1
        R = blk.R
        if failed or not np.all(np.isfinite(R)):
            raise failure(S, LL, sc, tk[k], tk[min(k + block, n_s - 1)], why)
        count = min(block, n_s - k)
        over = np.nonzero(R[:count, LL.rec["n_new"]] >= NSTOP - 0.5)[0]
        upto = int(over[0]) + 1 if over.size else count
        recs[k: k + upto] = R[:upto]
        collect(rev, R[:upto], LL, _K, skip_last=bool(over.size))
        if over.size:  # finish this period with the Python loop of prefriction.simulate
            j = k + upto - 1
            after = R[upto, : LL.nS] if upto < block else blk.S
            S = finish_in_python(system, fb, plant, eps, rtol, jit, R[upto - 1, : LL.nS].copy(), after, LL, tk, j,
                                  float(R[upto - 1, LL.rec["u"]]), par, rev, bool(R[upto - 1, LL.rec["lr"]] > 0.5))
            finished += 1
        else:
            S = blk.S.copy()
        k += upto
    wall = time.perf_counter() - start
    integrated = int(np.count_nonzero(recs[:, LL.rec["moved"]] > 0.5))
    table, W_r = reversal_table(rev, system, s0, v0, F0)
    ix = LL.state
    t = tk * sc.t
    x, v = recs[:, ix["x"]] * sc.x, recs[:, ix["v"]] * sc.v
    xc = recs[:, ix["xc0"]: ix["xc0"] + n_user] if n_user else np.zeros((n_s, 0))
    stats = RunStats(wall_time=wall, setup_time=setup, calls=blocks, steps=steps, jit=mode)
    sim = SimulationResult(
        reversals=table, status=0, message=f"reached t_end = {t_end:.9g} s", stats=stats, work_input=W_r,
        t=t, x=x, v=v, F=recs[:, LL.rec["F"]] * sc.F, E_k=0.5 * system.mass * v * v, u=recs[:, LL.rec["u"]],
        xc=np.array(xc),
    )
    extra = {"y": recs[:, LL.rec["y"]], "comp": recs[:, LL.rec["comp"]]}
    return sim, LoopStats(n_s, blocks, integrated, finished, wall, setup, inside, mode), extra


def _first_force(LL: LoopLayout, comp_fun: ca.Function, w: np.ndarray, par: np.ndarray, xc0: np.ndarray,
                 comp0: np.ndarray, x0: float, m: Measurement, u_max: Optional[float]) -> float:
    """The force [N] the loop applies at ``t = 0`` (controller and compensator, clipped), for the
    initial direction of motion: the compiled step's law, evaluated once in Python."""
    y0 = x0 + (w[LL.inp["noise"]] if m.delay == 0 else 0.0)
    if m.quantization > 0.0:
        y0 = m.quantization * math.floor(y0 / m.quantization + 0.5)
    raw = float(par[LL.p_C] @ xc0) + par[LL.param["D"]] * (w[LL.inp["r"]] - y0)
    if LL.n_comp or LL.p_comp.stop > LL.p_comp.start:
        ref = [w[LL.inp["r"]], w[LL.inp["rn"]], w[LL.inp["vr"]], w[LL.inp["vrn"]]]
        raw += float(comp_fun(comp0, [y0, 0.0], ref, par[LL.p_comp])[1])
    return raw if u_max is None else min(max(raw, -u_max), u_max)
