"""Velocity reversals located in measured positions (the segments of multiple shooting)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

__all__ = ["DataReversals", "locate_reversals"]

MIN_GAP = 4
"""Fewest samples between two located reversals; closer ones mean the motion is below the noise."""


@dataclass(frozen=True)
class DataReversals:
    """Reversals estimated from the data.

    Attributes
    ----------
    index : numpy.ndarray
        ``k`` for each reversal between samples ``k`` and ``k + 1``.
    time : numpy.ndarray
        Estimated reversal times [s] (zero of the smoothed velocity, linear between samples).
    s0 : float
        Direction of the motion at the first sample (+1 or -1).
    x, v, a : numpy.ndarray
        Smoothed position [m], velocity [m/s] and acceleration [m/s^2] at the samples.
    """

    index: np.ndarray
    time: np.ndarray
    s0: float
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray


def locate_reversals(t: np.ndarray, x: np.ndarray, times: np.ndarray | None = None, window: int = 7) -> DataReversals:
    """Reversals of ``x(t)``: sign changes of a Savitzky-Golay velocity (cubic, ``window`` samples),
    or the given approximate reversal ``times`` [s].

    Raises
    ------
    ValueError
        If two reversals lie fewer than :data:`MIN_GAP` samples apart (the motion has sunk into
        the noise: cut the record there), or the motion has no direction at the start.
    """
    h = float(np.mean(np.diff(t)))
    w = min(window, x.size - (1 - x.size % 2))
    xs = savgol_filter(x, w, 3)
    v = savgol_filter(x, w, 3, deriv=1, delta=h)
    a = savgol_filter(x, w, 3, deriv=2, delta=h)
    sv = np.sign(v)
    nz = np.flatnonzero(sv)
    if nz.size == 0:
        raise ValueError("x shows no motion (the smoothed velocity is zero throughout)")
    for i in range(1, sv.size):
        if sv[i] == 0.0:
            sv[i] = sv[i - 1] if sv[i - 1] != 0.0 else sv[nz[0]]
    sv[: nz[0]] = sv[nz[0]]
    if times is not None:
        return _given(t, times, sv[0], xs, v, a)
    k = np.flatnonzero(sv[1:] != sv[:-1])
    gaps = np.diff(k)
    if np.any(gaps < MIN_GAP):
        at = k[int(np.flatnonzero(gaps < MIN_GAP)[0])]
        raise ValueError(f"x reverses twice within {MIN_GAP} samples near t = {t[at]!r} s: the motion is "
                         f"below the noise or sampled too coarsely there; cut the record before that time")
    tau = t[k] + (t[k + 1] - t[k]) * v[k] / (v[k] - v[k + 1])
    return DataReversals(k, tau, float(sv[0]), xs, v, a)


def _given(t: np.ndarray, times: Any, s0: float, xs: np.ndarray, v: np.ndarray, a: np.ndarray) -> DataReversals:
    """Reversals at the given times (checked: 1-D, finite, inside the record, far enough apart)."""
    tau = np.array(times, dtype=float).ravel()
    if not np.all(np.isfinite(tau)) or np.any(tau <= t[0]) or np.any(tau >= t[-1]):
        raise ValueError(f"reversals must be finite times inside the record ({t[0]!r}, {t[-1]!r}) s, got {times!r}")
    k = np.searchsorted(t, tau, side="right") - 1
    if np.any(np.diff(k) < MIN_GAP):
        raise ValueError(f"reversals must be increasing and at least {MIN_GAP} samples apart, got {times!r}")
    return DataReversals(k, tau, s0, xs, v, a)
