"""Numeric building blocks of the exact interval steps (:meth:`FrictionModel.advance`), for
floats and CasADi symbols alike: a branch-free choice and the exponentials they need.

The steps themselves are in the model files (``advance``); ``docs/along.md#exact-steps``
derives them.
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca

__all__ = ["expm1", "exp", "log1p_ratio", "pick", "symbolic"]


def symbolic(*xs: Any) -> bool:
    """True if any argument is a CasADi symbol."""
    return any(isinstance(x, (ca.SX, ca.MX)) for x in xs)


def pick(cond: Any, a: Any, b: Any) -> Any:
    """``a`` where ``cond`` holds, else ``b`` (``casadi.if_else`` on symbols)."""
    if symbolic(cond, a, b):
        return ca.if_else(cond, a, b)
    return a if cond else b


def exp(x: Any) -> Any:
    """``exp(x)``."""
    return ca.exp(x) if symbolic(x) else math.exp(x)


def expm1(x: Any) -> Any:
    """``exp(x) - 1`` to full relative accuracy near 0."""
    return ca.expm1(x) if symbolic(x) else math.expm1(x)


def log1p_ratio(y: Any) -> Any:
    """``log(1 + y) / y`` (1 at ``y = 0``), smooth through 0 (a series for ``|y| < 1e-4``:
    error below 3e-17), for ``y > -1``."""
    series = 1.0 - y / 2.0 + y * y / 3.0 - y * y * y / 4.0
    if symbolic(y):
        safe = ca.if_else(ca.fabs(y) < 1e-4, 1.0, y)
        return ca.if_else(ca.fabs(y) < 1e-4, series, ca.log1p(safe) / safe)
    return series if abs(y) < 1e-4 else math.log1p(y) / y
