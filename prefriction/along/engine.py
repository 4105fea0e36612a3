"""The compiled interval step of a model structure, run over blocks of samples.

One CasADi Function per model structure (:func:`prefriction.identify.stepping.counted_interval_function`),
repeated with ``mapaccum`` over :data:`BLOCK` samples and compiled once (cached on disk,
:func:`prefriction.simulation.compiled.compiled`); a Python loop runs it block after block, the
last block padded with intervals of zero duration. The same step, unmapped, serves the streaming
form. Everything numeric (data, parameters through the run-time numbers ``q``) is an input.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass
from typing import Hashable

import casadi as ca
import numpy as np

from prefriction.along.step import counted_interval_function, has_exact_step
from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import CompileInfo, compiled

__all__ = ["BLOCK", "BufferedStep", "Stepper", "stepper"]

BLOCK = 4096
"""Samples per call of the compiled block."""

_CACHE: dict[Hashable, "Stepper"] = {}
_EXACT: dict[Hashable, bool] = {}


@dataclass(frozen=True)
class Units:
    """SI value of one normalised unit for a unit mass: force ``F`` [N], time ``t`` [s],
    velocity ``v`` [m/s] (``docs/along.md#units``)."""

    F: float
    t: float
    v: float

    @classmethod
    def of(cls, model: FrictionModel) -> "Units":
        return cls(model.Fc, 1.0 / math.sqrt(model.sigma), model.Fc / math.sqrt(model.sigma))


class Stepper:
    """The compiled step of one model structure: a block runner and a single step."""

    def __init__(self, model: FrictionModel, substeps: int) -> None:
        start = time.perf_counter()
        self.exact = has_exact_step(model)
        self.substeps = None if self.exact else substeps
        self.step = counted_interval_function(model, substeps)
        tag = repr((type(model).__qualname__, model.structure_key(), self.substeps)).encode()
        self._name = "along_" + hashlib.sha256(tag).hexdigest()[:12]
        self._what = f"friction_along, {type(model).__name__}"
        self._block: tuple[ca.Function, CompileInfo] | None = None
        self._single: ca.Function | None = None
        self.n_x = model.n_states + model.n_flags
        self.setup_time = time.perf_counter() - start

    def _compiled_block(self) -> tuple[ca.Function, CompileInfo]:
        """The block Function, built and compiled on first use (the C pass of
        :mod:`prefriction.along.native` does not need it)."""
        if self._block is None:
            start = time.perf_counter()
            self._block = compiled(self.step.mapaccum(self._name, BLOCK), self._what)
            self.setup_time += time.perf_counter() - start
        return self._block

    @property
    def block(self) -> ca.Function:
        """The step repeated over :data:`BLOCK` samples (``mapaccum``), compiled."""
        return self._compiled_block()[0]

    @property
    def info(self) -> CompileInfo:
        """How the block Function was obtained (compiled, cached, interpreted)."""
        return self._compiled_block()[1]

    def buffered(self) -> "BufferedStep":
        """The single step, compiled on first use, behind CasADi's buffer interface (for a loop)."""
        if self._single is None:
            self._single = compiled(self.step, "FrictionStream")[0]
        return BufferedStep(self._single)

    def run(self, X0: np.ndarray, rows: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """States, normalised forces and event counts at the ends of the intervals ``rows``
        (``5 x n``: ``v, dt, s_prev, s, v_end``, normalised), from the state ``X0``.

        The block is called through CasADi's buffer interface on numpy arrays (no conversions);
        the last block is padded with intervals of zero duration in the last direction."""
        n, nx = rows.shape[1], self.n_x
        X = np.empty((nx, n))
        F = np.empty(n)
        ev = np.empty(n)
        call = BufferedStep(self.block)
        ins, outs = call.inputs, call.outputs
        ins[0][:] = X0
        ins[6][:] = np.tile(q, BLOCK)  # the block maps q too: one column per interval
        for lo in range(0, n, BLOCK):
            hi = min(lo + BLOCK, n)
            m = hi - lo
            for r in range(5):
                ins[r + 1][:m] = rows[r, lo:hi]
            if m < BLOCK:
                ins[1][m:] = ins[2][m:] = ins[5][m:] = 0.0
                ins[3][m:] = ins[4][m:] = rows[3, hi - 1]
            call.call()
            Xb = outs[0].reshape(BLOCK, nx).T  # column-major nx x BLOCK
            X[:, lo:hi] = Xb[:, :m]
            F[lo:hi] = outs[1][:m]
            ev[lo:hi] = outs[2][:m]
            ins[0][:] = Xb[:, m - 1]
        return X, F, ev


def stepper(model: FrictionModel, substeps: int) -> Stepper:
    """The :class:`Stepper` of ``model``'s structure, built and compiled once per process
    (``substeps`` only matters for a model without an exact step)."""
    structure = (type(model), model.structure_key())
    if structure not in _EXACT:
        _EXACT[structure] = has_exact_step(model)
    key = (*structure, None if _EXACT[structure] else substeps)
    if key not in _CACHE:
        _CACHE[key] = Stepper(model, substeps)
    return _CACHE[key]


def compile_info(model: FrictionModel, substeps: int) -> CompileInfo:
    """How the block Function of ``model``'s structure was obtained (compiled, cached, interpreted)."""
    return stepper(model, substeps).info


class BufferedStep:
    """One interval step called through CasADi's buffer interface: the inputs and outputs are
    numpy arrays filled in place (a call costs well under a microsecond, against about 100 µs
    for an ordinary call from Python)."""

    def __init__(self, fun: ca.Function) -> None:
        self.inputs = [np.zeros(fun.nnz_in(i)) for i in range(fun.n_in())]
        self.outputs = [np.zeros(fun.nnz_out(i)) for i in range(fun.n_out())]
        self._buffer, self._call = fun.buffer()
        for i, a in enumerate(self.inputs):
            self._buffer.set_arg(i, memoryview(a))
        for i, a in enumerate(self.outputs):
            self._buffer.set_res(i, memoryview(a))

    def call(self) -> None:
        """Evaluate on the current ``inputs`` into ``outputs``."""
        self._call()

    def __call__(self, v: float, dt: float, s_prev: float, s: float, v_end: float) -> tuple[float, float]:
        """Advance the state held in ``inputs[0]`` by one interval; the normalised force and the
        number of events in it."""
        ins = self.inputs
        ins[1][0], ins[2][0], ins[3][0], ins[4][0], ins[5][0] = v, dt, s_prev, s, v_end
        self._call()
        ins[0][:] = self.outputs[0]
        return float(self.outputs[1][0]), float(self.outputs[2][0])
