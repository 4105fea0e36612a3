"""``friction_along`` in one C pass: the interval step generated as C, the loop over the samples in C.

:func:`along_driver` builds (once per model structure and sub-step count) a library of the
model's interval step (:func:`prefriction.along.step.counted_interval_function`, generated with
CasADi's code generator) and ``native.c``; :func:`run_native` runs every interval in one call,
reading the motion's arrays and writing the forces into the result's array (no per-block
assembly; ``docs/along.md``). The states and event counts per sample are written only when
asked for: :class:`~prefriction.along.result.AlongResult` asks on first access, by running the
same deterministic pass again.
"""

from __future__ import annotations

import ctypes
import functools
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, Hashable, NamedTuple, Optional

import casadi as ca
import numpy as np

from prefriction.along.emit import straight_line
from prefriction.along.motion import MAX_SAMPLES
from prefriction.along.step import counted_interval_function
from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import generated_source, jit_available, library
from prefriction.simulation import library_store as store

if TYPE_CHECKING:
    from prefriction.along.engine import Units

__all__ = ["NativePass", "along_driver", "fast_samples", "first_direction", "run_native"]

_SOURCE = (Path(__file__).parent / "native.c").read_text()
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CFLAGS = ("-O3", "-ffp-contract=off", "-shared", "-fPIC")
"""-O3: the pass is small and runs per sample (Maxwell-slip(3), 1e6 samples, with the step on CasADi's
buffers: 23 ms at -O3, 28 ms at -O2, 34 ms at the simulator's -O1), for a compile time of well
under a second; -ffp-contract=off: no fused multiply-adds, so the pass that writes the states
computes the same forces, bit for bit, as the one that does not."""
_CACHE: dict = {}
_LOCK = threading.Lock()


_SIGNATURE = ("(const double* X, double dxn, double dtn, double sp, double s, double ve, const double* q, "
              "double* Xn, double* F, double* e)")
_INLINE = "#ifdef __GNUC__\n#define PF_INLINE static inline __attribute__((always_inline))\n#else\n" \
          "#define PF_INLINE static inline\n#endif\n"


def _source(funs: list[ca.Function], nx: int) -> str:
    """C source: the steps ``funs`` (``pf_step``, ``pf_plain``) as inline functions on scalars
    (:func:`prefriction.along.emit.straight_line`; CasADi's code generator for an operation
    without a straight-line form), then ``native.c``."""
    nq = funs[0].nnz_in(6)
    head = (f"#include <math.h>\n#define PF_NX {nx}\n#define PF_NQ {nq}\n" + _INLINE
            + _copy_macro("PF_COPY_X", nx) + _copy_macro("PF_COPY_Q", nq))
    inputs = [lambda j: f"X[{j}]", lambda j: "dxn", lambda j: "dtn", lambda j: "sp", lambda j: "s", lambda j: "ve",
              lambda j: f"q[{j}]"]
    outputs = [lambda j: f"Xn[{j}]", lambda j: "*F", lambda j: "*e"]
    try:
        bodies = [straight_line(fun, inputs, outputs, "v") for fun in funs]
    except NotImplementedError:
        return head + _generated(funs) + _SOURCE
    return head + "".join(f"PF_INLINE void {fun.name()}_in{_SIGNATURE} {{\n{body}\n}}\n"
                          for fun, body in zip(funs, bodies)) + _SOURCE


def _copy_macro(name: str, n: int) -> str:
    """A macro copying ``n`` doubles, one statement each (the compiler then keeps them in registers)."""
    return f"#define {name}(d, s) do {{{''.join(f' (d)[{i}] = (s)[{i}];' for i in range(n))} }} while (0)\n"


def _generated(funs: list[ca.Function]) -> str:
    """The steps by CasADi's code generator, each called from an inline function of the pass's signature."""
    code = generated_source("pf_along", funs)
    for fun in funs:
        code += (f"PF_INLINE void {fun.name()}_in{_SIGNATURE} {{\n"
                 f"  const casadi_real* arg[{fun.sz_arg() + 1}] = {{X, &dxn, &dtn, &sp, &s, &ve, q}};\n"
                 f"  casadi_real* res[{fun.sz_res() + 1}] = {{Xn, F, e}};\n"
                 f"  casadi_int iw[{fun.sz_iw() + 1}];\n  casadi_real w[{fun.sz_w() + 1}];\n"
                 f"  {fun.name()}(arg, res, iw, w, 0);\n}}\n")
    return code


def along_driver(model: FrictionModel, substeps: Optional[int]) -> Optional[ctypes.CDLL]:
    """The library of ``model``'s structure (``substeps``: None for a model with an exact step),
    built once per process; None without a C compiler or if the build fails."""
    if not jit_available():
        return None
    key: Hashable = (type(model).__module__, type(model).__qualname__, model.structure_key(), substeps)
    with _LOCK:
        if key not in _CACHE:
            n_sub = 16 if substeps is None else substeps
            funs = []
            for name, reversal in (("pf_step", True), ("pf_plain", False)):
                fun = counted_interval_function(model, n_sub, reversal=reversal)
                ins = fun.sx_in()
                dxn = ca.SX.sym("dxn")  # the displacement in: v = dxn / dt, so that v dt is dxn exactly
                outs = fun.call([ins[0], dxn / ins[2], *ins[2:]])
                funs.append(ca.Function(name, [ins[0], dxn, *ins[2:]], [ca.densify(out) for out in outs]))
            handle, _ = library(f"along_native_{type(model).__name__.lower()}",
                                _source(funs, model.n_states + model.n_flags), "friction_along in C",
                                functools.partial(store.load_verified,
                                                  symbols=("pf_along", "pf_first_direction", "pf_check")),
                                "the CasADi block Function", cflags=_CFLAGS)
            if handle is not None:
                handle.pf_along.restype = ctypes.c_long
                handle.pf_along.argtypes = [_D, _D, ctypes.c_void_p, _D, ctypes.c_long, ctypes.c_double,
                                            ctypes.c_double, ctypes.c_double, ctypes.c_double, ctypes.c_double, _D,
                                            ctypes.c_void_p, _D, ctypes.c_void_p, _L, _D]
                handle.pf_first_direction.restype = ctypes.c_double
                handle.pf_first_direction.argtypes = [_D, ctypes.c_long]
                handle.pf_check.restype = ctypes.c_int
                handle.pf_check.argtypes = [_D, _D, ctypes.c_void_p, ctypes.c_long, _D, _D]
            _CACHE[key] = handle
        return _CACHE[key]


def first_direction(lib: ctypes.CDLL, x: np.ndarray) -> float:
    """The direction of the motion's first interval with a displacement (+1 if none moves)."""
    return float(lib.pf_first_direction(x, x.size))


def fast_samples(lib: ctypes.CDLL, t: Any, x: Any, v: Any) -> Optional[tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]]:
    """Copies of ``t`` and ``x`` (the result's own) and ``v`` if they are 1-D float64 arrays of one
    length, 2 to :data:`~prefriction.along.motion.MAX_SAMPLES` samples, finite, ``t`` strictly
    increasing (checked in the C pass that copies them); else None (:meth:`Motion.of` then checks
    them and names what is wrong)."""
    given = [t, x] if v is None else [t, x, v]
    for a in given:
        if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 1 and a.flags.c_contiguous
                and a.size == given[0].size):
            return None
    if not 2 <= t.size <= MAX_SAMPLES:
        return None
    tc, xc = np.empty(t.size), np.empty(t.size)  # the result's own t and x (v: copied by the caller)
    if not lib.pf_check(t, x, None if v is None else v.ctypes.data, t.size, tc, xc):
        return None
    return tc, xc, v


class NativePass(NamedTuple):
    """What one C pass wrote: forces [N], reversal samples, the number of model events and
    whether every force is finite; the states ``n x nx`` and event counts per sample only if
    asked for (else None)."""

    F: np.ndarray
    reversals: np.ndarray
    n_events: int
    finite: bool
    X: Optional[np.ndarray]
    events: Optional[np.ndarray]


def run_native(lib: ctypes.CDLL, X0: np.ndarray, F_first: float, t: np.ndarray, x: np.ndarray,
               v: Optional[np.ndarray], s0: float, q: np.ndarray, U: "Units", states: bool = False) -> NativePass:
    """Forces [N] at every sample of the motion ``t, x`` (checked, float, contiguous; ``v`` the
    user's velocities or None), the reversal samples and the number of model events in one C pass
    (the motion's intervals computed there, ``docs/along.md#motion``); ``states``: the states and
    event counts per sample written too (else the pass keeps only the current state)."""
    n = t.size
    nx = X0.size
    X0 = np.ascontiguousarray(X0, dtype=float)
    F = np.empty(n)
    F[0] = U.F * F_first
    X = ev = None
    if states:
        X = np.empty((n, nx))
        X[0] = X0
        ev = np.empty(n, dtype=np.int64)
        ev[0] = 0
    rv = np.empty(max(n - 1, 1), dtype=np.int64)  # pages written only as reversals come
    out = np.zeros(2)
    k = lib.pf_along(t, x, None if v is None else v.ctypes.data, np.ascontiguousarray(q, dtype=float), n, s0,
                     1.0 / U.v, 1.0 / U.t, 1.0 / (U.v * U.t), U.F, X0, None if X is None else X.ctypes.data, F,
                     None if ev is None else ev.ctypes.data, rv, out)
    return NativePass(F, rv[:k].copy(), int(out[0]), bool(np.isfinite(out[1])) and bool(np.isfinite(F[0])), X, ev)
