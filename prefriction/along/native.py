"""``friction_along`` in one C pass: the interval step generated as C, the loop over the samples in C.

:func:`along_driver` builds (once per model structure and sub-step count) a library of the
model's interval step (:func:`prefriction.along.step.counted_interval_function`, generated with
CasADi's code generator) and ``native.c``; :func:`run_native` runs every interval in one call,
reading the motion's arrays and writing the states, forces and event counts into the arrays
of the result (no per-block assembly; ``docs/along.md``).
"""

from __future__ import annotations

import ctypes
import functools
import os
import tempfile
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, Hashable, Optional

import casadi as ca
import numpy as np

from prefriction.along.motion import MAX_SAMPLES
from prefriction.along.step import counted_interval_function
from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import jit_available, library
from prefriction.simulation import library_store as store

if TYPE_CHECKING:
    from prefriction.along.engine import Units

__all__ = ["along_driver", "fast_samples", "first_direction", "run_native"]

_SOURCE = (Path(__file__).parent / "native.c").read_text()
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CFLAGS = ("-O3", "-shared", "-fPIC")
"""The pass is small and runs per sample: -O3 makes it 1.5x as fast as the simulator's -O1 (Maxwell-slip(3),
1e6 samples: 23 ms against 34 ms; -O2 28 ms), for a compile time of well under a second."""
_CACHE: dict = {}
_LOCK = threading.Lock()


def _source(funs: list[ca.Function], nx: int) -> str:
    """C source: the steps ``funs`` (``pf_step``, ``pf_plain``) generated, their work sizes, then ``native.c``."""
    with tempfile.TemporaryDirectory(prefix="prefriction-") as tmp:
        cg = ca.CodeGenerator("pf_along.c", {"with_header": False})
        for fun in funs:
            cg.add(fun)
        cg.generate(tmp + os.sep)
        code = (Path(tmp) / "pf_along.c").read_text()
    head = {"PF_NX": nx, "PF_SZ_ARG": max(f.sz_arg() for f in funs), "PF_SZ_RES": max(f.sz_res() for f in funs),
            "PF_SZ_IW": max(f.sz_iw() for f in funs) + 1, "PF_SZ_W": max(f.sz_w() for f in funs) + 1}
    return "".join(f"#define {k} {v}\n" for k, v in head.items()) + code + _SOURCE


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
                funs.append(ca.Function(name, fun.sx_in(), fun.call(fun.sx_in())))
            handle, _ = library(f"along_native_{type(model).__name__.lower()}",
                                _source(funs, model.n_states + model.n_flags), "friction_along in C",
                                functools.partial(store.load_verified,
                                                  symbols=("pf_along", "pf_first_direction", "pf_check")),
                                "the CasADi block Function", cflags=_CFLAGS)
            if handle is not None:
                handle.pf_along.restype = ctypes.c_long
                handle.pf_along.argtypes = [_D, _D, ctypes.c_void_p, _D, ctypes.c_long, ctypes.c_double,
                                            ctypes.c_double, ctypes.c_double, ctypes.c_double, _D, _D, _L, _D, _L]
                handle.pf_first_direction.restype = ctypes.c_double
                handle.pf_first_direction.argtypes = [_D, ctypes.c_long]
                handle.pf_check.restype = ctypes.c_int
                handle.pf_check.argtypes = [_D, _D, ctypes.c_void_p, ctypes.c_long]
            _CACHE[key] = handle
        return _CACHE[key]


def first_direction(lib: ctypes.CDLL, x: np.ndarray) -> float:
    """The direction of the motion's first interval with a displacement (+1 if none moves)."""
    return float(lib.pf_first_direction(x, x.size))


def fast_samples(lib: ctypes.CDLL, t: Any, x: Any, v: Any) -> Optional[tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]]:
    """``t, x, v`` as they are if they are 1-D float64 arrays of one length, 2 to
    :data:`~prefriction.along.motion.MAX_SAMPLES` samples, finite, ``t`` strictly increasing
    (checked in one C pass; ``t`` and ``x`` copied for the result); else None (:meth:`Motion.of` then checks them and names
    what is wrong)."""
    given = [t, x] if v is None else [t, x, v]
    for a in given:
        if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 1 and a.flags.c_contiguous
                and a.size == given[0].size):
            return None
    if not 2 <= t.size <= MAX_SAMPLES:
        return None
    if not lib.pf_check(t, x, None if v is None else v.ctypes.data, t.size):
        return None
    return t.copy(), x.copy(), v  # the result's own t and x (v: read into the result's velocities)


def run_native(lib: ctypes.CDLL, X0: np.ndarray, F_first: float, t: np.ndarray, x: np.ndarray,
               v: Optional[np.ndarray], s0: float, q: np.ndarray,
               U: "Units") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """States ``n x nx``, forces [N], event counts and velocities [m/s] at every sample of the
    motion ``t, x`` (checked, float, contiguous; ``v`` the user's velocities or None), and the
    reversal samples, in one C pass (the motion's intervals computed there, ``docs/along.md#motion``)."""
    n = t.size
    nx = X0.size
    X = np.empty((n, nx))
    X[0] = X0
    F = np.empty(n)
    F[0] = U.F * F_first
    ev = np.empty(n, dtype=np.int64)
    ev[0] = 0
    va = np.empty(n)
    rv = np.empty(max(n - 1, 1), dtype=np.int64)  # pages written only as reversals come
    k = lib.pf_along(t, x, None if v is None else v.ctypes.data, np.ascontiguousarray(q, dtype=float), n, s0,
                     1.0 / U.v, 1.0 / U.t, U.F, X, F, ev, va, rv)
    return X, F, ev, va, rv[:k].copy()
