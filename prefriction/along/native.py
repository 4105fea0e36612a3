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
from typing import TYPE_CHECKING, Hashable, Optional

import casadi as ca
import numpy as np

from prefriction.along.step import counted_interval_function
from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import jit_available, library
from prefriction.simulation import library_store as store

if TYPE_CHECKING:
    from prefriction.along.engine import Units
    from prefriction.along.motion import Motion

__all__ = ["along_driver", "run_native"]

_SOURCE = (Path(__file__).parent / "native.c").read_text()
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CACHE: dict = {}
_LOCK = threading.Lock()


def _source(fun: ca.Function, nx: int) -> str:
    """C source: the step ``fun`` (``pf_step``) generated, its work sizes, then ``native.c``."""
    with tempfile.TemporaryDirectory(prefix="prefriction-") as tmp:
        cg = ca.CodeGenerator("pf_along.c", {"with_header": False})
        cg.add(fun)
        cg.generate(tmp + os.sep)
        code = (Path(tmp) / "pf_along.c").read_text()
    head = {"PF_NX": nx, "PF_SZ_ARG": fun.sz_arg(), "PF_SZ_RES": fun.sz_res(), "PF_SZ_IW": fun.sz_iw() + 1,
            "PF_SZ_W": fun.sz_w() + 1}
    return "".join(f"#define {k} {v}\n" for k, v in head.items()) + code + _SOURCE


def along_driver(model: FrictionModel, substeps: Optional[int]) -> Optional[ctypes.CDLL]:
    """The library of ``model``'s structure (``substeps``: None for a model with an exact step),
    built once per process; None without a C compiler or if the build fails."""
    if not jit_available():
        return None
    key: Hashable = (type(model).__module__, type(model).__qualname__, model.structure_key(), substeps)
    with _LOCK:
        if key not in _CACHE:
            fun = counted_interval_function(model, 16 if substeps is None else substeps)
            fun = ca.Function("pf_step", fun.sx_in(), fun.call(fun.sx_in()))
            handle, _ = library(f"along_native_{type(model).__name__.lower()}",
                                _source(fun, model.n_states + model.n_flags), "friction_along in C",
                                functools.partial(store.load_verified, symbols=("pf_along",)),
                                "the CasADi block Function")
            if handle is not None:
                handle.pf_along.restype = None
                handle.pf_along.argtypes = [_D, _D, _D, _D, _D, _D, ctypes.c_long, ctypes.c_double, ctypes.c_double,
                                            ctypes.c_double, _D, _D, _L]
            _CACHE[key] = handle
        return _CACHE[key]


def run_native(lib: ctypes.CDLL, X0: np.ndarray, F_first: float, motion: "Motion", q: np.ndarray,
               U: "Units") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """States ``(n + 1) x nx``, forces [N] and event counts at every sample of ``motion``."""
    n = motion.dt.size
    nx = X0.size
    X = np.empty((n + 1, nx))
    X[0] = X0
    F = np.empty(n + 1)
    F[0] = U.F * F_first
    ev = np.zeros(n + 1, dtype=np.int64)
    c = np.ascontiguousarray
    lib.pf_along(c(motion.v, dtype=float), c(motion.dt, dtype=float), c(motion.s_prev, dtype=float),
                 c(motion.s, dtype=float), c(motion.v_at, dtype=float), c(q, dtype=float), n, 1.0 / U.v, 1.0 / U.t,
                 U.F, X, F, ev)
    return X, F, ev
