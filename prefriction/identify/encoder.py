"""The encoder's rounding error that does not average out: its covariance in a position fit.

An encoder of step ``q`` reads ``x_m = q round((x + n) / q)`` with Gaussian noise ``n`` of
deviation ``s``. Its error ``x_m - x`` has, given the true position, the mean

    mu(x) = sum_{h >= 1} (-1)^(h+1) a_h sin(2 pi h x / q),   a_h = (q / (pi h)) exp(-2 pi^2 h^2 s^2 / q^2)   (E1)

(the Fourier series of the rounding sawtooth smoothed by the noise; Widrow and Kollar,
*Quantization Noise*, Cambridge 2008, ch. 5 and 11): a fixed function of the position, not
noise. Every sample at the same place on the encoder's grid shares it (a stage at rest, a slow
crossing of a step at a reversal, a loop hunting between two steps). The grid's phase against
the motion is unknown; taken uniform, ``mu`` at the samples is a zero-mean vector with the
covariance

    Cov(mu_k, mu_l) = sum_h (a_h^2 / 2) cos(2 pi h (x_k - x_l) / q)                                 (E2)

of rank two per harmonic: ``(a_h^2 / 2) (c_h c_h^T + s_h s_h^T)``, ``c_h = cos(2 pi h x / q)``,
``s_h = sin(2 pi h x / q)``. A fit whose residual is the measured position minus the model's
passes it to the estimates through its influence weights ``W`` (``d theta = W e``): the
covariance ``W Cov(mu) W^T`` is added to the Newey-West one of the whole residual. Without
noise (``s = 0``) the harmonics hold the whole rounding error, variance ``q^2 / 12``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.stats import t as student_t

from prefriction.identify.statistics import Statistics

__all__ = ["grid_step", "rounding_covariance", "widened"]

HARMONICS = 64
"""Most harmonics of (E2) kept; those whose amplitude is below 1e-3 of the first are dropped."""


def grid_step(x: np.ndarray) -> float:
    """The step [m] of the grid the positions ``x`` lie on (an encoder's, undeclared), or 0.

    The smallest non-zero increment, if every position is ``x[0]`` plus a whole number of it
    (within 1e-6 of a step) and the range holds at most 1e7 of it.
    """
    x = np.asarray(x, dtype=float)
    steps = np.abs(np.diff(x))
    steps = steps[steps > 0.0]
    if steps.size == 0:
        return 0.0
    q = float(np.min(steps))
    k = (x - x[0]) / q
    if np.ptp(k) > 1e7 or np.max(np.abs(k - np.round(k))) > 1e-6:
        return 0.0
    return q


def rounding_covariance(W: np.ndarray, path: np.ndarray, x_noise: float, quantum: float) -> np.ndarray:
    """The covariance (E2) passed through the influence weights ``W``: ``W Cov(mu) W^T``.

    Parameters
    ----------
    W : numpy.ndarray
        Influence of each position error [per m] on each estimate (shape ``(p, n)``).
    path : numpy.ndarray
        The estimated true positions [m] at the ``n`` samples.
    x_noise : float
        Standard deviation [m] of the position noise before the rounding.
    quantum : float
        Encoder step [m] (0: no rounding, the covariance is zero).

    Returns
    -------
    numpy.ndarray
        Shape ``(p, p)``: the units of ``W`` squared times m^2.
    """
    p = W.shape[0]
    out = np.zeros((p, p))
    if quantum <= 0.0:
        return out
    ratio = (x_noise / quantum) ** 2
    phase = 2.0 * np.pi * np.asarray(path, dtype=float) / quantum
    for h in range(1, HARMONICS + 1):
        damping = np.exp(-2.0 * np.pi ** 2 * h ** 2 * ratio) / h
        if damping < 1e-3:
            break
        a = quantum / np.pi * damping
        wc, ws = W @ np.cos(h * phase), W @ np.sin(h * phase)
        out += 0.5 * a ** 2 * (np.outer(wc, wc) + np.outer(ws, ws))
    return out


def widened(stats: Statistics, extra: np.ndarray, estimates: np.ndarray) -> Statistics:
    """``stats`` with the covariance ``extra`` [physical units] added to the parameters' one:
    standard errors, correlations and Student-t 95 % intervals redone (an undetermined
    parameter keeps its infinite standard error)."""
    se = np.asarray(stats.stderr, dtype=float)
    finite = np.isfinite(se)
    corr = np.where(np.isfinite(stats.correlation), stats.correlation, 0.0)
    s = np.where(finite, se, 0.0)
    cov = corr * np.outer(s, s) + extra
    se_new = np.where(finite, np.sqrt(np.clip(np.diag(cov), 0.0, None)), np.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr_new = cov / np.outer(se_new, se_new)
    corr_new[~np.isfinite(corr_new)] = np.nan
    np.fill_diagonal(corr_new, 1.0)
    tq = float(student_t.ppf(0.975, stats.dof))
    return dataclasses.replace(stats, stderr=se_new, low=estimates - tq * se_new, high=estimates + tq * se_new,
                               correlation=corr_new)
