"""Conversion of the user-facing signal arguments (number, samples, callable) to signals."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from prefriction.signals._checks import is_real, number
from prefriction.signals.base import Signal
from prefriction.signals.piecewise import Constant
from prefriction.signals.samples import Samples
from prefriction.signals.traced import Traced

__all__ = ["as_signal"]


def as_signal(value: Any, name: str, unit: str) -> Optional[Signal]:
    """Convert a user-facing signal argument to a :class:`Signal`.

    Parameters
    ----------
    value : None, Signal, float, (array_like, array_like) or callable
        ``None`` (no signal), a signal, a finite real number (a :class:`Constant`), samples
        ``(t, values)`` (a :class:`Samples`) or a callable of time [s] (a :class:`Traced`).
    name : str
        Argument name for error messages (e.g. ``"u"``, ``"reference"``).
    unit : str
        Unit of the values for error messages (e.g. ``"N"``, ``"m"``).

    Returns
    -------
    Signal or None
        ``None`` only for ``None``.

    Raises
    ------
    TypeError, ValueError
        With a message naming ``name``.
    """
    if value is None or isinstance(value, Signal):
        return value
    if is_real(value):
        return Constant(number(name, value, unit))
    if isinstance(value, tuple):
        if len(value) != 2:
            raise ValueError(f"{name} samples must be a pair (t, values), got a tuple of length {len(value)}")
        return Samples(value[0], value[1], name=name, unit=unit)
    if callable(value):
        return Traced(value, name=name)
    hint = " (for samples pass a pair (t, values) with the sample times)" if isinstance(value, (list, np.ndarray)) else ""
    raise TypeError(
        f"{name} must be None, a Signal (prefriction.signals), a finite real number [{unit}], a pair "
        f"(t, values) of sample arrays or a callable of time t [s]; got {value!r} of type "
        f"{type(value).__name__}{hint}"
    )
