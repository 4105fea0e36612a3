"""Long Motion records: the sparse Gauss-Newton step of the multiple-shooting fit and a
25,000-sample fit from a factor-2 start.

References independent of the code under test: the step against a dense numpy solve of the
KKT system of the linearised problem and against the null-space method (scipy.linalg.null_space,
numpy.linalg.lstsq); the fit against the true parameters of a record simulated by the scipy
integration of :mod:`prefriction.identify.synthetic_loop` (LSODA per sample interval, restarted
at every velocity reversal), written from the equations.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.linalg import null_space

from prefriction.identify.kkt import kkt_step, polish


def _shooting_pattern(rng: np.random.Generator, nth: int = 3, ny: int = 2, segments: int = 6,
                      per: int = 7) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Random ``J``, ``A`` with the sparsity of multiple shooting: a residual row touches the
    parameters and its segment's node, a continuity row the parameters, its node and ``-I`` on
    the next node."""
    m = nth + ny * segments
    J = np.zeros((segments * per, m))
    for j in range(segments):
        rows = slice(j * per, (j + 1) * per)
        J[rows, :nth] = rng.standard_normal((per, nth))
        J[rows, nth + j * ny: nth + (j + 1) * ny] = rng.standard_normal((per, ny))
    A = np.zeros(((segments - 1) * ny, m))
    for j in range(segments - 1):
        rows = slice(j * ny, (j + 1) * ny)
        A[rows, :nth] = rng.standard_normal((ny, nth))
        A[rows, nth + j * ny: nth + (j + 1) * ny] = rng.standard_normal((ny, ny))
        A[rows, nth + (j + 1) * ny: nth + (j + 2) * ny] = -np.eye(ny)
    return sp.csr_matrix(J), sp.csr_matrix(A)


@pytest.mark.parametrize("damping", [0.0, 1e-3])
@pytest.mark.parametrize("border", [0, 3])
def test_kkt_step_matches_dense_solve(damping: float, border: int) -> None:
    """Sparse LU (no border) and the band with the parameters' Schur complement (border 3)."""
    rng = np.random.default_rng(3)
    J, A = _shooting_pattern(rng, segments=12)
    r = rng.standard_normal(J.shape[0])
    g = rng.standard_normal(A.shape[0])
    d, lam = kkt_step(J, A, r, g, damping, border=border)
    Jd, Ad = J.toarray(), A.toarray()
    m, p = Jd.shape[1], Ad.shape[0]
    K = np.block([[Jd.T @ Jd + damping * np.eye(m), Ad.T], [Ad, np.zeros((p, p))]])
    ref = np.linalg.solve(K, np.concatenate([-Jd.T @ r, -g]))
    np.testing.assert_allclose(d, ref[:m], rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(lam, ref[m:], rtol=1e-9, atol=1e-11)


def test_kkt_step_is_the_constrained_least_squares_step() -> None:
    """Null-space method: ``d = d_p + Z y`` with ``A d_p = -g`` and ``y`` the least-squares
    solution of ``J Z y = -(r + J d_p)``."""
    rng = np.random.default_rng(4)
    J, A = _shooting_pattern(rng, nth=2, ny=3, segments=5, per=9)
    r = rng.standard_normal(J.shape[0])
    g = rng.standard_normal(A.shape[0])
    d, _lam = kkt_step(J, A, r, g)
    Jd, Ad = J.toarray(), A.toarray()
    dp = np.linalg.lstsq(Ad, -g, rcond=None)[0]
    Z = null_space(Ad)
    y = np.linalg.lstsq(Jd @ Z, -(r + Jd @ dp), rcond=None)[0]
    np.testing.assert_allclose(d, dp + Z @ y, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(Ad @ d, -g, atol=1e-11)


def test_kkt_step_holds_entries_and_works_without_constraints() -> None:
    rng = np.random.default_rng(5)
    J, A = _shooting_pattern(rng)
    r = rng.standard_normal(J.shape[0])
    g = rng.standard_normal(A.shape[0])
    free = np.ones(J.shape[1], dtype=bool)
    free[1] = False
    d, _ = kkt_step(J, A, r, g, free=free, border=3)
    assert d[1] == 0.0
    keep = np.flatnonzero(free)
    Jd, Ad = J.toarray()[:, keep], A.toarray()[:, keep]
    K = np.block([[Jd.T @ Jd, Ad.T], [Ad, np.zeros((Ad.shape[0],) * 2)]])
    ref = np.linalg.solve(K, np.concatenate([-Jd.T @ r, -g]))
    np.testing.assert_allclose(d[keep], ref[:keep.size], rtol=1e-9, atol=1e-11)
    d0, lam0 = kkt_step(J, sp.csr_matrix((0, J.shape[1])), r, np.zeros(0))
    np.testing.assert_allclose(d0, np.linalg.lstsq(J.toarray(), -r, rcond=None)[0], rtol=1e-9, atol=1e-11)
    assert lam0.size == 0


def test_kkt_step_names_a_singular_system() -> None:
    J = sp.csr_matrix(np.array([[1.0, 0.0], [2.0, 0.0]]))      # the second entry is not seen
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        kkt_step(J, sp.csr_matrix((0, 2)), np.ones(2), np.zeros(0))


def test_polish_lands_on_the_constrained_minimum() -> None:
    """``min 0.5 |a exp(b t) - y|^2`` subject to ``c - a b = 0`` (a shooting-like chain of one
    link) against the minimum of the same problem with ``c`` eliminated (scipy least_squares)."""
    from scipy.optimize import least_squares

    t = np.linspace(0.0, 1.0, 40)
    y = 2.0 * np.exp(-1.3 * t) + 0.01 * np.random.default_rng(6).standard_normal(t.size)

    def plain(w):
        a, b, c = w
        return a * np.exp(b * t) - y, np.array([c - a * b])

    def full(w):
        a, b, c = w
        e = np.exp(b * t)
        J = sp.csr_matrix(np.column_stack([e, a * t * e, np.zeros_like(t)]))
        return a * e - y, J, np.array([c - a * b]), sp.csr_matrix(np.array([[-b, -a, 1.0]]))

    out = polish(full, plain, np.array([1.8, -1.1, 0.0]), np.full(3, -np.inf), np.full(3, np.inf), gtol=1e-12)
    ref = least_squares(lambda v: v[0] * np.exp(v[1] * t) - y, [1.8, -1.1], xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    assert out.success, out.message
    np.testing.assert_allclose(out.w[:2], ref, rtol=1e-8)
    assert abs(out.w[2] - out.w[0] * out.w[1]) <= 1e-12


def test_constraints_that_cannot_be_met_stop_the_solve_and_say_so() -> None:
    """``min 0.5 |w - 1|^2`` subject to ``w_0^2 + 1 = 0`` (no real solution, like segments that
    cannot close near the data): as the weight rises the violation only falls from 2 towards 1
    while the constraint term outweighs the data, so the solve stops after three tenfold raises
    and says so, long before its budget; a feasible twin (``w_0^2 - 0.25 = 0``) converges to its
    closed-form minimum ``w_0 = 0.5`` (the other entries at 1)."""
    from prefriction.identify.constrained_lsq import solve

    n = 5

    def problem(c: float):
        def plain(w):
            return w - 1.0, np.array([w[0] ** 2 + c])

        def full(w):
            A = np.zeros((1, n))
            A[0, 0] = 2.0 * w[0]
            return w - 1.0, sp.identity(n, format="csr"), np.array([w[0] ** 2 + c]), sp.csr_matrix(A)
        return full, plain

    full, plain = problem(1.0)
    out = solve(full, plain, np.ones(n), np.zeros(0), np.zeros(0), max_iter=500, tol=1e-10, gtol=1e-9, weight=0.01)
    assert not out.success and "the segments do not close" in out.message and out.iterations < 200
    full, plain = problem(-0.25)
    out = solve(full, plain, np.ones(n), np.zeros(0), np.zeros(0), max_iter=500, tol=1e-12, gtol=1e-10, weight=0.01)
    assert out.success, out.message
    np.testing.assert_allclose(out.w, [0.5] + [1.0] * (n - 1), rtol=0, atol=1e-8)


@pytest.mark.slow
def test_motion_fit_of_25000_samples_from_a_factor_2_start() -> None:
    """The EMPS-like stage of the success harness (LuGre, 95.1 kg, PD at 1 kHz, 50 nm encoder,
    offset), 25,000 samples, every free parameter (mass and offset included) started within a
    factor 2 of the truth: converged, and every estimate within 5 % of the truth."""
    from prefriction import identify
    from prefriction.identify._success import STAGES, stage_record, start_model
    from prefriction.identify.parameters import _entries

    stage = STAGES[3]
    data = stage_record(stage, 25_000, np.random.default_rng([0, 3]))
    start, m0, off0 = start_model(stage, np.random.default_rng([0, 3, 200]), 2.0)
    fixed = [e.name for e in _entries(start) if e.name not in stage.free]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(start, data, fixed=fixed, offset=True, mass0=m0, offset0=off0)
    assert res.success, res.message
    for name, true in stage.truth().items():
        scale = stage.friction.Fc if name == "offset" else abs(true)
        assert abs(res.estimate(name) - true) <= 0.05 * scale, (name, res.estimate(name), true)
