"""Gauss-Newton for least squares with equality constraints (multiple shooting), sparse.

``min 0.5 |r(w)|^2`` subject to ``g(w) = 0`` and box bounds on the first entries of ``w``. Each
iteration solves the Levenberg-Marquardt damped KKT system

    [ J^T J + mu D   A^T ] [dw]     [ -J^T r ]
    [ A              0   ] [lam]  = [ -g     ]

(``D`` the diagonal of ``J^T J``, ``A = dg/dw``) with scipy's sparse LU, shortens the step to
stay inside the bounds and backtracks on the exact-penalty merit ``0.5 |r|^2 + rho |g|_1``
(Nocedal and Wright, *Numerical Optimization*, 2nd ed., Springer 2006, 18.3 and 10.3). The
matrices of multiple shooting are block-sparse, so the cost of a step grows linearly with
the number of samples.
"""

from __future__ import annotations

from dataclasses import dataclass
import warnings
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

__all__ = ["LsqOutcome", "solve"]

_MU_DONE = 1e-4
"""Largest damping at which a short step counts as convergence (a damped step is short anyway)."""


@dataclass(frozen=True)
class LsqOutcome:
    """The end point of :func:`solve` and how it got there."""

    w: np.ndarray
    success: bool
    iterations: int
    message: str


def _merit(r: np.ndarray, g: np.ndarray, rho: float) -> float:
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(g))) or np.abs(r).max(initial=0.0) > 1e150:
        return np.inf
    return 0.5 * float(r @ r) + rho * float(np.abs(g).sum())


def solve(full: Callable, plain: Callable, w0: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, max_iter: int,
          tol: float, gtol: float = 1e-9, progress: Callable[[str], None] | None = None) -> LsqOutcome:
    """Constrained Gauss-Newton from ``w0``.

    Parameters
    ----------
    full : callable
        ``w -> (r, J, g, A)``: residuals, their sparse Jacobian, constraints and their sparse Jacobian.
    plain : callable
        ``w -> (r, g)`` (trial points).
    w0 : numpy.ndarray
        Start point; its first ``len(lo)`` entries are bounded by ``lo``, ``hi``.
    lo, hi : numpy.ndarray
        Bounds of the leading entries.
    max_iter : int
        Most iterations (Jacobian evaluations).
    tol : float
        Convergence: the step (relative to ``1 + |w|``) below ``tol``, or a full step that
        decreases ``|r|^2`` by less than ``tol`` relative and moves less than ``1000 tol``,
        with ``|g| <= gtol``.
    gtol : float, default 1e-9
        Largest constraint violation at convergence (in the scaled units of ``g``).
    progress : callable, optional
        Called with one line per iteration.

    Notes
    -----
    A trial step is accepted when the merit decreases (by at least ``1e-4`` of the decrease the
    linear model predicts); convergence is declared only at a damping ``mu <= 1e-4``; a rejected full step first gets a second-order correction (the
    constraints' curvature, the Maratos effect), then a larger damping ``mu``.
    """
    w = np.array(w0, dtype=float)
    nb = lo.size
    mu, rho = 1e-2, 0.0
    r, J, g, A = full(w)
    for it in range(1, max_iter + 1):
        f0 = 0.5 * float(r @ r)
        JtJ = (J.T @ J).tocsc()
        grad = J.T @ r
        diag = np.maximum(JtJ.diagonal(), 1e-12 * max(float(JtJ.diagonal().max()), 1e-300))
        accepted = False
        while not accepted and mu < 1e12:
            lu = _factor(JtJ, diag, mu, A)
            if lu is None:
                mu *= 10.0
                continue
            sol = lu.solve(-np.concatenate([grad, g]))
            d, lam = sol[: w.size], sol[w.size:]
            rho = max(rho, 1.1 * float(np.abs(lam).max(initial=0.0)))
            phi0 = _merit(r, g, rho)
            Jd = J @ d
            pred = -(float(grad @ d) + 0.5 * float(Jd @ Jd)) + rho * float(np.abs(g).sum())
            alpha = _to_bounds(w[:nb], d[:nb], lo, hi)
            wt = w + alpha * d
            rt, gt = plain(wt)
            phi = _merit(rt, gt, rho)
            if not phi0 - phi >= 0.1 * alpha * pred and np.isfinite(phi):
                corr = lu.solve(np.concatenate([np.zeros(w.size), -gt]))[: w.size]
                beta = _to_bounds(wt[:nb], corr[:nb], lo, hi)
                ws = wt + beta * corr
                rs, gs = plain(ws)
                if _merit(rs, gs, rho) < phi:
                    wt, rt, gt, phi = ws, rs, gs, _merit(rs, gs, rho)
            ratio = (phi0 - phi) / max(alpha * pred, 1e-300)
            if ratio >= 1e-4:
                accepted = True
                mu = max(mu / 3.0, 1e-12) if ratio > 0.25 else mu
            else:
                mu *= 10.0
        if not accepted:
            return LsqOutcome(w, False, it, "no decrease of the merit function at any damping")
        moved = float(np.max(np.abs(wt - w) / (1.0 + np.abs(w))))
        w = wt
        r, J, g, A = full(w)
        f1 = 0.5 * float(r @ r)
        gmax = float(np.abs(g).max(initial=0.0))
        if progress is not None:
            progress(f"iteration {it}: 0.5 |r|^2 = {f1:.6g}, |g| = {gmax:.2e}, step {moved:.2e}, damping {mu:.2g}")
        if gmax <= gtol and (moved <= tol or (alpha == 1.0 and f0 - f1 <= tol * f0 and moved <= 1e3 * tol)):
            if mu <= _MU_DONE:
                return LsqOutcome(w, True, it, f"converged after {it} Gauss-Newton iterations")
            mu = 1e-2 * _MU_DONE  # a short step of a heavily damped system is no optimum: try Gauss-Newton
    return LsqOutcome(w, False, max_iter, f"no convergence after max_iter = {max_iter} Gauss-Newton iterations")


def _factor(JtJ: sp.csc_matrix, diag: np.ndarray, mu: float, A: sp.csr_matrix) -> Any:
    """Sparse LU of the damped KKT matrix, or None if it is singular."""
    K = sp.bmat([[JtJ + sp.diags(mu * diag), A.T], [A, None]], format="csc")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return splu(K)
    except RuntimeError:
        return None


def _to_bounds(x: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Largest ``alpha <= 1`` that keeps ``x + alpha d`` within 99.5 % of the way to the bounds."""
    alpha = 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        up = np.where(d > 0, (hi - x) / d, np.inf)
        down = np.where(d < 0, (lo - x) / d, np.inf)
    lim = float(np.min(np.concatenate([up, down, [np.inf]])))
    if lim < 1.0:
        alpha = 0.995 * lim
    return alpha
