"""Piecewise-linear analytic kinds: :class:`Constant`, :class:`Step` and :class:`Ramp`.

The simulator compiles them (and :class:`~prefriction.signals.Samples`, and their sums) in one
structure, their value and slope given per integration interval
(:func:`~prefriction.signals.compiled_form`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from prefriction.signals._checks import UNIT, number, time_end
from prefriction.signals.base import Analytic, Signal

__all__ = ["Constant", "Ramp", "Step"]


class Constant(Analytic):
    """Constant signal.

    Parameters
    ----------
    value : float
        The value [signal units], finite.
    """

    __slots__ = ("value",)
    _names = ("value",)

    def __init__(self, value: float) -> None:
        self._set(value=number("value", value, UNIT))

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[0]

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(value, 0)``: a constant is piecewise linear."""
        return self.value, 0.0

    def bound(self, t_end: float) -> float:
        """``|value|`` [signal units] (:meth:`Signal.bound`)."""
        time_end(t_end)
        return abs(self.value)


class Step(Analytic):
    """Step: ``before`` for ``t < time``, ``after`` for ``t >= time``.

    Parameters
    ----------
    time : float
        Switching time [s], ``>= 0``.
    before : float
        Value before the step [signal units].
    after : float
        Value from the step on [signal units].
    """

    __slots__ = ("time", "before", "after")
    _names = ("time", "before", "after")

    def __init__(self, time: float, before: float, after: float) -> None:
        self._set(
            time=number("time", time, "s", ">= 0", lambda v: v >= 0.0),
            before=number("before", before, UNIT),
            after=number("after", after, UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return ops.where(t >= theta[0], theta[2], theta[1])

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(before or after, 0)`` by the midpoint of ``[ta, tb]``."""
        return (self.after if 0.5 * (ta + tb) >= self.time else self.before), 0.0

    def breaks(self) -> np.ndarray:
        """``[time]`` [s]: the switching time."""
        return np.array([self.time])

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`):
        ``max(|before|, |after|)``, or ``|before|`` if the step comes after ``t_end`` [s]."""
        if time_end(t_end) < self.time:
            return abs(self.before)
        return max(abs(self.before), abs(self.after))


class Ramp(Analytic):
    """Ramp: ``offset`` for ``t < time``, ``offset + slope (t - time)`` afterwards.

    Parameters
    ----------
    time : float
        Start of the ramp [s], ``>= 0``.
    slope : float
        Slope [signal units / s].
    offset : float, optional
        Value before the ramp [signal units], default 0.
    """

    __slots__ = ("time", "slope", "offset")
    _names = ("time", "slope", "offset")

    def __init__(self, time: float, slope: float, offset: float = 0.0) -> None:
        self._set(
            time=number("time", time, "s", ">= 0", lambda v: v >= 0.0),
            slope=number("slope", slope, UNIT + " / s"),
            offset=number("offset", offset, UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[2] + theta[1] * ops.fmax(t - theta[0], 0.0)

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(offset + slope (ta - time), slope)`` after ``time``, ``(offset, 0)`` before."""
        if 0.5 * (ta + tb) > self.time:
            return self.offset + self.slope * (ta - self.time), self.slope
        return self.offset, 0.0

    def breaks(self) -> np.ndarray:
        """``[time]`` [s]: the start of the ramp."""
        return np.array([self.time])

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`; exact, the
        value is monotonic): ``max(|offset|, |offset + slope max(t_end - time, 0)|)``."""
        end = self.offset + self.slope * max(time_end(t_end) - self.time, 0.0)
        return max(abs(self.offset), abs(end))


Signal._constant = Constant  # Signal.__add__ builds it (the kinds import Signal, not the reverse)
