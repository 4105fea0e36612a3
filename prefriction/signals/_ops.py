"""The operations a signal's expression is built from, for numpy, plain floats and CasADi.

:meth:`prefriction.signals.Signal.expr` builds one expression for every kind of argument: the
kinds call ``ops.sin``, ``ops.where``, ``ops.fmax`` and ``ops.fmin`` of the table they are given.
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np


class NumpyOps:
    """Operations on numpy arrays."""

    sin = staticmethod(np.sin)
    where = staticmethod(np.where)
    fmax = staticmethod(np.maximum)
    fmin = staticmethod(np.minimum)


class MathOps:
    """Operations on scalar floats: the fast path of ``Signal.__call__`` (loops evaluate per sample)."""

    sin = staticmethod(math.sin)
    fmax = staticmethod(max)
    fmin = staticmethod(min)

    @staticmethod
    def where(c: bool, a: float, b: float) -> float:
        """``a`` if ``c`` else ``b``."""
        return a if c else b


class CasadiOps:
    """Operations on CasADi symbols and matrices."""

    sin = staticmethod(ca.sin)
    where = staticmethod(ca.if_else)
    fmax = staticmethod(ca.fmax)
    fmin = staticmethod(ca.fmin)


CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def vector(x: Any, n: int, name: str, casadi: bool) -> Any:
    """Parameter or piece vector ``x`` of length ``n``, as casadi (``casadi=True``) or numpy."""
    if casadi:
        x = x if isinstance(x, CASADI_TYPES) else ca.DM(np.asarray(x, dtype=float).reshape(-1))
        size = x.numel()
    else:
        x = np.asarray(x, dtype=float).reshape(-1)
        size = x.size
    if size != n:
        raise ValueError(f"{name} must have length {n}, got {size}")
    return x
