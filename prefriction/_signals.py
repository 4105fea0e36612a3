"""Input force and reference signals of a simulation: kind, numeric value, linear pieces, size.

A signal is ``None``, a constant, a callable of time [s] (traced with a CasADi symbol by
:func:`checked_signal_kind`) or samples ``(t, values)``, linear between samples and held outside them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Optional

import casadi as ca
import numpy as np

from ._feedback import LinearFeedback
from ._plant import trace_signal
from .models import Oscillator


@dataclass(frozen=True)
class ConstantSignal:
    """A constant signal [SI] as a callable of time, equal (and hashed) by value, so that a plant
    with a constant input force is built once per value."""

    value: float

    def __call__(self, t: Any) -> float:
        return self.value


def signal_kind(value: Any) -> str:
    """Kind of an input or reference signal: none, const, callable or samples."""
    if value is None:
        return "none"
    if callable(value):
        return "callable"
    if isinstance(value, tuple):
        return "samples"
    return "const"


def checked_signal_kind(value: Any, what: str) -> str:
    """:func:`signal_kind`, after checking that a callable can be traced (``TypeError`` naming ``what``)."""
    kind = signal_kind(value)
    if kind == "callable":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            trace_signal(value, what)
    return kind


def eval_signal(value: Any, kind: str, t: np.ndarray) -> np.ndarray:
    """Numeric value of a signal at times ``t`` [s] (samples: linear, held outside the range)."""
    t = np.asarray(t, dtype=float)
    if kind == "none":
        return np.zeros_like(t)
    if kind == "const":
        return np.full_like(t, float(value))
    if kind == "samples":
        return np.interp(t, value[0], value[1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        return np.array([float(ca.DM(value(float(ti)))) for ti in t.ravel()]).reshape(t.shape)


def linear_piece(value: Any, t: float, t_next: float) -> tuple[float, float, float]:
    """(left time, value, slope) of the linear piece of sampled ``value`` on ``[t, t_next]`` [SI]."""
    ts, vs = value
    if t_next <= ts[0] or t >= ts[-1]:
        return t, float(np.interp(t, ts, vs)), 0.0
    mid = 0.5 * (t + t_next)  # robust to round-off when t is a sample time
    k = int(np.clip(np.searchsorted(ts, mid, side="right") - 1, 0, len(ts) - 2))
    slope = (vs[k + 1] - vs[k]) / (ts[k + 1] - ts[k])
    return float(ts[k]), float(vs[k]), float(slope)


def applied_force_scale(system: Oscillator, u_kind: str, fb: Optional[LinearFeedback], r_kind: str,
                        x0: float, t_end: float) -> float:
    """Size [N] of the applied force: input samples, or 257 evaluations over [0, t_end], plus the
    feedback force ``|D| max |r - x0| + |C xc0|``; used for the error-control scale."""
    t = np.linspace(0.0, t_end, 257)
    with np.errstate(invalid="ignore"):
        scale = float(np.nanmax(np.abs(eval_signal(system.u, u_kind, t)), initial=0.0)) if system.forced else 0.0
        if fb is not None:
            r = eval_signal(fb.reference, r_kind, t)
            scale += abs(fb.D[0, 0]) * float(np.nanmax(np.abs(r - x0), initial=0.0))
            scale += float(np.abs(fb.C[0] @ fb.xc0))
    return scale
