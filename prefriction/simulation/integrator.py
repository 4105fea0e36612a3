"""The CasADi integrator of a plant, built once per specification and called through persistent buffers."""

from __future__ import annotations

import time
import warnings
from typing import Any

import casadi as ca
import numpy as np

from prefriction.simulation.compiled import compiled, jit_available
from prefriction.simulation.per_thread import PerThread
from prefriction.simulation.plant import PlantSpec, build_integrator

_CACHE = PerThread()  # one Function per structure and process, its buffers per thread
INTEGRATOR_FAILED = (
    "the integrator stopped with an error before the end of its interval (a non-finite right-hand "
    "side such as a NaN input, a step below its minimum, or more steps or events than allowed)"
)


class BufferedIntegrator:
    """A CasADi integrator with persistent argument and result arrays (calls cost ~2 us, not ~50 us)."""

    def __init__(self, fun: ca.Function) -> None:
        self.fun = fun
        nx, n_p, (nu, n_out) = fun.size1_in(0), fun.size1_in(2), fun.size_in(3)  # the plant's Layout sizes
        self.X0 = np.zeros(nx)
        self.P = np.zeros(n_p)
        self.U = np.zeros((n_out, nu))  # row j = column j of CasADi's column-major u
        self.out = np.zeros(n_out * nx)
        self.buf, self.trigger = fun.buffer()
        self.buf.set_arg(0, memoryview(self.X0))
        self.buf.set_arg(2, memoryview(self.P))
        self.buf.set_arg(3, memoryview(self.U.reshape(-1)))
        self.buf.set_res(0, memoryview(self.out))


def integrator(spec: PlantSpec, jit: bool) -> tuple[BufferedIntegrator, float, str]:
    """Build (or reuse) the integrator of the structure ``spec``; returns it, the setup time and
    the JIT mode. One Function per structure and process (numbers and tolerances are run-time
    inputs), called through buffers of the calling thread: runs in threads do not interfere."""
    jit = jit and jit_available()  # PREFRICTION_NO_JIT may change between calls
    call, (_, mode, setup), built = _CACHE.get(
        (spec, jit), lambda: _build(spec, jit), lambda made: BufferedIntegrator(made[0]))
    if built:
        return call, setup, mode
    return call, 0.0, mode if mode == "interpreted" else "cached"


def _build(spec: PlantSpec, jit: bool) -> tuple[Any, str, float]:
    """The Function of ``spec`` (compiled or loaded from the cache if ``jit``), its mode and setup time."""
    start = time.perf_counter()
    what = _describe(spec)  # for the compile message
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        fun = build_integrator(spec)
    mode = "interpreted"
    if jit:
        fun, info = compiled(fun, what)
        mode = info.mode
    return fun, mode, time.perf_counter() - start


def _describe(spec: PlantSpec) -> str:
    """One line on what a plant is, for the compile message."""
    key = spec.model_key[2]
    what = [" ".join(str(k) for k in key) if isinstance(key, tuple) else str(key)]
    for name, key in (("input", spec.u_key), ("reference", spec.r_key)):
        if key is None:
            continue
        if key[0] == "Traced":
            what.append(f"{name} from a Python callable: compiled once per function object; "
                        f"prefriction.signals (Sine, Step, Ramp, Chirp, Samples) compile once per kind")
        else:
            what.append(f"{name} {key}")
    if spec.fb != "none":
        what.append(f"{spec.fb} controller of order {spec.n_c}")
    if spec.energy:
        what.append("dense output")
    return ", ".join(what)
