"""Argument checks shared by the signal kinds: real numbers with a unit and a rule."""

from __future__ import annotations

import math
from numbers import Real
from typing import Any, Callable

import numpy as np

UNIT = "signal units"
"""Unit of signal values in messages (a signal may be a force [N], a position [m], ...)."""


def is_real(value: Any) -> bool:
    """True for a real number (Python or numpy), False for booleans and everything else."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (Real, np.floating, np.integer))


def number(name: str, value: Any, unit: str, rule: str = "", ok: Callable[[float], bool] = lambda v: True) -> float:
    """``value`` as a finite float satisfying ``ok``; messages name ``name``, the value and ``rule``."""
    allowed = f"a finite real number{(' ' + rule) if rule else ''} [{unit}]"
    if not is_real(value):
        raise TypeError(f"{name} must be {allowed}, got {value!r} of type {type(value).__name__}")
    v = float(value)
    if not (math.isfinite(v) and ok(v)):
        raise ValueError(f"{name} must be {allowed}, got {v!r}")
    return v


def time_end(t_end: Any) -> float:
    """``t_end`` [s] of a signal's :meth:`~prefriction.signals.Signal.bound` as a float ``>= 0``."""
    return number("t_end", t_end, "s", ">= 0", lambda v: v >= 0.0)


def hertz(name: str, value: Any, rule: str, ok: Callable[[float], bool]) -> float:
    """A frequency in Hz (``number`` with the unit), refusing a value in rad/s by mistake.

    Signals take cycles per second (Hz); controller designs and python-control take rad/s. A value
    that is exactly ``2 pi`` times a number with at most two decimals (``2 * math.pi * 150``,
    942.4778 "Hz"; up to 2 pi 1e4, where such a coincidence is still telling) is almost surely an
    angular frequency passed where Hz belong: refused, with both readings
    (``docs/conventions.md#frequencies``).
    """
    v = number(name, value, "Hz", rule, ok)
    cycles = v / (2.0 * math.pi) * 100.0
    if 0.0 < cycles <= 1e6 and round(cycles) > 0 and abs(cycles - round(cycles)) <= 1e-11 * cycles:
        raise ValueError(f"{name}={v!r} Hz is 2 pi x {round(cycles) / 100:g}: it looks like an angular frequency "
                         f"[rad/s]. Signals take Hz (cycles per second): pass {name}={round(cycles) / 100:g} for "
                         f"{round(cycles) / 100:g} Hz, or {name}={v!r} / (2 * math.pi) if {v!r} rad/s was meant")
    return v
