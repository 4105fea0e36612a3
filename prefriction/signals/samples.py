"""Sampled data: :class:`Samples`, linear between the samples and held outside them."""

from __future__ import annotations

from typing import Any, Optional, Union

import numpy as np

from prefriction._validation import check_real_array
from prefriction.signals._checks import UNIT, number, time_end
from prefriction.signals.base import LinearPieces

__all__ = ["MAX_SAMPLES", "Samples"]

#: Largest number of samples accepted by :class:`Samples`.
MAX_SAMPLES = 10_000_000


def _sample_array(name: str, values: Any, unit: str) -> np.ndarray:
    """A finite 1-D float array (copy, read-only); messages name ``name``."""
    if isinstance(values, (str, bytes)) or values is None:
        raise TypeError(f"{name} must be a 1-D array of finite real numbers [{unit}], got {values!r}")
    try:
        arr = np.asarray(values)
    except Exception as exc:  # ragged lists and the like
        raise TypeError(f"{name} must be a 1-D array of finite real numbers [{unit}], got {exc}") from None
    if arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must be a 1-D array of finite real numbers [{unit}], got an array of dtype {arr.dtype}"
        )
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array [{unit}], got shape {arr.shape}")
    if arr.size > MAX_SAMPLES:
        raise ValueError(f"{name} must have at most {MAX_SAMPLES} samples, got {arr.size}")
    arr = np.array(arr, dtype=float)
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(
            f"{name} must be finite (every entry) [{unit}], got {arr[bad][0]!r} at index {int(np.argmax(bad))}"
        )
    arr.setflags(write=False)
    return arr


def _times_values(nt: str, t: Any, nu: str, u: Any, unit: str, least: int, noun: str) -> tuple[np.ndarray, np.ndarray]:
    """Times ``t`` [s] and values ``u`` [``unit``] as checked arrays of one length, ``t`` strictly increasing.

    At least ``least`` entries (``noun`` names them in the message); messages name ``nt`` and ``nu``.
    """
    ts = _sample_array(nt, t, "s")
    us = _sample_array(nu, u, unit)
    if ts.size < least:
        raise ValueError(f"{nt} must have at least {least} {noun}, got {ts.size}")
    if us.shape != ts.shape:
        raise ValueError(f"{nu} must have the same length as {nt} ({ts.size}), got {us.size}")
    steps = np.diff(ts)
    if not np.all(steps > 0.0):
        k = int(np.argmax(steps <= 0.0))
        raise ValueError(
            f"{nt} must be strictly increasing, got {nt}[{k}] = {float(ts[k])!r} >= {nt}[{k + 1}] = {float(ts[k + 1])!r}"
        )
    return ts, us


class Samples(LinearPieces):
    """Piecewise-linear signal through samples, held constant outside them (as ``numpy.interp``).

    The samples are not compiled: :meth:`piece` hands the simulator the linear piece of each
    interval between sample times, so all sampled signals share the key ``("Samples",)``.

    Parameters
    ----------
    t : array_like
        Sample times [s]: 1-D, finite, strictly increasing, 2 to :data:`MAX_SAMPLES` entries.
    u : array_like
        Sample values [signal units]: 1-D, finite, same length as ``t``.
    name : str, optional
        Name of the signal in error messages (e.g. ``"reference"``); default: none.
    unit : str, optional
        Unit of the values in error messages, default ``"signal units"``.
    """

    __slots__ = ("_t", "_u")

    def __init__(self, t: Any, u: Any, *, name: Optional[str] = None, unit: str = UNIT) -> None:
        nt, nu = (f"{name} sample times t", f"{name} sample values") if name else ("t", "u")
        ts, us = _times_values(nt, t, nu, u, unit, 2, "samples")
        self._set(_t=ts, _u=us)

    @property
    def t(self) -> np.ndarray:
        """Sample times [s] (read-only)."""
        return self._t

    @property
    def u(self) -> np.ndarray:
        """Sample values [signal units] (read-only)."""
        return self._u

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """Value at ``ta`` and slope of the linear piece of :meth:`piece`."""
        tl, a, b = self.piece(ta, tb)
        return float(a + b * (ta - tl)), float(b)

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Linear piece ``a + b (t - tl)`` valid on ``[ta, tb]``.

        The piece is the one containing the midpoint of ``[ta, tb]``, so that ``ta`` may be a
        sample time exactly; outside the sample range the slope is 0.

        Parameters
        ----------
        ta, tb : float
            Start and end [s] of the interval, ``ta <= tb``, with no sample time strictly inside.

        Returns
        -------
        numpy.ndarray
            ``(tl [s], a [signal units], b [signal units / s])``.
        """
        ta = number("ta", ta, "s")
        tb = number("tb", tb, "s", f">= ta = {ta!r}", lambda v: v >= ta)
        ts, us = self._t, self._u
        mid = 0.5 * (ta + tb)
        if mid <= ts[0]:
            return np.array([ta, us[0], 0.0])
        if mid >= ts[-1]:
            return np.array([ta, us[-1], 0.0])
        k = int(np.clip(np.searchsorted(ts, mid, side="right") - 1, 0, ts.size - 2))
        slope = (us[k + 1] - us[k]) / (ts[k + 1] - ts[k])
        return np.array([ts[k], us[k], slope])

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value at the time(s) ``t`` [s]: ``numpy.interp(t, self.t, self.u)``, shaped like ``t``."""
        value = np.interp(check_real_array("t", t, "s"), self._t, self._u)
        return float(value) if np.ndim(value) == 0 else value

    def velocity(self, t: Any) -> Union[float, np.ndarray]:
        """Slope [signal units / s] of the line after each time ``t`` [s] (0 outside the samples), vectorised."""
        tt = np.asarray(check_real_array("t", t, "s"), dtype=float)
        ts, us = self._t, self._u
        k = np.clip(np.searchsorted(ts, tt, side="right") - 1, 0, ts.size - 2)
        value = np.where((tt >= ts[0]) & (tt < ts[-1]), (us[k + 1] - us[k]) / (ts[k + 1] - ts[k]), 0.0)
        return float(value) if value.ndim == 0 else value

    def breaks(self) -> np.ndarray:
        """Copy of the sample times :attr:`t` [s], where the slope jumps."""
        return self._t.copy()

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`; exact)."""
        t_end = time_end(t_end)
        inside = (self._t >= 0.0) & (self._t <= t_end)
        ends = np.abs(np.interp([0.0, t_end], self._t, self._u))
        return float(max(ends.max(), np.abs(self._u[inside]).max(initial=0.0)))

    def __repr__(self) -> str:
        t0, t1, lo, hi = (float(x) for x in (self._t[0], self._t[-1], self._u.min(), self._u.max()))
        return f"Samples(n={self._t.size}, t=[{t0!r} .. {t1!r}], u=[{lo!r} .. {hi!r}])"
