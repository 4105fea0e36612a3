"""Periodic analytic kinds: :class:`Sine` and the frequency sweep :class:`Chirp`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from prefriction.signals._checks import UNIT, hertz, number, time_end
from prefriction.signals.base import Analytic

__all__ = ["Chirp", "Sine"]


class Sine(Analytic):
    """Sinusoid ``offset + amplitude sin(2 pi frequency t + phase)``.

    Parameters
    ----------
    amplitude : float
        Amplitude [signal units].
    frequency : float
        Frequency [Hz] (cycles per second, not rad/s: ``docs/conventions.md#frequencies``), ``> 0``;
        a value of exactly ``2 pi`` times a round number is refused as a likely angular frequency.
    phase : float, optional
        Phase at ``t = 0`` [rad], default 0.
    offset : float, optional
        Mean value [signal units], default 0.
    """

    __slots__ = ("amplitude", "frequency", "phase", "offset")
    _names = ("amplitude", "frequency", "phase", "offset")

    def __init__(self, amplitude: float, frequency: float, phase: float = 0.0, offset: float = 0.0) -> None:
        self._set(
            amplitude=number("amplitude", amplitude, UNIT),
            frequency=hertz("frequency", frequency, "> 0", lambda v: v > 0.0),
            phase=number("phase", phase, "rad"),
            offset=number("offset", offset, UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[3] + theta[0] * ops.sin(2.0 * math.pi * theta[1] * t + theta[2])

    def bound(self, t_end: float) -> float:
        """``|offset| + |amplitude|`` [signal units] (:meth:`Signal.bound`)."""
        time_end(t_end)
        return abs(self.offset) + abs(self.amplitude)


class Chirp(Analytic):
    """Linear-frequency sweep from ``f0`` to ``f1`` over ``[0, duration]``, then a sine at ``f1``.

    For ``t <= duration`` the value is ``amplitude sin(2 pi (f0 t + (f1 - f0) t^2 / (2 duration)))``;
    afterwards the sine continues at ``f1`` with a continuous phase.

    Parameters
    ----------
    amplitude : float
        Amplitude [signal units].
    f0 : float
        Frequency at ``t = 0`` [Hz], ``>= 0``.
    f1 : float
        Frequency from ``t = duration`` on [Hz], ``>= 0``; ``f0`` and ``f1`` not both 0.
    duration : float
        Length of the sweep [s], ``> 0``.
    """

    __slots__ = ("amplitude", "f0", "f1", "duration")
    _names = ("amplitude", "f0", "f1", "duration")

    def __init__(self, amplitude: float, f0: float, f1: float, duration: float) -> None:
        self._set(
            amplitude=number("amplitude", amplitude, UNIT),
            f0=hertz("f0", f0, ">= 0", lambda v: v >= 0.0),
            f1=hertz("f1", f1, ">= 0", lambda v: v >= 0.0),
            duration=number("duration", duration, "s", "> 0", lambda v: v > 0.0),
        )
        if self.f0 == 0.0 and self.f1 == 0.0:
            raise ValueError(f"f0 and f1 must not both be 0 [Hz] (allowed: f0, f1 >= 0, f0 + f1 > 0), "
                             f"got f0={self.f0!r}, f1={self.f1!r}")

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        a, f0, f1, d = theta[0], theta[1], theta[2], theta[3]
        tc = ops.fmin(t, d)  # time within the sweep
        cycles = f0 * tc + (f1 - f0) * tc * tc / (2.0 * d) + f1 * ops.fmax(t - d, 0.0)
        return a * ops.sin(2.0 * math.pi * cycles)

    def breaks(self) -> np.ndarray:
        """``[duration]`` [s]: the end of the sweep (the chirp rate jumps there)."""
        return np.array([self.duration])

    def bound(self, t_end: float) -> float:
        """``|amplitude|`` [signal units] (:meth:`Signal.bound`)."""
        time_end(t_end)
        return abs(self.amplitude)
