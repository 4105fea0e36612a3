"""Gauss-Newton statistics of a least-squares fit: standard errors, 95 % intervals, correlation,
and the parameters the data cannot identify.

At the optimum of ``min |r(w)|^2`` with Jacobian ``J = dr/dw`` (and equality constraints with
Jacobian ``A``, multiple shooting), the estimates are approximately normal with covariance
``s^2 N (N^T J^T J N)^-1 N^T``, where ``N`` spans the null space of ``A`` (the identity without
constraints) and ``s^2 = |r|^2 / (n - p)`` with ``p`` the number of free directions (Bates and
Watts, *Nonlinear Regression Analysis and Its Applications*, Wiley 1988, ch. 2). The 95 %
intervals use Student's t quantile with ``n - p`` degrees of freedom.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import null_space
from scipy.stats import t as student_t

__all__ = ["BoundWarning", "ConvergenceWarning", "IdentifiabilityWarning", "Statistics", "at_bounds", "gauss_newton"]

SINGULAR = 1e-12
"""Eigenvalue of the Jacobi-scaled ``N^T J^T J N`` (relative to the largest) below which a
direction is undetermined."""


class IdentifiabilityWarning(UserWarning):
    """The data cannot identify a parameter: its relative standard error is huge, or it enters
    the fit only in a combination with others (a singular information matrix)."""


@dataclass(frozen=True)
class Statistics:
    """Gauss-Newton statistics of the fitted parameters (physical units).

    Attributes
    ----------
    stderr : numpy.ndarray
        Standard errors (``inf`` along an undetermined direction).
    low, high : numpy.ndarray
        95 % confidence intervals (t quantile).
    correlation : numpy.ndarray
        Correlation matrix of the estimates (NaN where a standard error is infinite).
    sigma_hat : float
        Residual standard deviation ``|r| / sqrt(n - p)``.
    dof : int
        Degrees of freedom ``n - p``.
    condition : float
        Condition number of the Jacobi-scaled information matrix (columns of ``J`` normalised)
        over the variables that change the residual (a nuisance variable that changes nothing,
        such as the initial virgin distance of a record that starts in gross sliding, is left
        out; a parameter that changes nothing is reported as unidentifiable).
    unidentifiable : tuple of (str, str)
        Names of the parameters the data cannot identify, each with the reason.
    """

    stderr: np.ndarray
    low: np.ndarray
    high: np.ndarray
    correlation: np.ndarray
    sigma_hat: float
    dof: int
    condition: float
    unidentifiable: tuple[tuple[str, str], ...]


def gauss_newton(J: np.ndarray, r: np.ndarray, names: list[str], estimates: np.ndarray, scale: np.ndarray,
                 *, constraints: np.ndarray | None = None, limit: float = 0.5) -> Statistics:
    """Statistics of the parameters at the columns ``0..len(names)-1`` of ``J``.

    Parameters
    ----------
    J : numpy.ndarray
        Residual Jacobian with respect to the optimisation vector ``w`` (shape ``(n, n_w)``);
        its first ``len(names)`` columns are the scaled parameters ``p / scale``, the others
        nuisance variables (initial state, shooting nodes, reversal times).
    r : numpy.ndarray
        Residuals at the optimum.
    names : list of str
        Parameter names.
    estimates : numpy.ndarray
        Fitted physical values.
    scale : numpy.ndarray
        ``p = w * scale`` for the parameter columns.
    constraints : numpy.ndarray or None
        Jacobian of the equality constraints with respect to ``w`` (multiple shooting).
    limit : float, default 0.5
        Relative standard error above which a parameter is reported as not identifiable.

    Returns
    -------
    Statistics
    """
    n, nw = J.shape
    k = len(names)
    N = np.eye(nw) if constraints is None or constraints.size == 0 else null_space(constraints)
    p_eff = N.shape[1]
    dof = n - p_eff
    if dof < 1:
        raise ValueError(f"the fit has {p_eff} free directions and only {n} residuals: it needs more samples "
                         f"than free parameters and nuisance variables")
    rss = float(r @ r)
    s2 = rss / dof
    H = (J @ N).T @ (J @ N)
    d = np.sqrt(np.diag(H))
    moves = d > 0.0    # variables that change the residual (the condition number is theirs)
    d[~moves] = 1.0  # a column that changes nothing stays zero: a singular direction
    lam, U = np.linalg.eigh(H / np.outer(d, d))  # Jacobi-scaled: eigenvalues measure collinearity
    top = max(float(lam[-1]), 1e-300)
    good = lam > SINGULAR * top
    inv = ((U[:, good] / lam[good]) @ U[:, good].T) / np.outer(d, d)
    U = U / d[:, None]  # null directions back in the coordinates of w
    cov_w = s2 * N @ inv @ N.T
    cov = cov_w[:k, :k] * np.outer(scale, scale)
    var = np.clip(np.diag(cov).copy(), 0.0, None)
    reasons: dict[str, str] = {}
    null_dirs = N @ U[:, ~good]
    for j in range(null_dirs.shape[1]):
        comp = null_dirs[:k, j] / max(float(np.max(np.abs(null_dirs[:, j]))), 1e-300)
        involved = [names[i] for i in np.flatnonzero(np.abs(comp) > 0.2)]  # relative to the largest entry
        for name in involved:
            var[names.index(name)] = np.inf
            others = [o for o in involved if o != name]
            reasons[name] = ("enters only in a combination with " + ", ".join(others)) if others else \
                "does not change the fitted signal"
    se = np.sqrt(var)
    tq = float(student_t.ppf(0.975, dof))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
        rse = se / np.abs(estimates)
    undetermined = ~np.isfinite(se)
    corr[undetermined, :] = np.nan
    corr[:, undetermined] = np.nan
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    for i, name in enumerate(names):
        if name not in reasons and not rse[i] <= limit:
            reasons[name] = f"relative standard error {100.0 * rse[i]:.3g} % > {100.0 * limit:.3g} %"
    lam_moving = np.linalg.eigvalsh((H / np.outer(d, d))[np.ix_(moves, moves)]) if moves.any() else lam
    cond = float(lam_moving[-1] / lam_moving[0]) if lam_moving[0] > 0 else np.inf
    return Statistics(se, estimates - tq * se, estimates + tq * se, corr, float(np.sqrt(s2)), dof, cond,
                      tuple((n_, reasons[n_]) for n_ in names if n_ in reasons))


class BoundWarning(UserWarning):
    """A fitted parameter ended on a bound of its allowed range (declared, user or structure
    bound): the optimum may lie beyond it, and its interval is cut at the bound."""


class ConvergenceWarning(UserWarning):
    """The fit stopped without converging (``FitResult.success`` is False)."""


def at_bounds(names: list[str], estimates: np.ndarray, low: np.ndarray, high: np.ndarray, scale: np.ndarray,
              lower: dict[str, float], upper: dict[str, float], why_low: dict[str, str],
              why_high: dict[str, str]) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Intervals cut to the allowed range and a note per parameter on a bound or cut.

    An estimate within ``1e-6`` of its scale (or of the bound) of a bound is on it. Its interval is
    one-sided: it starts at the bound. An interval that reaches past a bound is cut there.

    Parameters
    ----------
    names : list of str
        Parameter names.
    estimates, low, high, scale : numpy.ndarray
        Estimates, 95 % interval ends and scales (physical units).
    lower, upper : dict
        The allowed range of each name.
    why_low, why_high : dict
        What each end of the range is (``"the declared range"``, ``"the user bound"``, a structure
        boundary).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, tuple of str)
        Cut interval ends and a note per parameter (``""`` when neither on a bound nor cut).
    """
    lo_out, hi_out, notes = low.copy(), high.copy(), []
    for i, n in enumerate(names):
        a, b = lower[n], upper[n]
        note = ""
        for side, bound, why in (("lower", a, why_low[n]), ("upper", b, why_high[n])):
            if np.isfinite(bound) and abs(estimates[i] - bound) <= 1e-6 * max(abs(scale[i]), abs(bound)):
                note = f"on its {side} bound {bound:.6g} ({why}); interval one-sided"
        if not note and (low[i] < a or high[i] > b):
            cut = a if low[i] < a else b
            which = why_low[n] if low[i] < a else why_high[n]
            note = f"interval cut at {cut:.6g} ({which})"
        lo_out[i], hi_out[i] = max(low[i], a), min(high[i], b)
        notes.append(note)
    return lo_out, hi_out, tuple(notes)
