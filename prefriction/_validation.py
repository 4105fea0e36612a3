"""Argument checks whose messages name the argument, its value and the allowed range."""

from __future__ import annotations

import math
from numbers import Real
from typing import Any, Optional, Sequence

import numpy as np

MAX_ARRAY_SIZE = 100_000_000
"""Most entries accepted in an array argument (0.8 GB of doubles)."""


def _short(value: Any, limit: int = 80) -> str:
    """``repr(value)`` cut to ``limit`` characters (a numpy scalar as its Python value: ``0.5``, not ``np.float64(0.5)``)."""
    text = repr(value.item() if isinstance(value, np.generic) else value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_real(name: str, value: Any) -> float:
    """Return ``value`` as a float or raise ``TypeError`` naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Real, np.floating, np.integer)):
        raise TypeError(f"{name} must be a real number, got {_short(value)} of type {type(value).__name__}")
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


def check_count(name: str, value: Any, minimum: int = 1, maximum: Optional[int] = None, why: str = "") -> int:
    """Return ``value`` as an int in ``[minimum, maximum]``; ``TypeError``/``ValueError`` otherwise.

    ``maximum`` is a size limit (memory or run time); ``why`` says what it protects, for the message.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {_short(value)} of type {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    if maximum is not None and value > maximum:
        reason = f" ({why})" if why else ""
        raise ValueError(f"{name} must be an integer <= {maximum:_}, got {value!r}: the limit{reason}")
    return int(value)


def check_bool(name: str, value: Any) -> bool:
    """Return ``value`` if it is ``True`` or ``False`` (numpy booleans too); ``TypeError`` otherwise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {_short(value)} of type {type(value).__name__}")
    return bool(value)


def check_choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """Return ``value`` if it is one of the strings ``choices``; ``TypeError``/``ValueError`` otherwise."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {tuple(choices)!r}, got {_short(value)} of type {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {tuple(choices)!r}, got {value!r}")
    return value


def check_real_array(name: str, values: Any, unit: str = "", *, lo: float = -math.inf, hi: float = math.inf,
                     max_size: int = MAX_ARRAY_SIZE) -> np.ndarray:
    """Return ``values`` (a real number or an array of them) as a float array, every entry finite
    and in ``[lo, hi]``.

    ``TypeError`` for ``None``, strings, booleans, complex numbers, objects and ragged nesting;
    ``ValueError`` for a non-finite entry, an entry outside ``[lo, hi]`` or more than
    ``max_size`` entries. Messages name ``name`` (with the index of the first bad entry), the
    value and the allowed range.
    """
    unit_txt = f" [{unit}]" if unit else ""
    allowed = f"a real number or an array of finite real numbers{unit_txt}"
    if values is None or isinstance(values, (str, bytes, dict, set)):
        raise TypeError(f"{name} must be {allowed}, got {_short(values)} of type {type(values).__name__}")
    try:
        raw = np.asarray(values)
    except (ValueError, TypeError):  # ragged nesting
        raise TypeError(f"{name} must be {allowed}, got {_short(values)} (ragged or mixed nesting)") from None
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be {allowed}, got {_short(values)} (an array of dtype {raw.dtype})")
    if raw.size > max_size:
        raise ValueError(f"{name} must have at most {max_size:_} entries (memory), got {raw.size:_}")
    arr = raw.astype(float)
    bad = ~np.isfinite(arr) | (arr < lo) | (arr > hi)
    if np.any(bad):
        where = "" if arr.ndim == 0 else f"[{', '.join(str(int(i)) for i in np.argwhere(bad)[0])}]"
        value = float(arr[bad].flat[0])
        rng = "-inf < {n} < inf" if lo == -math.inf and hi == math.inf else f"{lo!r} <= {{n}} <= {hi!r}"
        raise ValueError(f"{name}{where} must be finite and in [{lo!r}, {hi!r}]{unit_txt}, got {value!r} "
                         f"(allowed range: {rng.format(n=name)})")
    return arr


def check_broadcast(**arrays: np.ndarray) -> tuple[int, ...]:
    """The common shape of the named arrays; ``ValueError`` naming them and their shapes if
    numpy cannot broadcast them together."""
    try:
        return np.broadcast_shapes(*(np.shape(a) for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{k} has shape {np.shape(a)}" for k, a in arrays.items())
        raise ValueError(f"{' and '.join(arrays)} must have equal or broadcastable shapes, got: {shapes}") from None


def check_array_interval(name: str, values: Any, lo: float, hi: float) -> np.ndarray:
    """Return ``values`` as a float array with every entry in ``[lo, hi]``; ``ValueError``/``TypeError`` otherwise."""
    try:
        return check_real_array(name, values, lo=lo, hi=hi)
    except ValueError as exc:
        if "entries (memory)" in str(exc):
            raise
        arr = np.asarray(values, dtype=float)
        first = float(arr[~(np.isfinite(arr) & (arr >= lo) & (arr <= hi))].flat[0])
        raise ValueError(f"{name} must lie in [{lo!r}, {hi!r}] (every entry finite), got {first!r}") from None


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
        t = np.array(check_real_array(f"{name} samples t", value[0]), dtype=float)
        val = np.array(check_real_array(f"{name} samples {letter}", value[1]), dtype=float)
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
