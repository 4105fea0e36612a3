"""Forced and dense runs on the native driver: the input force generated as C, one C call per block.

:func:`forced_driver` builds (once per model structure and input structure) the library of the
model's generated code, the input signal's generated ``pf_input``, ``driver.c`` and
``forced.c``; :func:`run_forced` runs a whole :func:`prefriction.simulate` call on it: the
reversals in blocks of :data:`~prefriction.simulation.native.advance.BLOCK`, the dense samples
in blocks of :data:`SAMPLE_BLOCK` requested times (``docs/simulator.md#native``).

Inputs: every :mod:`prefriction.signals` kind. Analytic kinds (and sums of them) are their
expression compiled into C; piecewise-linear kinds (constants, steps, ramps, :class:`Samples`,
:class:`ZeroOrderHold` and their sums) are one line per interval between break times, read from
a table inside C; any other signal with per-interval numbers (a sum of both) gets the same
table of its :meth:`~prefriction.signals.Signal.piece` numbers.
"""

from __future__ import annotations

import ctypes
import functools
import math
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Hashable, Optional

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.signals.compiled import linear_pieces
from prefriction.simulation.compiled import CompileInfo, jit_available, library
from prefriction.simulation.native.advance import BLOCK, STIFF
from prefriction.simulation.native.controller import controller_numbers
from prefriction.simulation import library_store as store
from prefriction.simulation.native.library import _DRIVER
from prefriction.simulation.native.model_code import model_source
from prefriction.simulation.samples import DENSE_STEP, SampleBuffer
from prefriction.simulation.stiff_forced import advance_stiff_forced

if TYPE_CHECKING:
    from prefriction.simulation.run_state import RunState

__all__ = ["FORCED_SOURCE", "ForcedDriver", "SAMPLE_BLOCK", "forced_driver", "input_function", "input_tables",
           "run_forced"]

FHEAD = 14  # run-state entries before z and m (forced.c: st[])
SAMPLE_BLOCK = 1 << 14  # requested times per C call (4 x 128 kB of output)
FORCED_SOURCE = (Path(__file__).parent / "forced.c").read_text()
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CACHE: dict = {}
_LOCK = threading.Lock()
_WHY = {
    2: "the motion has died out (its reversals came at the level of the integration error)",
    3: "the right-hand side became non-finite",
    5: "the step size fell below round-off of the time",
}


class ForcedDriver:
    """The ``pf_forced`` entry point of one (model, input) structure's library (forced.c), or
    ``pf_forced_fb`` with a continuous controller of ``n_c`` states
    (:mod:`prefriction.simulation.native.closed`); ``u_sig`` is then the input to use when the
    system has none (zero)."""

    def __init__(self, lib: ctypes.CDLL, model: FrictionModel, u_sig: Any, info: CompileInfo, n_c: int = 0) -> None:
        self.lib, self.info = lib, info
        self.nz, self.nm, self.nc = model.n_states, model.n_flags, n_c
        self.width = FHEAD + self.nz + self.nm + (n_c + 1 if n_c else 0)  # then xc and the clip's mode
        self.forced = u_sig is not None
        self.u_sig = u_sig  # the structure's input (the zero input of an unforced closed loop)
        self.n_piece = 0 if u_sig is None else u_sig.n_piece
        self.linear = u_sig is not None and u_sig.key == ("PiecewiseLinear",)
        args = [_D, _D, _D, ctypes.c_long, _D, _D, _D, ctypes.c_double, ctypes.c_long, _D, _D, ctypes.c_long, _D, _L]
        self.call = lib.pf_forced_fb if n_c else lib.pf_forced
        self.call.restype = ctypes.c_int
        self.call.argtypes = args + ([_D, _D, _D] if n_c else [])
        self.call_stiff = lib.pf_forced_stiff  # stops on a stiff stretch (code 6: stiff_forced.py goes on)
        self.call_stiff.restype = ctypes.c_int
        self.call_stiff.argtypes = args


def input_function(u_sig: Any, name: str = "pf_input") -> ca.Function:
    """``name(t [s], theta, piece) -> u`` of the signal's structure (``pf_input``: the input
    force [N]; ``pf_ref``: a controller's position reference [m])."""
    t = ca.SX.sym("t")
    th = ca.SX.sym("th", u_sig.n_params)
    pc = ca.SX.sym("pc", max(u_sig.n_piece, 1))
    u = u_sig.expr(t, th, pc[:u_sig.n_piece] if u_sig.n_piece else ())
    return ca.Function(name, [t, th, pc], [ca.SX(u)], ["t", "th", "pc"], ["u"])


def forced_driver(model: FrictionModel, u_sig: Any, r_sig: Any = None,
                  n_c: int = 0) -> tuple[Optional[ForcedDriver], float]:
    """The native driver of ``model`` with the input structure of ``u_sig`` (the simulator's
    :func:`~prefriction.signals.compiled_form`; None: unforced dense runs) and, with ``n_c > 0``,
    a continuous controller of ``n_c`` states following the reference structure ``r_sig``, built
    once per process, and the setup time [s] of this call; ``(None, 0)`` where it cannot be used
    (no C compiler, ``PREFRICTION_NO_JIT``, closed-form branches, a failed compilation)."""
    if not jit_available() or model.has_free_branch:
        return None, 0.0
    key: Hashable = (type(model).__module__, type(model).__qualname__, model.structure_key(),
                     None if u_sig is None else u_sig.key, n_c, None if r_sig is None else r_sig.key)
    with _LOCK:
        if key in _CACHE:
            return _CACHE[key], 0.0
        start = time.perf_counter()
        extra = () if u_sig is None else (input_function(u_sig),)
        head = f"#define PF_FORCED {int(u_sig is not None)}\n#define PF_NPC {0 if u_sig is None else u_sig.n_piece}\n"
        symbols: tuple[str, ...] = ("pf_run", "pf_forced", "pf_forced_stiff")
        name = f"native_{type(model).__name__.lower()}_{'forced' if u_sig is not None else 'dense'}"
        if n_c:
            extra += (input_function(r_sig, "pf_ref"),)
            head += f"#define PF_NC {n_c}\n#define PF_NRPC {r_sig.n_piece}\n"
            symbols += ("pf_forced_fb",)
            name += "_feedback"
        source = head + model_source(model, extra) + _DRIVER + FORCED_SOURCE
        handle, info = library(name, source, "forced and dense runs in C",
                              functools.partial(store.load_verified, symbols=symbols),
                              "the CasADi integrator loop")
        driver = None if handle is None else ForcedDriver(handle, model, u_sig, info, n_c)
        _CACHE[key] = driver
        return driver, time.perf_counter() - start


def _pieces(run: "RunState", sig: Any, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """The break times (normalised, below ``t_end``) and the per-interval numbers of ``sig``, one
    row per interval ``[b_{k-1}, b_k]`` (``b_{-1} = 0``, the last row to ``t_end``)."""
    sc = run.sc
    brk = run.breaks[run.breaks < t_end]
    n_piece = 0 if sig is None else sig.n_piece
    if not n_piece:
        return np.ascontiguousarray(brk, dtype=float), np.zeros(brk.size + 1)
    last = t_end if math.isfinite(t_end) else (brk[-1] + 1.0 if brk.size else 1.0)
    ends = np.concatenate(([0.0], brk, [max(last, brk[-1] * (1 + 1e-9) if brk.size else last)])) * sc.t
    ta, tb = ends[:-1], ends[1:]
    if sig.key == ("PiecewiseLinear",):
        table = np.column_stack((ta, *linear_pieces(sig, ta, tb)))
    else:
        table = np.array([sig.piece(a, b) for a, b in zip(ta.tolist(), tb.tolist())], dtype=float)
    return np.ascontiguousarray(brk, dtype=float), np.ascontiguousarray(table.ravel())


def input_tables(run: "RunState", u_sig: Any, t_end: float) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """The numbers of the input ``u_sig`` (the compiled form of the run's input) in the arguments
    of ``pf_forced``: its parameters ``theta``, the break times below the normalised ``t_end``
    (at least one entry), their count and the per-interval numbers (:func:`_pieces`)."""
    th = np.ascontiguousarray(u_sig.params(), dtype=float)
    brk, pcs = _pieces(run, u_sig, t_end)
    return (th if th.size else np.zeros(1)), (brk if brk.size else np.zeros(1)), int(brk.size), pcs


def run_forced(run: "RunState", t_end: float, n_target: float, times: Optional[np.ndarray],
               buf: Optional[SampleBuffer]) -> None:
    """The whole run of ``run`` on its forced driver up to the normalised ``t_end`` or
    ``n_target`` reversals, samples at the normalised ``times`` into ``buf`` (``times`` None
    and ``buf`` given: every :data:`~prefriction.simulation.samples.DENSE_STEP`)."""
    drv, st, model, sc = run.native_forced, run.st, run.model, run.sc
    state = np.empty(drv.width)
    state[:FHEAD] = (st["t"], st["x"], st["v"], st["s"], st.get("ne", 0), st["rest"], st["W"], st["Ef"],
                     run.A_max, 0.0, 0.0, st.get("Eb", 0.0), math.nan, math.nan)
    state[FHEAD:FHEAD + drv.nz] = st["z"]
    state[FHEAD + drv.nz:FHEAD + drv.nz + drv.nm] = st["m"]
    q = np.ascontiguousarray(run.q, dtype=float)
    u_sig = run.spec.u_sig if run.spec.u_sig is not None else drv.u_sig
    th = np.ascontiguousarray(u_sig.params() if drv.forced else np.zeros(0), dtype=float)
    th = th if th.size else np.zeros(1)
    brk, pcs = _pieces(run, u_sig, t_end)
    nbrk = brk.size
    brk = brk if nbrk else np.zeros(1)
    cfg = np.array([run.eps_native, run.eps, run.snap, sc.t, 1.0 / sc.F, run.force_scale,
                    1.0 if buf is not None else 0.0, 1.0 if drv.linear else 0.0, 1.0 if "Eb" in st else 0.0,
                    1.0 / sc.x])
    fb_args: tuple = ()
    if drv.nc:
        fb_args = controller_numbers(run, state, FHEAD + drv.nz + drv.nm, _pieces(run, run.spec.r_sig, t_end)[1])
    cnt = np.zeros(3, np.int64)
    n_all = len(run.rev)
    # the stiff switch: open-loop runs without dense output (simulation/stiff_forced.py)
    entry = drv.call_stiff if buf is None and not drv.nc and run.system.forced else drv.call
    code = 1

    def call(t_stop: float, td: np.ndarray) -> int:
        nonlocal n_all
        nd = td.size
        out = np.empty((4 + drv.nc) * max(nd, 1))
        cnt[1] = 0
        while True:
            want = int(min(n_target - n_all, BLOCK)) if math.isfinite(n_target) else BLOCK
            if want <= 0:
                return 0
            rev = np.empty(5 * want)
            cnt[0] = 0
            c = entry(q, th, brk, nbrk, pcs, cfg, state, t_stop, want, rev, td if nd else np.zeros(1), nd,
                      out, cnt, *fb_args)
            run.calls += 1
            k = int(cnt[0])
            if k:
                R = rev.reshape(5, want)[:, :k]
                run.rev.extend_columns(R[0], R[1], R[2], R[3])
                run.rev_events.extend(R[4].astype(int).tolist())
                n_all += k
            if c != 0 or n_all >= n_target:
                break
        if buf is not None and cnt[1]:
            j = int(cnt[1])
            O = out[:(4 + drv.nc) * nd].reshape(4 + drv.nc, nd)
            buf.extend(td[:j], O[0, :j], O[1, :j], O[2, :j], O[3, :j], O[4:, :j].T if drv.nc else None)
        return c

    if buf is None:
        code = call(t_end, np.zeros(0))
    elif times is not None:
        for a in range(0, len(times), SAMPLE_BLOCK):
            td = np.ascontiguousarray(times[a:a + SAMPLE_BLOCK], dtype=float)
            code = call(min(t_end, float(td[-1])), td)
            if code != 1 or n_all >= n_target:
                break
        if code == 1 and n_all < n_target and state[0] < t_end:
            code = call(t_end, np.zeros(0))
    else:
        k0 = 0
        while True:
            td = DENSE_STEP * np.arange(k0, k0 + SAMPLE_BLOCK, dtype=float)
            td = td[td <= t_end]
            if td.size and td[-1] < t_end < td[-1] + DENSE_STEP:
                td = np.append(td, t_end)
            if not td.size:
                break
            code = call(min(t_end, float(td[-1])), td)
            if code != 1 or n_all >= n_target or not state[0] < t_end:
                break
            k0 += SAMPLE_BLOCK
    run.steps = (run.steps or 0) + int(cnt[2])
    t, x, v, s, ne, rest, W, Ef, A_max = state[:9].tolist()
    k = FHEAD + drv.nz + drv.nm
    z, m = state[FHEAD:FHEAD + drv.nz].tolist(), state[FHEAD + drv.nz:k].tolist()
    st.update(t=t, x=x, v=v, s=s, z=z, m=m, ne=int(ne), rest=rest, W=W, Ef=Ef,
              F=float(model.force(z, m, v, s, run.q.tolist())))
    if drv.nc:
        st["xc"] = state[k:k + drv.nc].copy()
    if "Eb" in st:
        st["Eb"] = float(state[11])
    run.A_max = A_max
    if code == STIFF:  # the rest of the run on the implicit method (docs/simulator.md#stiff)
        run.note = (f"switched to the implicit Radau method at t = {t * sc.t:.9g} s after {len(run.rev)} "
                    f"reversal{'' if len(run.rev) == 1 else 's'}: the explicit Runge-Kutta step was held by stability "
                    f"(h |lambda| > 3.25 on 15 steps, more than 20,000 steps after the last reversal), the problem is stiff")
        advance_stiff_forced(run, t_end, n_target)
    elif code > 1:
        raise run._failure(_WHY.get(code, f"the native driver stopped (code {code})"))
