"""The CasADi integrator of a plant, built once per specification and called through persistent buffers."""

from __future__ import annotations

import time
import warnings

import casadi as ca
import numpy as np

from ._jit import compiled
from ._plant import Layout, PlantSpec, build_integrator

_CACHE: dict = {}
INTEGRATOR_FAILED = (
    "the integrator stopped with an error before the end of its interval (a non-finite right-hand "
    "side such as a NaN input, a step below its minimum, or more steps or events than allowed)"
)


class BufferedIntegrator:
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


def integrator(spec: PlantSpec, tol: float, atol: float, jit: bool) -> tuple[BufferedIntegrator, float, str]:
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
    call = BufferedIntegrator(fun, Layout(spec), spec.n_out)
    setup = time.perf_counter() - start
    _CACHE[key] = (call, mode)
    return call, setup, mode
