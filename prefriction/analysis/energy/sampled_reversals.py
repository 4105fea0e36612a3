"""Velocity reversals located between the samples of a trajectory (:func:`find_reversals`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from prefriction.analysis.energy.checks import check_samples


@dataclass(frozen=True, eq=False)
class SampledReversals:
    """Velocity reversals located in a sampled trajectory.

    Attributes
    ----------
    t : numpy.ndarray
        Reversal times [s].
    x : numpy.ndarray or None
        Positions at the reversals [m] (``None`` if no positions were given).
    F : numpy.ndarray or None
        Friction forces at the reversals [N] (``None`` if no forces were given).
    direction : numpy.ndarray
        Sign of the velocity after each reversal, +1 or -1 (int).
    index : numpy.ndarray
        Index ``i`` of the last sample before each reversal, ``t[i] < t_rev <= t[i + 1]``
        (int). Samples ``index[k] + 1 .. index[k + 1]`` belong to half-cycle ``k``.
    initial_direction : int
        Sign of the first non-zero velocity sample (+1 or -1), the direction of the first
        excursion; 0 if every velocity sample is zero.
    """

    t: np.ndarray
    x: Optional[np.ndarray]
    F: Optional[np.ndarray]
    direction: np.ndarray
    index: np.ndarray
    initial_direction: int

    def __len__(self) -> int:
        return len(self.t)


def _hermite_root(h: np.ndarray, dx: np.ndarray, va: np.ndarray, vb: np.ndarray) -> np.ndarray:
    """Root ``s`` in [0, 1] of the derivative of the cubic Hermite interpolant of x.

    On an interval of length ``h`` with end velocities ``va``, ``vb`` of opposite signs and
    displacement ``dx``, the velocity of the interpolant is the quadratic
    ``q(s) = 6 s (1 - s) dx/h + (3 s^2 - 4 s + 1) va + (3 s^2 - 2 s) vb``, with ``q(0) = va``
    and ``q(1) = vb``; it has exactly one root in (0, 1), found by bisection.
    """
    d = dx / h
    lo = np.zeros_like(va)
    hi = np.ones_like(va)
    sa = np.sign(va)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        q = 6.0 * mid * (1.0 - mid) * d + (3.0 * mid * mid - 4.0 * mid + 1.0) * va + (3.0 * mid * mid - 2.0 * mid) * vb
        same = np.sign(q) == sa
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


def find_reversals(t: Any, v: Any, *, x: Any = None, F: Any = None) -> SampledReversals:
    """Locate the velocity reversals (sign changes of ``v``) of a sampled trajectory.

    A reversal is a change of sign between two consecutive *non-zero* velocity samples, so a
    velocity that touches zero (or rests at zero) without changing sign is not a reversal,
    and a reversal that lands exactly on zero samples is counted once (at the first zero
    sample). A sign change between two samples is located by interpolation: with positions,
    as the root of the velocity of the cubic Hermite interpolant of ``x`` (third order);
    without, linearly in ``v``. The position there is the Hermite interpolant; the force is
    extrapolated along the incoming branch linearly in ``x`` (``F`` is a function of ``x`` on
    a branch, so this is accurate to second order in the step); linearly in ``t`` when the
    incoming branch has a single sample or no positions are given.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    v : array_like
        Velocities [m/s], length N.
    x : array_like, optional
        Positions [m], length N.
    F : array_like, optional
        Friction forces [N], length N.

    Returns
    -------
    SampledReversals
        Reversal times, positions, forces, direction after each reversal and the index of
        the sample before it.

    Raises
    ------
    ValueError
        Arrays of unequal length, shorter than 2, not finite, not 1-D, or ``t`` not strictly
        increasing.
    """
    named = {"t": t, "v": v}
    if x is not None:
        named["x"] = x
    if F is not None:
        named["F"] = F
    arrays = dict(zip(named, check_samples(**named)))
    t, v = arrays["t"], arrays["v"]
    xs, Fs = arrays.get("x"), arrays.get("F")

    sgn = np.sign(v).astype(int)
    nz = np.flatnonzero(sgn)
    initial = int(sgn[nz[0]]) if nz.size else 0
    a, b = nz[:-1], nz[1:]
    flip = sgn[a] != sgn[b]
    a, b = a[flip], b[flip]
    direction = sgn[b]
    on_zero = b > a + 1  # zero samples between: the reversal is the first of them
    t_r = np.empty(a.size)
    x_r = None if xs is None else np.empty(a.size)
    F_r = None if Fs is None else np.empty(a.size)

    z = a[on_zero] + 1
    t_r[on_zero] = t[z]
    if xs is not None:
        x_r[on_zero] = xs[z]
    if Fs is not None:
        F_r[on_zero] = Fs[z]

    ia = a[~on_zero]
    ib = ia + 1
    h = t[ib] - t[ia]
    if xs is not None:
        s = _hermite_root(h, xs[ib] - xs[ia], v[ia], v[ib])
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        x_r[~on_zero] = h00 * xs[ia] + h10 * h * v[ia] + h01 * xs[ib] + h11 * h * v[ib]
    else:
        s = v[ia] / (v[ia] - v[ib])
    t_r[~on_zero] = t[ia] + s * h
    if Fs is not None:
        Fi = Fs[ia] + s * (Fs[ib] - Fs[ia])
        if xs is not None:
            prev = ia - 1
            ok = prev >= 0
            ok[ok] &= ((sgn[prev[ok]] == sgn[ia[ok]]) | (sgn[prev[ok]] == 0)) & (xs[prev[ok]] != xs[ia[ok]])
            p, q = prev[ok], ia[ok]
            slope = (Fs[q] - Fs[p]) / (xs[q] - xs[p])
            Fi[ok] = Fs[q] + slope * (x_r[~on_zero][ok] - xs[q])
        F_r[~on_zero] = Fi
    return SampledReversals(t=t_r, x=x_r, F=F_r, direction=direction, index=a, initial_direction=initial)
