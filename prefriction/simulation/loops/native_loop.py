"""The sampled-data loop on the native driver: one C call per block of sample periods.

:func:`loop_driver` builds (once per loop structure: model, controller order, compensator) the
library of the model's generated code, the input force of the plant's structure (generated as
for a forced run: :func:`~prefriction.simulation.native.forced.input_function`), the controller's law at a
sample instant (``pf_ctrl``, from :func:`prefriction.simulation.loops.compiled_loop.control_law`)
and ``native/loop.c`` on ``native/forced.c``; :func:`run_blocks` runs the periods of
:func:`prefriction.simulation.loops.runner.run_sampled` on it, block by block, with the loop
state, inputs and records of :class:`~prefriction.simulation.loops.compiled_loop.LoopLayout`
(``docs/controllers.md#compiled-loop``). Any number of reversals per period; the step size is
carried over from period to period; the input's break times are honoured inside a period.
"""

from __future__ import annotations

import ctypes
import functools
import math
import threading
import time
from pathlib import Path
from typing import Hashable, Optional

import casadi as ca
import numpy as np

from prefriction.errors import SolverError
from prefriction.models.sizes import check_sizes
from prefriction.simulation import library_store as store
from prefriction.simulation.compiled import CompileInfo, jit_available, library
from .compiled_loop import LoopLayout, LoopSpec, control_law
from prefriction.simulation.native.forced import FORCED_SOURCE, FHEAD, input_function
from prefriction.simulation.native.library import _DRIVER
from prefriction.simulation.native.model_code import model_source

__all__ = ["CAPACITY", "LoopDriver", "loop_driver", "loop_source", "run_blocks"]

_LOOP = (Path(__file__).parent.parent / "native" / "loop.c").read_text()  # with the driver's other C files
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CACHE: dict = {}
_LOCK = threading.Lock()
CAPACITY = 1 << 14  # reversal slots per C call (the loop returns to empty them when fewer than 64 are free)


class LoopDriver:
    """The ``pf_loop`` and ``pf_loop_input`` entry points of one loop structure's library (loop.c);
    ``linear``: the input's structure is piecewise linear."""

    def __init__(self, lib: ctypes.CDLL, spec: LoopSpec, info: CompileInfo) -> None:
        self.lib, self.info = lib, info
        model = spec.plant.model
        self.nz, self.nm = model.n_states, model.n_flags
        self.width = FHEAD + self.nz + self.nm
        self.call = lib.pf_loop
        self.call.restype = ctypes.c_int
        self.call.argtypes = [_D, _D, _D, _D, ctypes.c_long, _D, _D, _D, _D, ctypes.c_long, _L]
        self.call_input = lib.pf_loop_input
        self.call_input.restype = ctypes.c_int
        self.call_input.argtypes = [_D, _D, _D, ctypes.c_long, _D] + self.call.argtypes[1:]
        self.linear = spec.plant.u_key == ("PiecewiseLinear",)


def _control_function(spec: LoopSpec, LL: LoopLayout) -> ca.Function:
    """``pf_ctrl(S, w, par) -> (S_next, [u_total, u, y, comp, F])``: the sample instant; the plant's
    entries of ``S_next`` are those of ``S`` (the period's integration sets them)."""
    S, w, par = ca.SX.sym("S", LL.nS), ca.SX.sym("w", LL.nw), ca.SX.sym("par", LL.npar)
    law = control_law(spec, LL, S, w, par)
    Sn = ca.SX(S)
    ix = LL.state
    for i in range(spec.n_c):
        Sn[ix[f"xc{i}"]] = law["xc_next"][i]
    for i in range(LL.n_comp):
        Sn[ix[f"c{i}"]] = ca.if_else(law["active"], law["cs_next"][i], law["cs"][i])
    for i, yi in enumerate([law["y_now"]] + law["past"][:-1]):
        Sn[ix[f"y{i}"]] = yi
    Sn[ix["uprev"]] = law["u"]
    out = ca.vertcat(law["u_total"], law["u"], law["y_meas"], law["comp"], law["F"])
    return ca.Function("pf_ctrl", [S, w, par], [ca.densify(Sn), ca.densify(out)], ["S", "w", "par"], ["S_next", "out"])


def loop_driver(spec: LoopSpec) -> tuple[Optional[LoopDriver], float]:
    """The native loop of ``spec`` (built once per process) and the setup time [s] of this call;
    ``(None, 0)`` where it cannot be used (no C compiler, ``PREFRICTION_NO_JIT``, closed-form
    branches, a failed compilation)."""
    model = spec.plant.model
    if not jit_available() or model.has_free_branch:
        return None, 0.0
    key: Hashable = (spec.plant.model_key, spec.n_c, spec.comp, spec.plant.u_key)
    with _LOCK:
        if key in _CACHE:
            return _CACHE[key], 0.0
        start = time.perf_counter()
        check_sizes(model)
        source = loop_source(spec)
        name = f"native_{type(model).__name__.lower()}_loop{spec.n_c}"
        if spec.comp.n_state or spec.comp.n_param:
            name += "_" + spec.comp.function().name()
        handle, info = library(name, source, "sampled loops in C",
                               functools.partial(store.load_verified, symbols=("pf_run", "pf_forced", "pf_loop", "pf_loop_input")),
                               "the CasADi block Function")
        driver = None if handle is None else LoopDriver(handle, spec, info)
        _CACHE[key] = driver
        return driver, time.perf_counter() - start


def loop_source(spec: LoopSpec, extra: tuple[ca.Function, ...] = ()) -> str:
    """The C source of the native loop of ``spec``: the layout's sizes, the model's generated code
    with the input of the plant's structure (``spec.plant.u_sig``), ``pf_ctrl`` and the ``extra``
    Functions, ``driver.c``, ``forced.c`` and ``loop.c``."""
    LL = LoopLayout(spec)
    u_sig = spec.plant.u_sig
    ix, inp, rec = LL.state, LL.inp, LL.rec
    defs = {"PF_FORCED": 1, "PF_NPC": u_sig.n_piece, "PF_LNS": LL.nS, "PF_LNW": LL.nw, "PF_LNREC": LL.nrec,
            "PF_LI_T0": inp["t0"], "PF_LI_T1": inp["t1"], "PF_LI_ACTIVE": inp["active"], "PF_LI_TL": inp["tl"],
            "PF_LI_DA": inp["da"], "PF_LI_DB": inp["db"], "PF_LS_S": ix["s"], "PF_LR_F": rec["F"],
            "PF_LR_U": rec["u"], "PF_LR_MOVED": rec["moved"], "PF_LR_Y": rec["y"], "PF_LR_COMP": rec["comp"]}
    assert ix["rest"] == ix["s"] + 1 and ix["W"] == ix["s"] + 2 and ix["Amax"] == ix["s"] + 3  # loop.c reads them so
    head = "".join(f"#define {k} {v}\n" for k, v in defs.items())
    code = model_source(spec.plant.model, (input_function(u_sig), _control_function(spec, LL)) + tuple(extra))
    return head + code + _DRIVER + FORCED_SOURCE + _LOOP


_WHY = {
    3: "the right-hand side became non-finite",
    5: "the step size fell below round-off of the time",
    6: "more reversals inside one sample period than the loop holds",
}


def run_blocks(drv: LoopDriver, LL: LoopLayout, S: np.ndarray, Wall: np.ndarray, n_s: int, par: np.ndarray,
               q: np.ndarray, cfg: np.ndarray, block: int, stop_at: float = math.inf,
               inputs: Optional[tuple[np.ndarray, np.ndarray, int, np.ndarray]] = None,
               ) -> tuple[np.ndarray, tuple, int, int, np.ndarray]:
    """The sample periods up to ``n_s``, or up to the block in which ``stop_at`` reversals were
    reached: the records of the periods run (``n_s`` rows unless stopped), the reversals as five
    columns ``(t~, x~, F~, W~, events)`` (events: the model events of the half-cycle ending at the
    reversal), the C calls, the accepted steps and the driver's run state after the last period
    (entry 4: the model events since the last reversal). ``inputs``: the oscillator's own input as
    ``(theta, breaks, n_breaks, pieces)`` (:func:`~prefriction.simulation.native.forced.input_tables`; None:
    no input of its own). ``SolverError`` if a period fails."""
    S = np.ascontiguousarray(S, dtype=float).copy()
    fst = np.zeros(drv.width)
    fst[12] = fst[13] = math.nan
    recs = np.empty((n_s, LL.nrec))
    rev = np.empty(5 * CAPACITY)
    cols: list = [[], [], [], [], []]
    cnt = np.zeros(4, np.int64)
    calls = k = n_rev = 0
    Wall = np.ascontiguousarray(Wall, dtype=float)
    while k < n_s and n_rev < stop_at:
        nb = min(block, n_s - k)
        cnt[0] = 0
        args = (cfg, par, Wall[k:k + nb], nb, S, fst, recs[k:k + nb], rev, CAPACITY, cnt)
        if inputs is None:
            code = drv.call(q, *args)
        else:
            code = drv.call_input(q, *inputs, *args)
        calls += 1
        n = int(cnt[0])
        if n:
            R = rev.reshape(5, CAPACITY)
            for col, row in zip(cols, R):
                col.append(row[:n].copy())
            n_rev += n
        done = int(cnt[3])
        if code != 0:
            t = Wall[k + done, LL.inp["t0"]] * cfg[3]
            raise SolverError(f"the sampled loop failed in the period from t = {t:.9g} s (period {k + done}): "
                              f"{_WHY.get(code, f'code {code}')}. Try a looser rtol, a shorter sample time Ts, or a "
                              f"stable controller.")
        k += done
    columns = tuple(np.concatenate(c) if c else np.zeros(0) for c in cols)
    return recs[:k], columns, calls, int(cnt[2]), fst
