"""The reference velocity at the sample instants, for the compensators of the sampled loop."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from prefriction.signals import Constant, Sine, Step, Sum

__all__ = ["reference_velocity"]


def _analytic(reference: Any, t: np.ndarray) -> "np.ndarray | None":
    """The velocity [m/s] of a reference with a known derivative, else ``None``."""
    if hasattr(reference, "velocity"):
        return np.asarray(reference.velocity(t), dtype=float)
    if isinstance(reference, Sine):
        w = 2.0 * math.pi * reference.frequency
        return reference.amplitude * w * np.cos(w * t + reference.phase)
    if isinstance(reference, (Constant, Step)) or (isinstance(reference, (int, float)) and not isinstance(reference, bool)):
        return np.zeros_like(t)
    if isinstance(reference, Sum):
        parts = [_analytic(term, t) for term in reference.terms]
        return None if any(p is None for p in parts) else np.sum(parts, axis=0)
    return None


def reference_velocity(reference: Any, t: np.ndarray, r: np.ndarray, Ts: float) -> np.ndarray:
    """Velocity [m/s] of the reference at the sample instants ``t`` [s].

    Analytic for :class:`prefriction.signals.Sine`, constants, steps, the motion profiles
    (:class:`prefriction.signals.PointToPoint`, any signal with a ``velocity`` method) and their
    sums; otherwise the central difference of the samples ``r`` [m] (one-sided at the ends).
    """
    v = _analytic(reference, t)
    if v is not None:
        return np.broadcast_to(v, t.shape).astype(float)
    if len(r) < 2:
        return np.zeros_like(t)
    return np.gradient(r, Ts)
