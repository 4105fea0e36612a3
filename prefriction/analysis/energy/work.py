"""Integrals of sampled powers between velocity reversals: the input's work ``int u v dt`` (2.8)
for a force known at the samples or held constant between them (a sampled controller), and
any power that vanishes at a reversal."""

from __future__ import annotations

from typing import Optional

import numpy as np
from scipy.integrate import simpson, trapezoid

from prefriction.analysis.energy.sampled_reversals import SampledReversals


def piece_integrals(t: np.ndarray, powers: np.ndarray, t_a: float, t_b: float, method: str) -> np.ndarray:
    """Integrals over ``(t_a, t_b)`` of each row of ``powers`` [W] (shape ``(rows, N)``).

    Uses the samples strictly inside and zero power at both ends (a reversal: ``v = 0``, and
    every power of the analysis has the factor ``v`` or vanishes with it). ``t_a == t[0]`` (not
    a reversal, the first excursion) takes the power of the first sample there instead."""
    inside = (t > t_a) & (t < t_b)
    tt = np.concatenate(([t_a], t[inside], [t_b]))
    start = powers[:, :1] if t_a == t[0] else np.zeros((powers.shape[0], 1))
    pp = np.concatenate((start, powers[:, inside], np.zeros((powers.shape[0], 1))), axis=1)
    if method == "simpson" and tt.size >= 3:
        return simpson(pp, x=tt, axis=1)
    return trapezoid(pp, tt, axis=1)


def split_integrals(t: np.ndarray, powers: np.ndarray, rev: SampledReversals, method: str) -> np.ndarray:
    """:func:`piece_integrals` over the first excursion (``t[0]`` to reversal 1) and every
    half-cycle (reversal k to k + 1): shape ``(rows, len(rev))``, column 0 the first excursion."""
    ends = np.concatenate(([t[0]], rev.t))
    return np.array([piece_integrals(t, powers, ends[k], ends[k + 1], method) for k in range(ends.size - 1)]).T


def held_work(x: np.ndarray, u: np.ndarray, rev: SampledReversals) -> np.ndarray:
    """Work of a force held constant over each sample interval, ``u[k]`` on ``[t[k], t[k+1])``
    (zero-order hold), over the first excursion and each half-cycle [J], exact:
    ``u[k] (x[k+1] - x[k])`` per interval, ``u[i] (x_rev - x[i])`` up to a reversal inside
    interval ``i``. Needs the reversal positions ``rev.x``."""
    cum = np.concatenate(([0.0], np.cumsum(u[:-1] * np.diff(x))))
    i = rev.index
    at_rev = cum[i] + u[i] * (rev.x - x[i])
    return np.diff(np.concatenate(([0.0], at_rev)))


def input_work(
    t: np.ndarray, x: np.ndarray, v: np.ndarray, rev: SampledReversals, method: str, *,
    u: Optional[np.ndarray] = None, held: Optional[np.ndarray] = None,
) -> np.ndarray:
    """Work of the input force over the first excursion and each half-cycle [J], length
    ``len(rev)``: ``int u v dt`` by ``method`` for the force ``u`` [N] known at the samples, plus
    :func:`held_work` of the zero-order-hold force ``held`` [N]; zeros if neither is given."""
    W = np.zeros(len(rev))
    if u is not None:
        W += split_integrals(t, (u * v)[None, :], rev, method)[0]
    if held is not None:
        W += held_work(x, held, rev)
    return W
