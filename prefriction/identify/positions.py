"""Measured positions with noise and encoder quantisation: the path a hysteresis model is driven along.

A rate-independent hysteresis model integrated along noisy positions sees a spurious reversal
at every sample where the noise turns the increment's sign. Each is a minor loop that pulls
the force towards the centre of the loop (Dahl, ``gamma = 1``: a wiggle of amplitude ``a`` at
force ``F`` moves the force by about ``-2 sigma a F / Fc``), so the estimates are biased, not just
noisier: with 10 nm encoder steps and 3 nm of noise a Dahl ``sigma`` came out 7 % low, by 44
standard errors (``docs/identify.md#positions``).

:func:`denoise_path` estimates the true path from the samples and the declared noise level
``s^2 = x_noise^2 + quantum^2 / 12`` (the encoder's rounding error as a uniform variable of one
step's width) in two steps, each a consistent estimator of a smooth path:

1. a local cubic fit (Savitzky-Golay) over a window of ``w`` samples, ``w`` chosen by Stein's
   unbiased risk estimate with the known ``s^2`` (Mallows' ``C_p``)
   ``R(w) = |x - S_w x|^2 - n s^2 + 2 s^2 tr(S_w)`` (eq. P1), over odd windows up to about a
   hundredth of the record;
2. a monotone projection between the reversals of the smoothed path: reversals where the path
   retraces more than ``4`` times the smoothed noise's standard deviation
   ``s_w = s sqrt(h_0(w))`` (``h_0`` the window's centre weight); near each reversal (within
   ``8 s_w`` of it) the least-squares parabola through the raw samples replaces the smoothed
   path, whose extreme is a selected, outward-biased value; then the least-squares monotone
   fit of each piece (isotonic regression), which keeps the reversal samples (each is its
   piece's extreme) and removes the wiggles the smoothing left where the path is slow.

The result turns only where the data show a reversal; its error is of the order of ``s_w``,
smooth, and enters the force residuals through ``dF/dx`` as correlated noise: the fit adds its
covariance (:func:`prefriction.identify.prescribed.path_covariance`, eqs. P2 and P3 of
``docs/identify.md#positions``) to the HAC one (``statistics.py``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import isotonic_regression
from scipy.ndimage import convolve1d
from scipy.signal import savgol_coeffs, savgol_filter

__all__ = ["denoise_path", "dwell_error_sd", "dwell_sets", "noise_sd", "smoothed_covariance_factor",
           "noisy_positions_message", "reversal_indices", "turns"]

POLYORDER = 3
"""Degree of the local polynomial (a cubic: exact on a parabola-shaped reversal)."""
REVERSAL_SDS = 4.0
"""A retrace larger than this many smoothed-noise standard deviations is a reversal."""
PEAK_SDS = 8.0
"""Half-height of the neighbourhood of a reversal fitted by a parabola, in smoothed-noise
standard deviations."""


def noise_sd(x_noise: float, quantum: float) -> float:
    """Standard deviation [m] of the position error: ``sqrt(x_noise^2 + quantum^2 / 12)``.

    Parameters
    ----------
    x_noise : float
        Standard deviation of the additive position noise [m].
    quantum : float
        Encoder step [m] (rounding error uniform over one step).
    """
    return float(np.hypot(x_noise, quantum / np.sqrt(12.0)))


def _windows(n: int) -> list[int]:
    top = max(POLYORDER + 2, min(n // 100, 2001))
    grid = np.unique(np.geomspace(POLYORDER + 2, top, 24).astype(int) | 1)
    return [int(w) for w in grid if POLYORDER + 2 <= w <= n]


def _smooth(x: np.ndarray, s: float) -> tuple[np.ndarray, float, int]:
    """Local cubic fit with the window of least estimated risk (eq. P1); the smoothed path, the
    standard deviation of its noise [m] and the window [samples]."""
    n = x.size
    best = (np.inf, x, s, 1)
    for w in _windows(n):
        y = savgol_filter(x, w, POLYORDER, mode="interp")
        h0 = float(savgol_coeffs(w, POLYORDER)[w // 2])
        risk = float(np.sum((x - y) ** 2)) - n * s * s + 2.0 * s * s * n * h0
        if risk < best[0]:
            best = (risk, y, s * np.sqrt(h0), w)
    return best[1], best[2], best[3]


def _reversals(y: np.ndarray, h: float) -> list[int]:
    """Indices of the reversals of ``y`` (with its ends): the extremes after which it retraces more than ``h``."""
    out = [0]
    hi = lo = ext = 0
    direction = 0
    for i in range(1, y.size):
        if direction == 0:  # the first direction: the first excursion larger than h
            hi, lo = (i if y[i] > y[hi] else hi), (i if y[i] < y[lo] else lo)
            if y[hi] - y[lo] > h:
                direction = 1 if hi > lo else -1
                out.append(lo if direction > 0 else hi)
                ext = hi if direction > 0 else lo
        elif direction * (y[i] - y[ext]) >= 0.0:
            ext = i
        elif direction * (y[ext] - y[i]) > h:
            out.append(ext)
            direction, ext = -direction, i
    out.append(y.size - 1)
    return sorted(set(out))


def _peak(x: np.ndarray, y: np.ndarray, e: int, s_w: float) -> None:
    """Replace ``y`` around its reversal ``e`` by the least-squares parabola through the raw ``x``
    there (in place).

    The smoothed path's extreme is the largest of several noisy values (selected, so biased
    outwards); the parabola through all the samples near it is not selected. On the
    reproducer of ``docs/identify.md#positions`` (60 seeds, random encoder phase) it lowers the
    rms error at the four reversals from 1.22-1.41 nm to 1.12-1.34 nm. The neighbourhood: the
    samples within ``PEAK_SDS * s_w`` of the extreme, contiguous around ``e``.
    """
    d = 1.0 if e + 1 < y.size and y[e] >= y[e + 1] else -1.0
    near = d * (y[e] - y) <= PEAK_SDS * s_w
    a = e
    while a > 0 and near[a - 1]:
        a -= 1
    b = e
    while b + 1 < y.size and near[b + 1]:
        b += 1
    if b - a < 6:
        return
    i = np.arange(a, b + 1, dtype=float) - e
    coef = np.polyfit(i, x[a: b + 1], 2)
    if d * coef[0] >= 0.0:   # not a peak of the right kind: keep the smoothed path
        return
    y[a: b + 1] = np.polyval(coef, i)


def denoise_path(x: np.ndarray, x_noise: float, quantum: float) -> tuple[np.ndarray, int]:
    """The estimated true path [m] under noisy, quantised position samples (steps 1 and 2 above).

    Parameters
    ----------
    x : numpy.ndarray
        Measured positions [m], one per sample (uniform sampling assumed: the window counts
        samples).
    x_noise : float
        Standard deviation of the position noise [m].
    quantum : float
        Encoder step [m].

    Returns
    -------
    (numpy.ndarray, int)
        The path, monotone between its reversals, and the window of step 1 [samples] (1: none).
    """
    s = noise_sd(x_noise, quantum)
    if s == 0.0 or x.size < POLYORDER + 2:
        return x.copy(), 1
    x = np.asarray(x, dtype=float)
    y, s_w, window = _smooth(x, s)
    rev = _reversals(y, REVERSAL_SDS * s_w)
    for e in rev[1:-1]:
        _peak(x, y, e, s_w)
    out = y.copy()
    for a, b in zip(rev[:-1], rev[1:]):
        piece = y[a: b + 1]
        up = piece[-1] >= piece[0]
        out[a: b + 1] = isotonic_regression(piece, increasing=up).x
    return out, window


def dwell_error_sd(x_noise: float, quantum: float) -> float:
    """Standard deviation [m] of the rounding error that does not average out where the path dwells
    within one encoder step (at a reversal).

    The mean error of a quantiser of step ``q`` under Gaussian noise of deviation ``sigma`` is
    periodic in the position, with first harmonic of amplitude ``(q / pi) exp(-2 pi^2 sigma^2 / q^2)``
    (Widrow and Kollar, *Quantization Noise*, Cambridge 2008, ch. 5 and 11); where the true
    position sits relative to the steps is unknown, so the error is taken as that harmonic at a
    uniform random phase: standard deviation ``amplitude / sqrt(2)`` (eq. P3).

    Parameters
    ----------
    x_noise : float
        Standard deviation of the position noise [m].
    quantum : float
        Encoder step [m].
    """
    if quantum == 0.0:
        return 0.0
    return float(quantum / np.pi * np.exp(-2.0 * np.pi**2 * (x_noise / quantum) ** 2) / np.sqrt(2.0))


def dwell_sets(path: np.ndarray, quantum: float) -> list[np.ndarray]:
    """Per interior reversal of ``path``: the indices of the contiguous samples within one step
    ``quantum`` of it (the dwell whose rounding error is common, eq. P3).

    Parameters
    ----------
    path : numpy.ndarray
        The estimated path [m] (monotone between reversals).
    quantum : float
        Encoder step [m].
    """
    if quantum == 0.0:
        return []
    dx = np.diff(path)
    s = np.sign(dx)
    nz = np.flatnonzero(s)
    out = []
    for j0, j1 in zip(nz[:-1], nz[1:]):
        if s[j0] == s[j1]:
            continue
        e = j1  # the extreme: the samples j0 + 1 ... j1 are flat between the two directions
        a, b = e, e
        while a > 0 and abs(path[a - 1] - path[e]) <= quantum:
            a -= 1
        while b + 1 < path.size and abs(path[b + 1] - path[e]) <= quantum:
            b += 1
        out.append(np.arange(a, b + 1))
    return out


def smoothed_covariance_factor(G: np.ndarray, window: int) -> np.ndarray:
    """``G S_w`` for the rows of ``G`` (shape ``(k, n)``): with the path error ``e = S_w eps``
    (``eps`` white, variance ``s^2``), ``Cov(G e) = s^2 (G S_w)(G S_w)^T``.

    ``S_w`` is taken as the interior Savitzky-Golay convolution at both ends too (the end
    windows' own weights differ; ``window // 2`` samples at each end).

    Parameters
    ----------
    G : numpy.ndarray
        Sensitivities of the quantities of interest to the path samples [per m].
    window : int
        The smoothing window [samples] (1: no smoothing).
    """
    if window <= 1:
        return G
    c = savgol_coeffs(window, POLYORDER)
    return convolve1d(G, c[::-1], axis=-1, mode="constant")


def reversal_indices(x: np.ndarray) -> np.ndarray:
    """Sample indices where the motion ``x`` reverses by more than 1 % of its range.

    Parameters
    ----------
    x : numpy.ndarray
        Positions [m] (the estimated path of noisy data).
    """
    span = float(np.max(x) - np.min(x))
    rev = _reversals(np.asarray(x, dtype=float), 0.01 * span)
    return np.asarray(rev[1:-1], dtype=int)


def turns(x: np.ndarray) -> int:
    """How often the direction of ``x`` turns (``dx`` changes sign, steps of zero skipped)."""
    dx = np.diff(x)
    s = np.sign(dx[dx != 0.0])
    return int(np.count_nonzero(s[1:] != s[:-1]))


def noisy_positions_message(x: np.ndarray) -> str | None:
    """A sentence if the undeclared positions ``x`` [m] turn far more often than the motion
    reverses (by more than 1 % of its range): at least 10 extra turns and twice the reversals.

    It names the smallest step (a likely encoder step) and a noise level from the second
    differences (``median(|d2 x|) / 0.6745 / sqrt(6)``, robust to the motion's curvature when the
    sampling is fine), as values to declare.
    """
    n_turns, n_rev = turns(x), int(reversal_indices(x).size)
    if n_turns - n_rev < max(10, 2 * n_rev):
        return None
    steps = np.abs(np.diff(x))
    step = float(np.min(steps[steps > 0.0]))
    sd = float(np.median(np.abs(np.diff(x, 2))) / 0.6745 / np.sqrt(6.0))
    return (f"the positions turn {n_turns} times but the motion reverses {n_rev} times: noise or encoder steps "
            f"on x make a spurious reversal at each turn, which biases a hysteresis fit. Declare them: "
            f"ForceDisplacement(t, x, F, x_noise=..., quantum=...) (smallest step here {step:.3g} m, noise from the "
            f"second differences about {sd:.3g} m; docs/identify.md#positions)")
