"""A prescribed motion as the rows of the interval steps: durations, velocities, directions.

The motion is linear between samples (``docs/along.md#motion``): interval ``k`` (samples ``k`` to
``k + 1``) has the constant velocity ``(x[k+1] - x[k]) / (t[k+1] - t[k])`` and the direction of
its displacement; an interval without displacement keeps the previous direction (the first
moving interval's direction before it), so a reversal sits on the sample between two intervals
of opposite directions. The velocity at a sample, for the rate-dependent part of the force, is
the velocity of the interval that ends there (of the first interval at the first sample), or
the user's samples ``v``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_real_array

__all__ = ["MAX_SAMPLES", "Motion"]

MAX_SAMPLES = 20_000_000
"""Most samples of one motion (the states of every sample are kept: about 0.2 GB per state)."""


def _samples(name: str, value: Any, unit: str, n: int | None = None) -> np.ndarray:
    arr = check_real_array(name, value, unit, max_size=MAX_SAMPLES)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array of samples [{unit}], got shape {arr.shape}")
    if n is None and arr.size < 2:
        raise ValueError(f"{name} must hold 2 to {MAX_SAMPLES:_} samples, got {arr.size}")
    if n is not None and arr.size != n:
        raise ValueError(f"{name} must hold as many samples as t ({n}), got {arr.size}")
    return arr


@dataclass(frozen=True)
class Motion:
    """The checked samples of a prescribed motion and the rows of its intervals (SI units)."""

    t: np.ndarray       # sample times [s]
    x: np.ndarray       # positions [m]
    dt: np.ndarray      # interval durations [s]
    v: np.ndarray       # interval velocities [m/s]
    s: np.ndarray       # interval directions (+-1)
    s_prev: np.ndarray  # direction of the interval before (the first one's own before it)
    v_at: np.ndarray    # velocity at every sample [m/s] (module notes)
    s0: float           # direction of the first moving interval (+1 if none moves)

    @classmethod
    def of(cls, t: Any, x: Any, v: Any = None) -> "Motion":
        """Check ``t`` (strictly increasing), ``x`` and ``v`` (optional) and build the rows.

        Raises
        ------
        TypeError
            If an argument is not an array of real numbers.
        ValueError
            If an array is not 1-D, holds fewer than 2 or more than :data:`MAX_SAMPLES` samples,
            a non-finite entry, lengths differ, or ``t`` is not strictly increasing.
        """
        t = _samples("t", t, "s")
        x = _samples("x", x, "m", t.size)
        dt = np.diff(t)
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ValueError(f"t must be strictly increasing, got t[{i}] = {t[i]!r} and t[{i + 1}] = {t[i + 1]!r}")
        dx = np.diff(x)
        vi = dx / dt
        s = np.sign(dx)
        moving = np.flatnonzero(s)
        s0 = float(s[moving[0]]) if moving.size else 1.0
        if moving.size:  # carry the last direction over intervals without displacement
            idx = np.where(s != 0.0, np.arange(s.size), 0)
            np.maximum.accumulate(idx, out=idx)
            s = np.where(np.arange(s.size) < moving[0], s0, s[idx])
        else:
            s = np.full(dx.size, 1.0)
        s_prev = np.concatenate(([s[0]], s[:-1]))
        if v is None:
            v_at = np.concatenate(([vi[0]], vi))
        else:
            v_at = _samples("v", v, "m/s", t.size)
        return cls(t, x, dt, vi, s, s_prev, v_at, s0)

    @property
    def reversals(self) -> np.ndarray:
        """Indices of the samples where the direction reverses."""
        return np.flatnonzero(self.s * self.s_prev < 0.0)
