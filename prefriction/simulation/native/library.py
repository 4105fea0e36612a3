"""The compiled native driver of one model structure: generated, compiled once, loaded with ctypes.

The source is the model's generated code (:func:`~prefriction.simulation.native.model_code.model_source`)
followed by ``driver.c``; it is compiled and cached like every compiled Function
(:func:`prefriction.simulation.compiled.library`: one library per structure and machine, a
checksum beside it) and loaded with :mod:`ctypes`. ctypes releases the GIL during a call and the
driver keeps no static mutable data, so threads run it in parallel.
"""

from __future__ import annotations

import ctypes
import functools
import threading
import time
from pathlib import Path
from typing import Hashable, Optional

import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.simulation import library_store as store
from prefriction.simulation.compiled import CompileInfo, jit_available, library
from prefriction.simulation.native.model_code import model_source

__all__ = ["HEAD", "NativeDriver", "native_driver"]

HEAD = 8  # run-state entries before z and m (driver.c: st[])
_DRIVER = (Path(__file__).parent / "driver.c").read_text()
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_L = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
_CACHE: dict = {}
_LOCK = threading.Lock()


class NativeDriver:
    """The ``pf_run`` entry point of one structure's library (driver.c)."""

    def __init__(self, lib: ctypes.CDLL, model: FrictionModel, info: CompileInfo) -> None:
        self.lib, self.info = lib, info
        self.nz, self.nm = model.n_states, model.n_flags
        self.width = HEAD + self.nz + self.nm
        self.run = lib.pf_run
        self.run.restype = ctypes.c_int
        self.run.argtypes = [_D, ctypes.c_double, ctypes.c_double, _D, ctypes.c_double, ctypes.c_long,
                             _D, _D, _D, _D, _L, _L]


def native_driver(model: FrictionModel) -> tuple[Optional[NativeDriver], float]:
    """The native driver of ``model``'s structure (built once per process) and the setup time
    [s] of this call, or ``(None, 0)`` if it cannot be used: no C compiler, ``PREFRICTION_NO_JIT``,
    a model with closed-form branches (:meth:`~prefriction.FrictionModel.free_branch`, taken by
    the compact CasADi loop) or a failed compilation."""
    if not jit_available() or model.has_free_branch:
        return None, 0.0
    # the class too: a subclass that changes the dynamics may keep its parent's structure_key
    key: Hashable = (type(model).__module__, type(model).__qualname__, model.structure_key())
    with _LOCK:
        if key in _CACHE:
            return _CACHE[key], 0.0
        start = time.perf_counter()
        handle, info = library(f"native_{type(model).__name__.lower()}", model_source(model) + _DRIVER,
                               "unforced runs in C",
                               functools.partial(store.load_verified, symbols=("pf_run",)),
                               "the CasADi integrator loop")
        driver = None if handle is None else NativeDriver(handle, model, info)
        _CACHE[key] = driver
        return driver, time.perf_counter() - start
