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
from typing import Any, Hashable

import casadi as ca
import numpy as np

from prefriction.along.step import counted_interval_function, has_exact_step
from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import CompileInfo, compiled

__all__ = ["BLOCK", "Stepper", "stepper"]

BLOCK = 4096
"""Samples per call of the compiled block."""

_CACHE: dict[Hashable, "Stepper"] = {}


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
        step = counted_interval_function(model, substeps)
        tag = repr((type(model).__qualname__, model.structure_key(), self.substeps)).encode()
        name = "along_" + hashlib.sha256(tag).hexdigest()[:12]
        block = step.mapaccum(name, BLOCK)
        self.block, self.info = compiled(block, f"friction_along, {type(model).__name__}")
        self.step = step
        self.n_x = model.n_states + model.n_flags
        self.setup_time = time.perf_counter() - start

    def run(self, X0: np.ndarray, rows: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """States, normalised forces and event counts at the ends of the intervals ``rows``
        (``5 x n``: ``v, dt, s_prev, s, v_end``, normalised), from the state ``X0``."""
        n = rows.shape[1]
        X = np.empty((self.n_x, n))
        F = np.empty(n)
        ev = np.empty(n)
        x_k = ca.DM(X0)
        for lo in range(0, n, BLOCK):
            hi = min(lo + BLOCK, n)
            chunk = rows[:, lo:hi]
            if hi - lo < BLOCK:  # pad: intervals of zero duration in the last direction
                pad = np.zeros((5, BLOCK - (hi - lo)))
                pad[2:4, :] = chunk[3, -1]
                chunk = np.hstack((chunk, pad))
            Xb, Fb, Eb = self.block(x_k, chunk[0], chunk[1], chunk[2], chunk[3], chunk[4], q)
            Xb = np.asarray(Xb)
            X[:, lo:hi] = Xb[:, : hi - lo]
            F[lo:hi] = np.asarray(Fb).ravel()[: hi - lo]
            ev[lo:hi] = np.asarray(Eb).ravel()[: hi - lo]
            x_k = ca.DM(Xb[:, hi - lo - 1])
        return X, F, ev


def stepper(model: FrictionModel, substeps: int) -> Stepper:
    """The :class:`Stepper` of ``model``'s structure, built and compiled once per process
    (``substeps`` only matters for a model without an exact step)."""
    key = (type(model), model.structure_key(), None if has_exact_step(model) else substeps)
    if key not in _CACHE:
        _CACHE[key] = Stepper(model, substeps)
    return _CACHE[key]


def compile_info(model: FrictionModel, substeps: int) -> CompileInfo:
    """How the block Function of ``model``'s structure was obtained (compiled, cached, interpreted)."""
    return stepper(model, substeps).info
