"""Standard errors that hold for serially correlated residuals: the Newey-West sandwich.

Residuals of records fitted sample by sample (inverse models, closed-loop simulations) are
correlated in time; ``s^2 (J^T J)^-1`` then understates the spread of the estimates. The sandwich

    C = (J^T J)^-1 S (J^T J)^-1 n / (n - p),   S = sum_{|l| <= L} w_l sum_k g_k g_{k-l}^T,   g_k = J_k r_k   (1)

with the Bartlett weights ``w_l = 1 - |l| / (L + 1)`` (Newey and West, *Econometrica* 55, 1987)
is consistent for any short-memory correlation. The lag ``L`` is Andrews' AR(1) plug-in
(*Econometrica* 59, 1991, (6.4)): ``L = 1.1447 (alpha n)^(1/3)``,
``alpha = 4 rho^2 / ((1 - rho)^2 (1 + rho)^2)`` with ``rho`` the residuals' lag-1
autocorrelation, at most ``n / 4``. Independent residuals give ``L`` near 0 and ``C`` near the
Gauss-Newton covariance.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.stats import t as student_t

from prefriction.identify.statistics import Statistics

__all__ = ["andrews_lag", "sandwich"]


def andrews_lag(r: np.ndarray) -> int:
    """Bartlett lag ``L`` of Andrews' AR(1) plug-in for the residuals ``r``."""
    n = r.size
    rho = float(np.clip(np.corrcoef(r[:-1], r[1:])[0, 1], -0.97, 0.97)) if n > 3 else 0.0
    alpha = 4.0 * rho ** 2 / ((1.0 - rho) ** 2 * (1.0 + rho) ** 2)
    return int(min(np.floor(1.1447 * (alpha * n) ** (1.0 / 3.0)), n // 4))


def sandwich(J: np.ndarray, r: np.ndarray, stats: Statistics, estimates: np.ndarray, scale: np.ndarray,
             channels: int = 1, names: list[str] | None = None, limit: float = 0.5) -> tuple[Statistics, int]:
    """``stats`` with standard errors and 95 % intervals from the sandwich (1).

    Parameters
    ----------
    J : numpy.ndarray
        Residual Jacobian with respect to the scaled parameters ``p / scale`` (``n x p``).
    r : numpy.ndarray
        Residuals.
    stats : Statistics
        The Gauss-Newton statistics (their identifiability findings are kept; an undetermined
        parameter keeps an infinite standard error).
    estimates, scale : numpy.ndarray
        Physical estimates and the scales of the columns.
    channels : int, default 1
        Number of signals stacked in ``r`` (each the same length, in time order): their scores at
        the same sample are summed before the lags are taken.
    names : list of str, optional
        The parameters' names: the relative-standard-error findings are redone with the sandwich's
        standard errors (``limit`` as in :func:`prefriction.identify.statistics.gauss_newton`).
    limit : float, default 0.5
        Relative standard error above which a parameter is reported as not identifiable.

    Returns
    -------
    (Statistics, int)
        The statistics with sandwich standard errors, and the lag used.
    """
    n, p = J.shape
    g = (J * r[:, None]).reshape(channels, n // channels, p).sum(axis=0)
    L = andrews_lag(r.reshape(channels, -1)[0])
    S = g.T @ g
    for lag in range(1, L + 1):
        G = g[lag:].T @ g[:-lag]
        S += (1.0 - lag / (L + 1.0)) * (G + G.T)
    H = np.linalg.pinv(J.T @ J)
    cov = H @ S @ H * (n / max(n - p, 1)) * np.outer(scale, scale)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    se = np.where(np.isfinite(stats.stderr), se, np.inf)
    tq = float(student_t.ppf(0.975, stats.dof))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    unident = stats.unidentifiable
    if names is not None:
        kept = [(n, why) for n, why in unident if not why.startswith("relative standard error")]
        with np.errstate(invalid="ignore", divide="ignore"):
            rse = se / np.abs(estimates)
        flagged = {n for n, _ in kept}
        kept += [(n, f"relative standard error {100.0 * rse[i]:.3g} % > {100.0 * limit:.3g} %")
                 for i, n in enumerate(names) if n not in flagged and not rse[i] <= limit]
        unident = tuple(sorted(kept, key=lambda item: names.index(item[0])))
    fields = {f.name for f in dataclasses.fields(stats)}
    marks = {k: v for k, v in (("covariance", "hac"), ("bandwidth", L), ("stderr_iid", stats.stderr)) if k in fields}
    return dataclasses.replace(stats, stderr=se, low=estimates - tq * se, high=estimates + tq * se,
                               correlation=corr, unidentifiable=unident, **marks), L
