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


def check_signal(name: str, value: Any, unit: str, letter: str) -> Any:
    """Validate a time signal: a finite number, a callable of time, or samples ``(t, values)``.

    Parameters
    ----------
    name : str
        Argument name used in error messages (e.g. ``"u"`` or ``"reference"``).
    value : number, callable or tuple
        The signal. Samples are a pair of 1-D arrays of equal length >= 2, finite, with
        strictly increasing times [s]; they are returned as read-only float arrays.
    unit : str
        Unit of the signal's values, for messages (e.g. ``"N"`` or ``"m"``).
    letter : str
        Symbol of the signal in messages, as in ``(t, r)``.

    Returns
    -------
    float, callable or (numpy.ndarray, numpy.ndarray)
    """
    if callable(value):
        return value
    if isinstance(value, tuple):
        if len(value) != 2:
            raise ValueError(f"{name} samples must be a pair (t, {letter}), got a tuple of length {len(value)}")
        t = np.array(value[0], dtype=float)
        val = np.array(value[1], dtype=float)
        if t.ndim != 1 or val.shape != t.shape or t.size < 2:
            raise ValueError(
                f"{name} samples must be a pair (t, {letter}) of 1-D arrays of equal length >= 2, "
                f"got shapes {t.shape} and {val.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(val))):
            raise ValueError(f"{name} samples must be finite (t and {letter}), got NaN or inf")
        if np.any(np.diff(t) <= 0):
            raise ValueError(f"{name} sample times t must be strictly increasing")
        t.setflags(write=False)
        val.setflags(write=False)
        return (t, val)
    if isinstance(value, (list, np.ndarray)):
        raise TypeError(
            f"{name} must be a number [{unit}], a callable {letter}(t) or a pair (t, {letter}) of sample "
            f"arrays; got a bare {type(value).__name__}: pass (t, {letter}) with the sample times"
        )
    try:
        return check_finite(name, value)
    except TypeError:
        raise TypeError(
            f"{name} must be a number [{unit}], a callable {letter}(t) of time t [s] or a pair (t, {letter}) "
            f"of sample arrays, got {value!r} of type {type(value).__name__}"
        ) from None
