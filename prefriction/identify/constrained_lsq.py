"""Least squares with equality constraints (multiple shooting): an augmented Lagrangian around
scipy's trust-region least squares, sparse.

``min 0.5 |r(w)|^2`` subject to ``g(w) = 0`` and box bounds on the first entries of ``w``. Each
outer iteration minimises the augmented residual vector

    R(w) = [ r(w) ; sqrt(mu) (g(w) + lam / mu) ]                                     (1)

with :func:`scipy.optimize.least_squares` (trust-region reflective, ``x_scale="jac"``, the
sparse Jacobian ``[J ; sqrt(mu) A]`` solved by LSMR), then updates the multipliers
``lam <- lam + mu g`` and raises ``mu`` tenfold when ``|g|`` fell by less than a factor 10
(Nocedal and Wright, *Numerical Optimization*, 2nd ed., Springer 2006, 17.3, the method of
multipliers). Early outer iterations hold the continuity of the shooting segments loosely: the
fit first matches the data segment by segment and tightens the chain as it goes, which keeps it
from the drifting open-loop simulations that trap a fit started far from the optimum. The trust
region globalises each inner solve; the matrices of multiple shooting are block-sparse, so the
cost of an iteration grows linearly with the number of samples. A solve that three tenfold
raises of the weight no longer move stops as frozen (:data:`_APART`).

A large problem (beyond :data:`_DENSE`) solves the trust-region steps by LSMR, whose inexact steps
on these ill-conditioned matrices stall a little above the defect tolerance. Once its defects are
below :data:`_POLISH_BELOW`, the end phase takes sparse direct Gauss-Newton (SQP) steps of the
constrained problem itself (:func:`prefriction.identify.kkt.polish`: the KKT system factorised as
a band plus the parameters' Schur complement, linear in the samples) until the defects meet the
tolerance and the step is below a thousandth of the estimates' standard errors.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.optimize import least_squares

from prefriction._blas_threads import with_one_blas_thread
from prefriction.identify.kkt import STEPS, polish

__all__ = ["LsqOutcome", "solve"]

_DENSE = 2e9
"""Largest ``rows x columns^2`` of the augmented Jacobian solved densely (``tr_solver="exact"``,
an SVD per iteration: far fewer iterations than LSMR on these ill-conditioned problems, measured
27 against 200+ Jacobian evaluations on a 1,000-sample Dahl record); larger problems use LSMR."""
_MU0 = 0.01
"""Initial weight of the constraints relative to the residuals at the start: small, so that the
first inner solve matches the data segment by segment (measured: a start 2x off that weight 1
left in a wrong basin converged from 0.01)."""
_OUTER = 14
"""Most multiplier updates."""
_INNER = 40
"""Most Jacobian evaluations of one inner solve (an early, loose one need not converge)."""
_RESTARTS = 2
"""Most restarts of the nuisance entries after a stalled outer iteration."""
_POLISH_BELOW = 1e-3
"""Largest constraint violation from which the sparse solve (LSMR) hands over to the sparse direct
Gauss-Newton steps of :func:`prefriction.identify.kkt.polish` (measured on a 25,000-sample LuGre
record: LSMR's trust-region steps stall at defects of 2e-5 to 8e-5 against the tolerance 1e-5,
where the direct steps reach it in two or three steps)."""
_POLISHES = 2
"""Most attempts of :func:`prefriction.identify.kkt.polish` in one solve."""
_APART = 3
"""Multiplier updates in a row, each raising the constraint weight tenfold, after which a solve
stops as frozen when its constraint violation and its sum of squares each changed by less than
:data:`_FROZEN` (relative) over them although the constraint term ``mu |g|^2`` weighs at least
as much as the data term ``|r|^2``: more weight no longer moves it, and its segments do not close
near this point. Measured on the 2.5 kg, 2 kHz, 10 nm closed-loop Dahl ``gamma = 2`` stage at
2,500 samples (seed 1): the whole chain with every parameter free went on for ten more updates,
its violation at 7.1e-3 and its sum of squares unchanged to three digits while the weight rose
to 1e12. Only a frozen solve stops: one whose sum of squares rises with the weight is still
moving its parameters, and on that stage where it went on the end point it reached decided
whether the record's moves converged from it (seed 0)."""
_FROZEN = 0.1
"""See :data:`_APART`."""
_RESTART_ABOVE = 1e-2
"""Smallest constraint violation of a stalled outer iteration that restarts the nodes (below it
a restart loses more than it gains: measured on 25,000 samples, 1.2e-5 became 5e-4)."""


@dataclass(frozen=True)
class LsqOutcome:
    """The end point of :func:`solve` and how it got there."""

    w: np.ndarray
    success: bool
    iterations: int
    message: str


class _Cache:
    """``full`` evaluated once per point: ``least_squares`` asks for the residuals and then the
    Jacobian at the same point."""

    def __init__(self, full: Callable, plain: Callable) -> None:
        self.full, self.plain = full, plain
        self.w: np.ndarray | None = None
        self.value: Any = None
        self.jacobians = 0

    def at(self, w: np.ndarray) -> Any:
        if self.w is None or not np.array_equal(w, self.w):
            self.value = self.full(w)
            self.w = w.copy()
            self.jacobians += 1
        return self.value


@with_one_blas_thread
def solve(full: Callable, plain: Callable, w0: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, max_iter: int,
          tol: float, gtol: float = 1e-9, weight: float = _MU0,
          restart: Callable[[np.ndarray], np.ndarray] | None = None,
          progress: Callable[[str], None] | None = None, inner_tol: float = 1e-8,
          final_tol: float = 0.0) -> LsqOutcome:
    """Constrained least squares from ``w0`` by the method of multipliers (1).

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
        Most Jacobian evaluations over all outer iterations.
    tol : float
        Relative tolerance of the inner solves (``xtol``, ``ftol``).
    gtol : float, default 1e-9
        Largest constraint violation at convergence (in the scaled units of ``g``).
    weight : float, default :data:`_MU0`
        Initial constraint weight ``mu`` relative to ``|r|^2 / |g|^2`` at ``w0``: small to let the
        segments first match the data (a start far from the optimum), larger for a start near it.
    restart : callable, optional
        ``w -> w'``: a new start of the nuisance entries at the parameters of ``w`` (the shooting
        nodes simulated from the data), used when an outer iteration stalls (no step, constraints
        violated by more than :data:`_RESTART_ABOVE`): at a kink of the motion (a reversal that
        moves between sub-steps) the trust region can shrink to nothing. At most :data:`_RESTARTS` times, each reported.
    progress : callable, optional
        Called with one line per outer iteration.
    inner_tol : float, default 1e-8
        ``ftol`` of the inner solves before the last (their ``xtol`` is ``1e-8``).
    final_tol : float, default 0.0
        The last inner solve uses ``max(tol, final_tol)``: a problem that is only piecewise smooth
        never meets a tight ``ftol`` (its trust region shrinks on the kinks until ``max_nfev``).
    """
    cache = _Cache(full, plain)
    nb = lo.size
    lower = np.r_[lo, np.full(w0.size - nb, -np.inf)]
    upper = np.r_[hi, np.full(w0.size - nb, np.inf)]
    w = np.clip(np.array(w0, dtype=float), lower, upper)
    inside = (w <= lower) | (w >= upper)
    w[inside] = np.where(np.isfinite(lower[inside]) & np.isfinite(upper[inside]),
                         0.5 * (lower[inside] + upper[inside]), w[inside])
    r, g = plain(w)
    dense = float(r.size + g.size) * w.size**2 <= _DENSE
    lam = np.zeros(g.size)
    mu = weight * max(1.0, float(r @ r)) / max(1.0, float(g @ g)) if g.size else 1.0
    mu = float(np.clip(mu, 1e-4, 1e6))
    gmax_prev = np.inf
    message = ""
    restarts: list[str] = []
    polished: list[str] = []
    outer = 0
    history: list[tuple[float, float, float, bool]] = []   # (|r|^2, max |g|, mu |g|^2, weight raised) per update
    while outer < _OUTER:
        outer += 1
        root = np.sqrt(mu)

        def fun(x: np.ndarray) -> np.ndarray:
            if cache.w is not None and np.array_equal(x, cache.w):
                rr, _J, gg, _A = cache.value
            else:
                rr, gg = plain(x)
            out = np.concatenate([rr, root * gg + lam / root])
            return out if np.all(np.isfinite(out)) else np.full(out.size, 1e150)

        def jac(x: np.ndarray) -> Any:
            _r, J, _g, A = cache.at(x)
            out = sp.vstack([J, root * A], format="csr")
            return out.toarray() if dense else out

        budget = max_iter - cache.jacobians
        if budget < 1:
            message = f"max_iter = {max_iter} Jacobian evaluations reached"
            break
        final = outer > 1 and gmax_prev <= 10.0 * gtol
        with np.errstate(over="ignore"):  # a trial step whose residuals overflow is rejected, not an error
            sol = least_squares(fun, w, jac=jac, bounds=(lower, upper), method="trf",
                                tr_solver="exact" if dense else "lsmr",
                                x_scale="jac", xtol=max(tol, final_tol) if final else max(tol, 1e-8),
                                ftol=max(tol, final_tol) if final else inner_tol,
                                gtol=1e-12, max_nfev=max(min(budget, _INNER) * 2, 2))
        stalled = np.array_equal(sol.x, w) or sol.nfev <= 1
        w = sol.x
        r, g = plain(w)
        gmax = float(np.abs(g).max(initial=0.0))
        if stalled and gmax > _RESTART_ABOVE and restart is not None and len(restarts) < _RESTARTS:
            w = restart(w)
            r, g = plain(w)
            lam = np.zeros(g.size)
            restarts.append(f"restart {len(restarts) + 1} of the nodes after outer iteration {outer} "
                            f"(stalled at |g| = {gmax:.2e})")
            if progress is not None:
                progress(restarts[-1])
            gmax_prev = np.inf
            continue
        if progress is not None:
            progress(f"outer iteration {outer}: 0.5 |r|^2 = {0.5 * float(r @ r):.6g}, |g| = {gmax:.2e}, "
                     f"weight {mu:.2g}, {sol.nfev} evaluations ({sol.message})")
        if final and gmax <= gtol and sol.status > 0:
            return LsqOutcome(w, True, cache.jacobians, f"converged after {outer} multiplier updates and "
                                                        f"{cache.jacobians} Jacobian evaluations"
                              + "".join(f"; {line}" for line in restarts))
        if not dense and gmax <= _POLISH_BELOW and len(polished) < _POLISHES:
            done = _polish(cache, w, lower, upper, max_iter, gtol, progress, nb)
            polished.append(done.message)
            if done.success:
                return LsqOutcome(done.w, True, cache.jacobians, f"converged after {outer} multiplier updates and "
                                                                 f"{done.message} ({cache.jacobians} Jacobian "
                                                                 f"evaluations)" + "".join(f"; {x}" for x in restarts))
            if done.steps:   # the steps taken lowered the merit and met the constraints better: go on from there
                w = done.w
                r, g = plain(w)
                gmax = float(np.abs(g).max(initial=0.0))
        history.append((float(r @ r), gmax, mu * float(g @ g), gmax > 0.1 * gmax_prev))
        lam = lam + mu * g
        if history[-1][3]:
            mu = min(10.0 * mu, 1e12)
        gmax_prev = gmax
        if (apart := _apart(history)):
            return LsqOutcome(w, False, cache.jacobians, apart + "".join(f"; {x}" for x in restarts))
        message = f"constraint violation {gmax:.2e} after {outer} multiplier updates"
    return LsqOutcome(w, False, cache.jacobians, (message or "no convergence")
                      + "".join(f"; {x}" for x in restarts + [f"sparse Gauss-Newton: {x}" for x in polished]))


def _apart(history: list[tuple[float, float, float, bool]]) -> str:
    """Why the solve stops as frozen (:data:`_APART`), or ``""``."""
    if len(history) <= _APART or not all(raised for *_x, raised in history[-_APART - 1:-1]):
        return ""
    (r0, g0, *_), (r1, g1, p1, _) = history[-_APART - 1], history[-1]
    if abs(g1 - g0) < _FROZEN * g0 and abs(r1 - r0) < _FROZEN * r0 and p1 >= r1:
        return (f"defects {g0:.2e} -> {g1:.2e}, 0.5 |r|^2 {0.5 * r0:.4g} -> {0.5 * r1:.4g} over {_APART} tenfold "
                f"weight raises (mu |g|^2 {p1:.3g} > |r|^2 {r1:.3g}): the segments do not close")
    return ""


def _polish(cache: _Cache, w: np.ndarray, lower: np.ndarray, upper: np.ndarray, max_iter: int, gtol: float,
            progress: Callable[[str], None] | None, border: int) -> Any:
    """:func:`prefriction.identify.kkt.polish` from ``w`` within the remaining Jacobian budget."""
    done = polish(cache.at, cache.plain, w, lower, upper, gtol=gtol,
                  steps=max(0, min(STEPS, max_iter - cache.jacobians)), border=border)
    if progress is not None:
        progress(f"sparse Gauss-Newton: {done.message}")
    return done
