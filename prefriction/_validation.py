"""Argument checks whose messages name the argument, its value and the allowed range."""

from __future__ import annotations

import math
from numbers import Real
from typing import Any

import numpy as np


def check_real(name: str, value: Any) -> float:
    """Return ``value`` as a float or raise ``TypeError`` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (Real, np.floating, np.integer)):
        raise TypeError(f"{name} must be a real number, got {value!r} of type {type(value).__name__}")
    return float(value)


def check_finite(name: str, value: Any) -> float:
    """Return ``value`` as a finite float; ``ValueError`` otherwise."""
    v = check_real(name, value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v!r} (allowed: a finite real number)")
    return v


def check_positive(name: str, value: Any) -> float:
    """Return ``value`` as a finite float > 0; ``ValueError`` otherwise."""
    v = check_real(name, value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be finite and > 0, got {v!r} (allowed range: 0 < {name} < inf)")
    return v


def check_nonnegative(name: str, value: Any) -> float:
    """Return ``value`` as a finite float >= 0; ``ValueError`` otherwise."""
    v = check_real(name, value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{name} must be finite and >= 0, got {v!r} (allowed range: 0 <= {name} < inf)")
    return v


def check_interval(name: str, value: Any, lo: float, hi: float) -> float:
    """Return ``value`` as a float in the closed interval ``[lo, hi]``; ``ValueError`` otherwise."""
    v = check_real(name, value)
    if not (lo <= v <= hi):
        raise ValueError(f"{name} must lie in [{lo!r}, {hi!r}], got {v!r}")
    return v


def check_count(name: str, value: Any, minimum: int = 1) -> int:
    """Return ``value`` as an int >= ``minimum``; ``TypeError``/``ValueError`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {value!r} of type {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def check_array_interval(name: str, values: Any, lo: float, hi: float) -> np.ndarray:
    """Return ``values`` as a float array with every entry in ``[lo, hi]``; ``ValueError`` otherwise."""
    arr = np.asarray(values, dtype=float)
    bad = ~((arr >= lo) & (arr <= hi))
    if np.any(bad):
        first = arr[bad].flat[0]
        raise ValueError(f"{name} must lie in [{lo!r}, {hi!r}] (every entry), got {first!r}")
    return arr
