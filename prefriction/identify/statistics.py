"""Gauss-Newton statistics of a least-squares fit: standard errors, 95 % intervals, correlation,
and the parameters the data cannot identify.

At the optimum of ``min |r(w)|^2`` with Jacobian ``J = dr/dw`` (and equality constraints with
Jacobian ``A``, multiple shooting), the estimates are approximately normal with covariance
``s^2 N (N^T J^T J N)^-1 N^T``, where ``N`` spans the null space of ``A`` (the identity without
constraints) and ``s^2 = |r|^2 / (n - p)`` with ``p`` the number of free directions (Bates and
Watts, *Nonlinear Regression Analysis and Its Applications*, Wiley 1988, ch. 2). The 95 %
intervals use Student's t quantile with ``n - p`` degrees of freedom.

That covariance assumes white residuals. Residuals of real records are not: noise on the
positions enters the force through ``dF/dx`` as a smooth error, quantisation repeats the same
error while the stage creeps, and a model error leaves runs. ``covariance="hac"`` (what
:func:`prefriction.identify.fit` uses) replaces ``s^2`` by the heteroscedasticity- and
autocorrelation-consistent (HAC) sandwich of Newey and West (*Econometrica* 55, 1987, 703-708):
with ``M = N (N^T J^T J N)^-1 N^T`` and the influence of sample ``t`` on the parameters
``psi_t = M_k J_t^T r_t`` (``M_k`` the parameters' rows; eq. S1),

``Cov = n / (n - p) [G_0 + sum_{l=1}^{L} (1 - l / (L + 1)) (G_l + G_l^T)]``,
``G_l = sum_t psi_t psi_{t-l}^T`` (eq. S2),

the Bartlett weights keeping it positive semi-definite; the bandwidth ``L`` is Andrews' plug-in
for the Bartlett kernel (*Econometrica* 59, 1991, 817-858, eq. 6.2) from an AR(1) fitted to each
``psi`` series, ``L = 1.1447 (alpha n)^(1/3)`` with
``alpha = sum 4 rho^2 v^2 / ((1 - rho)^6 (1 + rho)^2) / sum v^2 / (1 - rho)^4`` (eq. S3). With
white residuals ``L`` is near 0 and the result is the Gauss-Newton covariance (up to
heteroscedasticity). The Bartlett estimate is biased low in short records (its weights shrink
the positive correlations), so no variance is taken below the white-residual one: each
standard error is the larger of the two, the correlation the HAC one (eq. S4). Coverage is
measured in ``docs/identify.md#coverage``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.linalg import null_space
from scipy.stats import t as student_t

from prefriction._blas_threads import with_one_blas_thread

__all__ = ["BoundWarning", "ConvergenceWarning", "IdentifiabilityWarning", "NoisyPositionsWarning", "ResidualWarning",
           "Statistics", "at_bounds", "bandwidth", "gauss_newton", "hac"]

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
    covariance : str
        ``"iid"`` (Gauss-Newton, white residuals) or ``"hac"`` (eq. S2).
    bandwidth : int
        The HAC bandwidth ``L`` in samples (0 for ``"iid"``).
    stderr_iid : numpy.ndarray
        The Gauss-Newton standard errors (white residuals), for comparison with :attr:`stderr`.
    influence : numpy.ndarray or None
        ``psi`` of eq. S1 in physical units, shape ``(k, n)``: how much each sample moves each
        estimate (the residual diagnostics use it); ``None`` for ``"iid"``.
    """

    stderr: np.ndarray
    low: np.ndarray
    high: np.ndarray
    correlation: np.ndarray
    sigma_hat: float
    dof: int
    condition: float
    unidentifiable: tuple[tuple[str, str], ...]
    covariance: str = "iid"
    bandwidth: int = 0
    stderr_iid: np.ndarray | None = None
    influence: np.ndarray | None = None


def bandwidth(psi: np.ndarray) -> int:
    """Andrews' Bartlett-kernel bandwidth (eq. S3) for the influence series ``psi`` (shape ``(k, n)``).

    Parameters
    ----------
    psi : numpy.ndarray
        One series per row.

    Returns
    -------
    int
        ``L`` in samples, between 0 and ``n // 4``.
    """
    k, n = psi.shape
    num = den = 0.0
    for a in range(k):
        y = psi[a]
        y0, y1 = y[:-1], y[1:]
        d = float(y0 @ y0)
        if d <= 0.0:
            continue
        rho = min(max(float(y0 @ y1) / d, -0.97), 0.97)
        v = float(np.mean((y1 - rho * y0) ** 2))
        num += 4.0 * rho**2 * v**2 / ((1.0 - rho) ** 6 * (1.0 + rho) ** 2)
        den += v**2 / (1.0 - rho) ** 4
    if den <= 0.0:
        return 0
    return int(min(n // 4, np.ceil(1.1447 * (num / den * n) ** (1.0 / 3.0))))


def hac(psi: np.ndarray, L: int) -> np.ndarray:
    """The Newey-West sum of eq. S2 (without the ``n / (n - p)`` factor).

    Parameters
    ----------
    psi : numpy.ndarray
        Influence series, shape ``(k, n)``.
    L : int
        Bandwidth [samples].
    """
    if L == 0:
        return psi @ psi.T
    k, n = psi.shape
    # Bartlett weights are a boxcar convolved with itself: with the moving sums
    # B_t = sum_{j=0..L} psi_{t-j} (psi zero outside the record), sum_t B_t B_t^T = sum_l (L + 1 - |l|) G_l,
    # exactly eq. S2 times L + 1, in O(k n) instead of O(k^2 n L).
    c = np.cumsum(np.concatenate([psi, np.zeros((k, L))], axis=1), axis=1)
    B = c.copy()
    B[:, L + 1:] -= c[:, : n - 1]
    return (B @ B.T) / (L + 1.0)


@with_one_blas_thread
def gauss_newton(J: np.ndarray, r: np.ndarray, names: list[str], estimates: np.ndarray, scale: np.ndarray,
                 *, constraints: np.ndarray | None = None, limit: float = 0.5, covariance: str = "iid",
                 extra: Callable[[np.ndarray], np.ndarray] | None = None) -> Statistics:
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
    covariance : {"iid", "hac"}, default "iid"
        White-residual Gauss-Newton covariance, or the HAC sandwich (eq. S2).
    extra : callable, optional
        ``W -> C``: a covariance [physical units] added to the parameters' one, from the influence
        weights ``W = M_k J^T`` (physical units, shape ``(k, n)``; eq. S1 without the residual),
        e.g. the errors of the positions the model is driven along
        (:func:`prefriction.identify.prescribed.path_covariance`).

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
    M_k = (N[:k] @ inv) @ N.T   # the parameters' rows of M (eq. S1)
    cov_iid = s2 * (M_k @ N[:k].T) * np.outer(scale, scale)
    L, psi = 0, None
    if covariance not in ("iid", "hac"):
        raise ValueError(f"covariance must be 'iid' or 'hac', got {covariance!r}")
    W = (M_k @ J.T) * scale[:, None] if covariance == "hac" or extra is not None else None
    if covariance == "hac":
        psi = W * r[None, :]    # eq. S1, physical units
        L = bandwidth(psi)
        cov = hac(psi, L) * (n / dof)
        d_hac = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
        lift = np.maximum(np.sqrt(np.clip(np.diag(cov_iid), 0.0, None)) / d_hac, 1.0)
        cov = cov * np.outer(lift, lift)   # never narrower than the white-residual interval (eq. S4)
    else:
        cov = cov_iid.copy()
    if extra is not None:
        cov = cov + extra(W)
    se_iid = np.sqrt(np.clip(np.diag(cov_iid), 0.0, None))
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
    se_iid[undetermined] = np.inf
    return Statistics(se, estimates - tq * se, estimates + tq * se, corr, float(np.sqrt(s2)), dof, cond,
                      tuple((n_, reasons[n_]) for n_ in names if n_ in reasons), covariance, L, se_iid, psi)


class BoundWarning(UserWarning):
    """A fitted parameter ended on a bound of its allowed range (declared, user or structure
    bound): the optimum may lie beyond it, and its interval is cut at the bound."""


class ConvergenceWarning(UserWarning):
    """The fit stopped without converging (``FitResult.success`` is False)."""


def at_bounds(names: list[str], estimates: np.ndarray, low: np.ndarray, high: np.ndarray, scale: np.ndarray,
              lower: dict[str, float], upper: dict[str, float], why_low: dict[str, str],
              why_high: dict[str, str], floor: dict[str, float] | None = None
              ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Intervals cut to the allowed range and a note per parameter on a bound or cut.

    An estimate within ``1e-6`` of its scale (or of the bound) of a bound is on it. Its interval is
    one-sided: it starts at the bound. An interval that reaches past a bound is cut there.

    A lower bound that is another parameter's estimate (LuGre's ``Fs >= Fc``) is itself uncertain:
    the true values obey the relation, so the true ``Fs`` is at least the true ``Fc``, which lies
    anywhere in ``Fc``'s interval. ``floor`` gives such a parameter's cut (the lower end of its
    partner's interval): cutting at the partner's estimate would exclude a true ``Fs = Fc`` whenever
    ``Fc`` is overestimated, about half the fits of a model on the relation.

    Parameters
    ----------
    names : list of str
        Parameter names.
    estimates, low, high, scale : numpy.ndarray
        Estimates, 95 % interval ends and scales (physical units).
    lower, upper : dict
        The allowed range of each name.
    floor : dict, optional
        Per name, where to cut the interval's lower end instead of ``lower`` (at most ``lower``):
        the lower end of the interval of the partner whose estimate is the bound.
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
        cut_low = min(a, floor[n]) if floor and n in floor and np.isfinite(floor[n]) else a
        lo_out[i], hi_out[i] = max(low[i], cut_low), min(high[i], b)
        notes.append(note)
    return lo_out, hi_out, tuple(notes)


class ResidualWarning(UserWarning):
    """The residuals of a fit show structure the model does not explain (runs, correlation,
    spikes at reversals); the message names the estimates to distrust."""


class NoisyPositionsWarning(UserWarning):
    """The positions of :class:`prefriction.identify.ForceDisplacement` data turn far more often
    than the motion reverses, and no ``x_noise`` or ``quantum`` was declared: the fit integrates
    the model along the noise and its estimates are biased (``docs/identify.md#positions``)."""


def widen_statistics(stats: Statistics, names: list[str], estimates: np.ndarray, factors: dict[str, float],
                     limit: float) -> Statistics:
    """``stats`` with the standard errors of ``factors`` (``{name: factor}``) multiplied, their 95 %
    intervals widened to match, and each whose relative standard error then exceeds ``limit``
    reported as not identifiable (a secant check of a curved valley,
    :func:`prefriction.identify.polish.valley_secant`)."""
    se, low, high = stats.stderr.copy(), stats.low.copy(), stats.high.copy()
    tq = float(student_t.ppf(0.975, stats.dof))
    loose = dict(stats.unidentifiable)
    for name, f in factors.items():
        i = names.index(name)
        se[i] *= f
        low[i], high[i] = estimates[i] - tq * se[i], estimates[i] + tq * se[i]
        if name not in loose and not se[i] <= limit * abs(estimates[i]):
            loose[name] = (f"relative standard error {100.0 * se[i] / abs(estimates[i]):.3g} % > {100.0 * limit:.3g} % "
                           f"(the secant of the sum of squares along the valley, {f:.3g} times the linearisation's)")
    return dataclasses.replace(stats, stderr=se, low=low, high=high,
                               unidentifiable=tuple((n, loose[n]) for n in names if n in loose))
