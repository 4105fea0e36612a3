"""The reference velocity at the sample instants, for the compensators of the sampled loop."""

from __future__ import annotations

from typing import Any

import numpy as np

from prefriction.signals import Signal

__all__ = ["reference_velocity"]


def _analytic(reference: Any, t: np.ndarray) -> "np.ndarray | None":
    """The velocity [m/s] of a signal or a number (:meth:`prefriction.signals.Signal.velocity`), else ``None``."""
    if isinstance(reference, Signal):
        return np.asarray(reference.velocity(t), dtype=float)
    if isinstance(reference, (int, float)) and not isinstance(reference, bool):
        return np.zeros_like(t)
    return None


def reference_velocity(reference: Any, t: np.ndarray, r: np.ndarray, Ts: float) -> np.ndarray:
    """Velocity [m/s] of the reference at the sample instants ``t`` [s].

    Exact for every :class:`prefriction.signals.Signal` (its ``velocity``) and numbers;
    otherwise (a plain callable, samples) the central difference of the samples ``r`` [m]
    (one-sided at the ends).
    """
    v = _analytic(reference, t)
    if v is not None:
        return np.broadcast_to(v, t.shape).astype(float)
    if len(r) < 2:
        return np.zeros_like(t)
    return np.gradient(r, Ts)
