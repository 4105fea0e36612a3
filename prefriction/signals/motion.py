"""Point-to-point motion profiles: jerk-limited S-curve and trapezoidal velocity (:class:`PointToPoint`)."""

from __future__ import annotations

import math
from collections.abc import Hashable
from typing import Any, Optional, Union

import numpy as np

from prefriction._validation import check_real_array
from prefriction.signals._checks import number, time_end
from prefriction.signals.base import Signal

__all__ = ["PointToPoint"]


def _scurve_times(d: float, v: float, a: float, j: float) -> tuple[float, float, float]:
    """Jerk time ``tj``, constant-acceleration time ``ta`` and cruise time ``tv`` [s] of the
    symmetric seven-segment profile over the distance ``d`` with the limits ``v, a, j``."""

    def phases(vp: float) -> tuple[float, float]:
        tj = min(a / j, math.sqrt(vp / j))
        return tj, vp / (j * tj) - tj  # the speed reached: j tj (tj + ta) = vp

    tj, ta = phases(v)
    if v * (2.0 * tj + ta) <= d:
        return tj, ta, (d - v * (2.0 * tj + ta)) / v
    lo, hi = 0.0, v  # the peak speed that covers d without cruise: bisection (monotone)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        tj, ta = phases(mid)
        lo, hi = (mid, hi) if mid * (2.0 * tj + ta) < d else (lo, mid)
    tj, ta = phases(0.5 * (lo + hi))
    return tj, ta, 0.0


class PointToPoint(Signal):
    """A point-to-point move: position [m] along a jerk-limited (S-curve) or trapezoidal profile.

    From rest at ``position`` at time ``start`` to rest at ``position + distance``, within the
    speed ``v_max``, the acceleration ``a_max`` and (S-curve) the jerk ``j_max``, all reached
    if the distance allows (otherwise the profile is shortened: no cruise, a lower peak).

    - S-curve (``j_max`` given): seven segments of constant jerk ``+-j_max`` or zero; the
      position is ``position + sign(distance) sum_i dJ_i (t - t_i)_+^3 / 6`` over the eight jerk
      switches ``t_i`` with jumps ``dJ_i`` (continuous acceleration).
    - trapezoid (``j_max = None``): constant acceleration ``+-a_max`` or zero; the position is
      ``position + sign(distance) sum_i dA_i (t - t_i)_+^2 / 2`` over four switches.

    Time is clamped to the end of the move, so the position is exactly constant afterwards.
    The structure (:attr:`key`) is the kind only; the switch times and jumps are run-time numbers.
    :meth:`velocity` and :meth:`acceleration` give the profile's derivatives.

    Parameters
    ----------
    distance : float
        Signed length of the move [m], ``!= 0``.
    v_max : float
        Speed limit [m/s], ``> 0``.
    a_max : float
        Acceleration limit [m/s^2], ``> 0``.
    j_max : float, optional
        Jerk limit [m/s^3], ``> 0`` (S-curve); ``None``: trapezoidal velocity.
    start : float, default 0.0
        Start time [s], ``>= 0``.
    position : float, default 0.0
        Position at the start [m].

    Examples
    --------
    >>> from prefriction.signals import PointToPoint
    >>> move = PointToPoint(distance=1e-5, v_max=2e-4, a_max=5e-3, j_max=0.5)
    >>> round(move.duration, 9), round(move(move.duration) * 1e5, 12), float(move.velocity(1.0))
    (0.1, 1.0, 0.0)
    """

    __slots__ = ("distance", "v_max", "a_max", "j_max", "start", "position", "_times", "_jumps")

    def __init__(self, distance: float, v_max: float, a_max: float, j_max: Optional[float] = None,
                 start: float = 0.0, position: float = 0.0) -> None:
        d = number("distance", distance, "m", "!= 0", lambda x: x != 0.0)
        v = number("v_max", v_max, "m/s", "> 0", lambda x: x > 0.0)
        a = number("a_max", a_max, "m/s^2", "> 0", lambda x: x > 0.0)
        jm = None if j_max is None else number("j_max", j_max, "m/s^3", "> 0", lambda x: x > 0.0)
        t0 = number("start", start, "s", ">= 0", lambda x: x >= 0.0)
        x0 = number("position", position, "m")
        sgn, L = math.copysign(1.0, d), abs(d)
        if jm is None:
            ta = min(v / a, math.sqrt(L / a))
            tv = (L - a * ta * ta) / (a * ta)
            times = t0 + np.array([0.0, ta, ta + tv, 2.0 * ta + tv])
            jumps = sgn * a * np.array([1.0, -1.0, -1.0, 1.0])
        else:
            tj, tc, tv = _scurve_times(L, v, a, jm)
            t1 = 2.0 * tj + tc + tv
            times = t0 + np.array([0.0, tj, tj + tc, 2.0 * tj + tc, t1, t1 + tj, t1 + tj + tc, t1 + 2.0 * tj + tc])
            jumps = sgn * jm * np.array([1.0, -1.0, -1.0, 1.0, -1.0, 1.0, 1.0, -1.0])
        self._set(distance=d, v_max=v, a_max=a, j_max=jm, start=t0, position=x0, _times=times, _jumps=jumps)
        self._check_end()

    END_RTOL = 1e-8
    """How close [relative to ``distance``] the profile's series must land on the target."""

    def _check_end(self) -> None:
        """``ValueError`` if the series cannot be evaluated in double precision: the limits so far
        apart in scale from the distance (or the distance so small) that its terms cancel, e.g.
        ``PointToPoint(1e-5, 1e100, 1e100, j_max=1e100)`` ended at 3.5e9 m, ``distance=1e-310`` at 1.1e-95 m."""
        from prefriction.signals._ops import NumpyOps

        end = float(self._series(np.asarray(self._times[-1]), self.params(), NumpyOps, 0))
        target = self.position + self.distance
        if not (math.isfinite(end) and abs(end - target) <= self.END_RTOL * abs(self.distance)
                + 4.0 * np.spacing(abs(target))):
            raise ValueError(
                f"PointToPoint(distance={self.distance!r}, v_max={self.v_max!r}, a_max={self.a_max!r}, "
                f"j_max={self.j_max!r}) cannot be evaluated in double precision: its switch times "
                f"{self._times[1] - self.start:.3g} s and jumps {abs(self._jumps[0]):.3g} differ so much in scale that "
                f"the profile ends at {end!r} m instead of {target!r} m. Give limits the move reaches (v_max, a_max "
                f"and j_max of the order of distance over the move's time and its powers) and |distance| >= 1e-200 m")

    @property
    def key(self) -> Hashable:
        """``("PointToPoint", "S-curve")`` or ``("PointToPoint", "trapezoid")``."""
        return ("PointToPoint", "trapezoid" if self.j_max is None else "S-curve")

    @property
    def _order(self) -> int:
        return 2 if self.j_max is None else 3

    @property
    def n_params(self) -> int:
        """``1 + 2 n`` numbers: the start position, the ``n`` switch times and their jumps."""
        return 1 + 2 * len(self._times)

    def params(self) -> np.ndarray:
        """``[position, t_1..t_n, jump_1..jump_n]`` (SI; the jumps signed by the direction)."""
        return np.concatenate([[self.position], self._times, self._jumps])

    @property
    def duration(self) -> float:
        """Length of the move [s] (from ``start`` to rest at the target)."""
        return float(self._times[-1] - self.start)

    def _series(self, t: Any, theta: Any, ops: Any, derivative: int) -> Any:
        n, p = len(self._times), self._order
        tt = ops.fmin(t, theta[n])  # clamped at the end of the move
        total = theta[0] if derivative == 0 else 0.0
        k = p - derivative
        for i in range(n):
            h = ops.fmax(tt - theta[1 + i], 0.0)
            total = total + theta[1 + n + i] * h ** k / math.factorial(k)
        return total

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return self._series(t, theta, ops, 0)

    def _derivative(self, t: Any, order: int) -> Union[float, np.ndarray]:
        from prefriction.signals._ops import NumpyOps

        tt = check_real_array("t", t, "s")
        value = np.asarray(self._series(np.asarray(tt, dtype=float), self.params(), NumpyOps, order), dtype=float)
        value = np.where(np.asarray(tt) >= self._times[-1], 0.0, value)
        value = np.broadcast_to(value, np.shape(tt)).copy()
        return float(value) if value.ndim == 0 else value

    def velocity(self, t: Any) -> Union[float, np.ndarray]:
        """Velocity of the profile [m/s] at the time(s) ``t`` [s]."""
        return self._derivative(t, 1)

    def acceleration(self, t: Any) -> Union[float, np.ndarray]:
        """Acceleration of the profile [m/s^2] at the time(s) ``t`` [s]."""
        return self._derivative(t, 2)

    def bound(self, t_end: float) -> float:
        """``max(|position|, |position + distance|)`` [m] (:meth:`Signal.bound`)."""
        time_end(t_end)
        return max(abs(self.position), abs(self.position + self.distance))

    def _fields(self) -> dict:
        return {"distance": self.distance, "v_max": self.v_max, "a_max": self.a_max, "j_max": self.j_max,
                "start": self.start, "position": self.position}
