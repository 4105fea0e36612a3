"""Equality-constrained Gauss-Newton steps by a sparse direct factorisation (the last phase of
:func:`prefriction.identify.constrained_lsq.solve`).

At a point ``w`` with residuals ``r``, constraints ``g`` and their sparse Jacobians ``J``, ``A``,
the Gauss-Newton step ``d`` of ``min 0.5 |r(w)|^2`` subject to ``g(w) = 0`` solves

    min_d 0.5 |r + J d|^2 + 0.5 delta |d|^2   subject to   g + A d = 0,               (1)

whose optimality conditions, with the step's residual ``s = r + J d`` and the multipliers
``lam``, are the symmetric augmented system (Nocedal and Wright, *Numerical Optimization*, 2nd
ed., Springer 2006, (16.4) and 18.1, the KKT system of the Gauss-Newton model)

    [ -I    J        0  ] [  s  ]   [ -r ]
    [ J^T   delta I  A^T] [  d  ] = [  0 ]                                           (2)
    [  0    A        0  ] [ lam ]   [ -g ]

(the first row gives ``s = r + J d``, the second ``J^T (r + J d) + delta d + A^T lam = 0``, the
third ``A d = -g``). Unlike the normal equations ``J^T J``, (2) does not square the condition
number of ``J``. Multiple shooting makes (2) banded apart from the parameters: a residual row
touches the parameters and one node, a continuity row the parameters and two neighbouring nodes.
Ordered segment by segment, the rest is a band of constant width (about 120 for segments of 50
samples), which LAPACK's banded LU factorises in time and memory linear in the number of samples;
the parameters follow from their Schur complement. A general sparse LU (SuperLU through
:func:`scipy.sparse.linalg.splu`) fills in quadratically on the same matrices whatever its
ordering (COLAMD, or minimum degree on ``K + K^T``: 5.6 s against 0.17 s at 500 segments of 50
samples with 6 parameters and 3 node entries, 21 s against 0.34 s at 1,000), and an iterative
solve (LSMR) of the same steps stalls on these ill-conditioned matrices.

:func:`polish` takes such steps from the end point of the augmented Lagrangian: sequential
quadratic programming with the exact-penalty merit ``0.5 |r|^2 + nu |g|_1`` and a backtracking
line search (Nocedal and Wright 18.3, (18.28)), with a second-order correction of a rejected
full step (18.30). The constraints are linearised exactly, so the
defects fall quadratically; the step in the parameters stops mattering once its length is a small
fraction of their standard errors, which is how convergence is judged (see :func:`polish`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.linalg import solve_banded
from scipy.sparse.linalg import splu

__all__ = ["STEPS", "STEP_SE", "PolishOutcome", "kkt_step", "polish"]

STEP_SE = 1e-3
"""Largest Gauss-Newton step, in standard errors of the estimates (``|J d| / s``, ``s`` the
residual standard deviation), of a converged fit: a step a thousandth of a standard error moves no
estimate or interval in its printed digits."""
STEPS = 8
"""Most sparse Gauss-Newton steps of :func:`polish`."""
_HALVINGS = 12
"""Most halvings of a step in the line search."""
_BAND = 400
"""Widest band (``kl + ku + 1``) of the banded solve: a shooting segment of 50 samples gives about
120; the band's memory is ``(2 kl + ku + 1) x 8`` bytes per unknown."""
_DAMPING = 1e-12
"""``delta`` of (1) relative to the largest squared column norm of ``J``: keeps (2) regular when the
data leave a direction unidentified, without changing a determined step in its printed digits."""


@dataclass(frozen=True)
class PolishOutcome:
    """The end point of :func:`polish`."""

    w: np.ndarray
    success: bool
    steps: int
    message: str


def kkt_step(J: sp.spmatrix, A: sp.spmatrix, r: np.ndarray, g: np.ndarray, damping: float = 0.0,
             free: np.ndarray | None = None, border: int = 0,
             info: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Newton step ``d`` of (1) and the multipliers ``lam`` from a direct solve of (2).

    With ``border > 0`` the leading ``border`` entries of ``w`` (the parameters, touched by every
    row) are split off: the remaining unknowns of (2), ordered by the first entry of ``w`` they
    touch (a shooting segment's residuals, its node, its continuity rows, the next segment...),
    form a band of constant width, solved by LAPACK's banded LU with partial pivoting
    (:func:`scipy.linalg.solve_banded`) for the right-hand side and the ``border`` columns, and the
    border follows from its Schur complement (a ``border x border`` system): time and memory
    linear in the rows. Without a border, or when the band is wide, a sparse LU of (2) (SuperLU,
    minimum degree ordering of ``K + K^T``).

    Parameters
    ----------
    J : scipy.sparse matrix, shape (n, m)
        Jacobian of the residuals ``r``.
    A : scipy.sparse matrix, shape (p, m)
        Jacobian of the constraints ``g`` (full row rank).
    r : numpy.ndarray, shape (n,)
        Residuals.
    g : numpy.ndarray, shape (p,)
        Constraint values.
    damping : float, default 0
        ``delta >= 0`` of (1).
    free : numpy.ndarray of bool, shape (m,), optional
        Entries that may move; the others keep ``d = 0`` (bounds that hold).
    border : int, default 0
        Number of leading entries of ``w`` that couple all rows (the model parameters).
    info : dict, optional
        Filled with ``"border_variance"``: the diagonal of the border's block of the inverse of
        (2) (the free border entries, in order), which is the diagonal of the inverse reduced
        Gauss-Newton Hessian ``(N^T J^T J N)^-1`` of those entries on the constraints' null space
        (times ``s^2``: their variances); only when the banded solve is used.

    Returns
    -------
    d : numpy.ndarray, shape (m,)
        The step.
    lam : numpy.ndarray, shape (p,)
        Multipliers of the linearised constraints.

    Raises
    ------
    numpy.linalg.LinAlgError
        If (2) is singular (constraints without full row rank, or ``J`` rank-deficient on the
        null space of ``A`` with ``damping = 0``).
    """
    n, m = J.shape
    p = A.shape[0]
    if A.shape[1] != m or r.shape != (n,) or g.shape != (p,):
        raise ValueError(f"shapes do not match: J {J.shape}, A {A.shape}, r {r.shape}, g {g.shape}")
    cols = np.arange(m) if free is None else np.flatnonzero(free)
    Jf, Af = sp.csc_matrix(J)[:, cols], sp.csc_matrix(A)[:, cols]
    mid = sp.identity(cols.size, format="csc") * damping if damping > 0.0 else None
    blocks = [[-sp.identity(n, format="csc"), Jf, None], [Jf.T, mid, Af.T], [None, Af, None]]
    if p == 0:
        blocks = [row[:2] for row in blocks[:2]]
    K = sp.bmat(blocks, format="csr")
    rhs = np.concatenate([-r, np.zeros(cols.size), -g])
    nb = int(np.count_nonzero(cols < border))
    banded = _banded_solve(K, rhs, n + np.arange(nb), Jf[:, nb:], Af[:, nb:]) if nb else None
    sol = None
    if banded is not None:
        sol, variance = banded
        if info is not None:
            info["border_variance"] = variance
    if sol is None:
        try:
            sol = splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A").solve(rhs)
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            raise np.linalg.LinAlgError(f"the Gauss-Newton system of {m} unknowns and {p} constraints is "
                                        f"singular ({exc})") from exc
    if not np.all(np.isfinite(sol)):
        raise np.linalg.LinAlgError(f"the Gauss-Newton system of {m} unknowns and {p} constraints is singular")
    d = np.zeros(m)
    d[cols] = sol[n:n + cols.size]
    return d, sol[n + cols.size:]


def _banded_solve(K: sp.csr_matrix, rhs: np.ndarray, border: np.ndarray, Jn: sp.csc_matrix,
                  An: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray] | None:
    """Solve ``K x = rhs`` by the band of the non-border unknowns and the Schur complement ``S`` of
    the border; ``None`` when the band is wider than :data:`_BAND` (then a sparse LU is used).
    Also returns ``diag(S^-1)``, the border's block of ``K^-1`` (block inversion)."""
    N = K.shape[0]
    n, p = Jn.shape[0], An.shape[0]
    # key of each unknown: the first non-border entry of w it touches; residual rows, then nodes,
    # then continuity rows at equal keys
    first_j = _first_column(Jn, n)
    first_a = _first_column(An, p)
    key = np.concatenate([first_j * 3.0, np.arange(Jn.shape[1]) * 3.0 + 1.0, first_a * 3.0 + 2.0])
    inner = np.setdiff1d(np.arange(N), border)
    order = inner[np.argsort(key, kind="stable")]
    B = K[order][:, order].tocoo()
    kl = int(np.max(B.row - B.col, initial=0))
    ku = int(np.max(B.col - B.row, initial=0))
    if kl + ku + 1 > _BAND:
        return None
    ab = np.zeros((kl + ku + 1, order.size))
    ab[ku + B.row - B.col, B.col] = B.data
    C = K[order][:, border].toarray()
    try:
        X = solve_banded((kl, ku), ab, np.column_stack([rhs[order], C]), check_finite=False)
    except np.linalg.LinAlgError as exc:
        raise np.linalg.LinAlgError(f"the Gauss-Newton system of {N} unknowns is singular ({exc})") from exc
    D = K[border][:, border].toarray()
    S = D - C.T @ X[:, 1:]
    y = np.linalg.solve(S, rhs[border] - C.T @ X[:, 0])
    x = np.empty(N)
    x[order] = X[:, 0] - X[:, 1:] @ y
    x[border] = y
    return x, np.diag(np.linalg.inv(S)).copy()


def _first_column(M: sp.csc_matrix, rows: int) -> np.ndarray:
    """Index of the first structurally non-zero column of every row of ``M`` (``inf`` if none)."""
    coo = M.tocoo()
    first = np.full(rows, np.inf)
    np.minimum.at(first, coo.row, coo.col.astype(float))
    return first


def polish(full: Callable, plain: Callable, w: np.ndarray, lower: np.ndarray, upper: np.ndarray, *,
           gtol: float, steps: int = STEPS, border: int = 0) -> PolishOutcome:
    """Sparse Gauss-Newton (SQP) steps from ``w`` until the defects and the step are negligible.

    Each step solves (2) by :func:`kkt_step` at ``w`` (entries on a bound held there), then
    halves it until the merit ``0.5 |r|^2 + nu |g|_1`` falls by at least ``1e-4`` of its
    predicted decrease (Armijo), ``nu = 2 max |lam|`` (never lowered), which makes the step a
    descent direction of the merit (Nocedal and Wright (18.29)); the step is clipped to the bounds.

    Convergence: every ``|g| <= gtol`` and the step's length in standard errors,
    ``|J d| / s`` with ``s^2 = |r|^2 / (n - m + p)``, at most :data:`STEP_SE`. On the constraint
    manifold ``|J d|^2 / s^2 = d^T C^{-1} d`` with ``C`` the Gauss-Newton covariance of the
    estimates, so this bounds the remaining change of every estimate by a thousandth of its
    standard error. Where the steps of the nuisance entries (the nodes) stay larger because the
    residuals are only piecewise smooth in them (a stage hovering inside a segment), the test is
    applied to the parameters alone: every free parameter's step at most :data:`STEP_SE` of its
    standard error ``s sqrt((S^-1)_ii)``, ``S`` the Schur complement of the parameters in (2),
    whose inverse is the parameters' block of ``(N^T J^T J N)^-1`` (block inversion).

    Parameters
    ----------
    full : callable
        ``w -> (r, J, g, A)`` (sparse ``J`` and ``A``).
    plain : callable
        ``w -> (r, g)``.
    w : numpy.ndarray
        Start point (the augmented Lagrangian's end point).
    lower, upper : numpy.ndarray
        Bounds of every entry of ``w`` (``-inf``/``inf`` where none).
    gtol : float
        Largest constraint violation at convergence.
    steps : int, default :data:`STEPS`
        Most steps.
    border : int, default 0
        Leading entries of ``w`` that couple all rows (see :func:`kkt_step`).
    """
    w = np.array(w, dtype=float)
    nu = 0.0
    last = "no step taken"
    for k in range(1, steps + 1):
        r, J, g, A = full(w)
        n, m, p = J.shape[0], J.shape[1], A.shape[0]
        free = ~(((w <= lower) & np.isfinite(lower)) | ((w >= upper) & np.isfinite(upper)))
        scale = float(sp.csc_matrix(J).power(2).sum(axis=0).max()) if J.nnz else 1.0
        info: dict = {}
        try:
            d, lam = kkt_step(J, A, r, g, _DAMPING * scale, free, border, info)
        except np.linalg.LinAlgError as exc:
            return PolishOutcome(w, False, k - 1, str(exc))
        Jd = J @ d
        dof = max(n - m + p, 1)
        s = float(np.sqrt(r @ r / dof)) if r.size else 0.0
        size = float(np.linalg.norm(Jd)) / s if s > 0.0 else float(np.linalg.norm(Jd))
        gmax = float(np.abs(g).max(initial=0.0))
        moved = _parameter_step(d, free, border, info, s)
        if gmax <= gtol and (size <= STEP_SE or moved <= STEP_SE):
            what = (f"last step {size:.1e} standard errors" if size <= STEP_SE else
                    f"last step {moved:.1e} standard errors in every parameter ({size:.1e} with the nodes)")
            return PolishOutcome(w, True, k - 1, f"{k - 1} sparse Gauss-Newton steps, |g| = {gmax:.1e}, {what}")
        nu = max(nu, 2.0 * float(np.abs(lam).max(initial=0.0)))
        merit = 0.5 * float(r @ r) + nu * float(np.abs(g).sum())
        slope = float(r @ Jd) - nu * float(np.abs(g).sum())
        alpha, accepted = 1.0, False
        for half in range(_HALVINGS):
            trial = np.clip(w + alpha * d, lower, upper)
            rt, gt = plain(trial)
            if _accept(rt, gt, nu, merit, 1e-4 * alpha * min(slope, 0.0)):
                accepted = True
                break
            if half == 0 and np.all(np.isfinite(gt)):
                # second-order correction (Nocedal and Wright 18.3, (18.30)): the full step's
                # defects removed to first order, against the merit's rejection of a good step
                # where the constraints curve (the Maratos effect)
                try:
                    corr = np.clip(trial + kkt_step(J, A, np.zeros(n), gt, _DAMPING * scale, free, border)[0],
                                   lower, upper)
                except np.linalg.LinAlgError:
                    corr = None
                if corr is not None:
                    rc, gc = plain(corr)
                    if _accept(rc, gc, nu, merit, 1e-4 * min(slope, 0.0)):
                        trial, accepted = corr, True
                        break
            alpha *= 0.5
        last = (f"step {k}: |g| = {gmax:.1e}, step {size:.1e} standard errors ({moved:.1e} in the parameters), "
                f"length {alpha:.2g}")
        if not accepted:
            return PolishOutcome(w, False, k - 1, f"{last}; no decrease of the merit function along the step")
        w = trial
    r, g = plain(w)
    return PolishOutcome(w, False, steps, f"{last}; {steps} sparse Gauss-Newton steps did not converge "
                                          f"(|g| = {float(np.abs(g).max(initial=0.0)):.1e})")


def _parameter_step(d: np.ndarray, free: np.ndarray, border: int, info: dict, s: float) -> float:
    """Largest change of a free border entry (a model parameter) in the step ``d``, in its
    standard errors ``s sqrt(diag(S^-1))`` (``info`` of :func:`kkt_step`); ``inf`` without them."""
    var = info.get("border_variance")
    cols = np.flatnonzero(free[:border])
    if var is None or var.size != cols.size or not s > 0.0:
        return math.inf
    se = s * np.sqrt(np.clip(var, 1e-300, None))
    return float(np.max(np.abs(d[cols]) / se, initial=0.0))


def _accept(r: np.ndarray, g: np.ndarray, nu: float, merit: float, decrease: float) -> bool:
    """Armijo test of a trial point on the merit ``0.5 |r|^2 + nu |g|_1``."""
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(g))):
        return False
    return 0.5 * float(r @ r) + nu * float(np.abs(g).sum()) <= merit + decrease
