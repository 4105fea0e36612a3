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
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

__all__ = ["LsqOutcome", "solve"]


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
        ``w -> (r, g)`` (the line search).
    w0 : numpy.ndarray
        Start point; its first ``len(lo)`` entries are bounded by ``lo``, ``hi``.
    lo, hi : numpy.ndarray
        Bounds of the leading entries.
    max_iter : int
        Most iterations.
    tol : float
        Convergence: the relative decrease of ``|r|^2`` in a full step and the step (relative to
        ``1 + |w|``) below ``tol``, with ``|g| <= gtol``.
    gtol : float, default 1e-9
        Largest constraint violation at convergence (in the scaled units of ``g``).
    progress : callable, optional
        Called with one line per iteration.
    """
    w = np.array(w0, dtype=float)
    nb = lo.size
    mu, rho = 1e-2, 0.0
    for it in range(1, max_iter + 1):
        r, J, g, A = full(w)
        f0 = 0.5 * float(r @ r)
        JtJ = (J.T @ J).tocsc()
        grad = J.T @ r
        diag = np.maximum(JtJ.diagonal(), 1e-12 * max(float(JtJ.diagonal().max()), 1e-300))
        step = lam = None
        while mu < 1e12:
            H = JtJ + sp.diags(mu * diag)
            K = sp.bmat([[H, A.T], [A, None]], format="csc")
            with np.errstate(all="ignore"):
                sol = spsolve(K, -np.concatenate([grad, g]))
            if np.all(np.isfinite(sol)):
                step, lam = sol[: w.size], sol[w.size:]
                break
            mu *= 10.0
        if step is None:
            return LsqOutcome(w, False, it, "the Gauss-Newton system is singular at every damping")
        rho = max(rho, 1.1 * float(np.abs(lam).max(initial=0.0)))
        alpha = _to_bounds(w[:nb], step[:nb], lo, hi)
        phi0 = _merit(r, g, rho)
        slope = float(grad @ step) - rho * float(np.abs(g).sum())
        accepted = False
        while alpha > 1e-10:
            wt = w + alpha * step
            rt, gt = plain(wt)
            if np.all(np.isfinite(rt)) and np.all(np.isfinite(gt)) and \
                    _merit(rt, gt, rho) <= phi0 + 1e-4 * alpha * min(slope, 0.0):
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            if mu < 1e10:
                mu *= 100.0
                continue
            return LsqOutcome(w, False, it, "the line search found no decrease of the merit function")
        mu = max(mu / 10.0, 1e-12) if alpha == 1.0 else min(mu * 10.0, 1e10)
        moved = float(np.max(np.abs(alpha * step) / (1.0 + np.abs(w))))
        w = wt
        f1 = 0.5 * float(rt @ rt)
        gmax = float(np.abs(gt).max(initial=0.0))
        if progress is not None:
            progress(f"iteration {it}: 0.5 |r|^2 = {f1:.6g}, |g| = {gmax:.2e}, step {moved:.2e}, alpha {alpha:.3g}")
        if gmax <= gtol and (moved <= tol or (alpha == 1.0 and f0 - f1 <= tol * f0 and moved <= 1e3 * tol)):
            return LsqOutcome(w, True, it, f"converged after {it} Gauss-Newton iterations")
    return LsqOutcome(w, False, max_iter, f"no convergence after max_iter = {max_iter} Gauss-Newton iterations")


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
