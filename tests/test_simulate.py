"""simulate(): reversal tables of the stiff and extreme cases against exact_reversals (unforced)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.cli.bench import Case, reversal_error, stability_cases
from prefriction.analysis.exact import exact_reversals

CASES = stability_cases()


@pytest.mark.parametrize("tol", [1e-6, 1e-10])
@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_reversal_table_matches_exact(case: Case, tol: float) -> None:
    """Times, positions and forces of the first 50 reversals within 10 tol of the exact map."""
    ref = exact_reversals(case.system, case.v0, 50, x0=0.0, F0=case.F0)
    res = pf.simulate(case.system, case.v0, F0=case.F0, reversals=50, rtol=tol)
    tab = res.reversals
    assert res.status == 1 and res.success and len(tab) == 50
    err = reversal_error(case, tab.t, tab.x, tab.F, ref)
    assert err <= 10 * tol, f"{case.name}: max relative error {err:.3e} > 10 * {tol:g}"
    # energies of the table follow from the same forces: (3.9)-type potential and (2.10)
    np.testing.assert_allclose(tab.E_p, ref.E_p, rtol=30 * tol, atol=0)
    assert tab.E_0 == pytest.approx(ref.E_0, rel=1e-12)


def test_gamma0_keeps_its_undamped_oscillation() -> None:
    """Prandtl stop: after the first saturation E_p stays Fc^2 / (2 sigma) over 1e4 reversals."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0, 0.0))
    res = pf.simulate(sys_, 1.0, reversals=10_000, rtol=1e-8)
    E_p = res.reversals.E_p
    assert len(E_p) == 10_000
    assert np.max(np.abs(E_p / (0.5 * 1.0 / 1e4) - 1.0)) <= 1e-8
    np.testing.assert_allclose(np.abs(res.reversals.F), 1.0, rtol=1e-8)


def test_ten_thousand_reversals_gamma1() -> None:
    """1e4 reversals in one run: no reversal missed or doubled, global error grows at most linearly."""
    case = CASES[0]
    tol = 1e-8
    ref = exact_reversals(case.system, case.v0, 10_000)
    tab = pf.simulate(case.system, case.v0, reversals=10_000, rtol=tol).reversals
    assert len(tab) == 10_000
    assert np.all(np.diff(tab.t) > 0)
    assert np.all(np.sign(tab.F[1:]) == -np.sign(tab.F[:-1]))  # alternating branches
    assert reversal_error(case, tab.t, tab.x, tab.F, ref, 50) <= 10 * tol
    assert reversal_error(case, tab.t, tab.x, tab.F, ref, 10_000) <= 10 * tol * 10_000 / 50


@pytest.mark.parametrize("a", [1e-6, 1e-12])
def test_tiny_amplitudes(a: float) -> None:
    """Oscillations of amplitude a Fc (energy ~ a^2 / 2): relative accuracy does not degrade."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 2.0), mass=0.5)
    sc = pf.Scales.of(sys_)
    v0 = a * sc.v  # kinetic energy a^2 / 2 in units Fc^2 / sigma
    tol = 1e-8
    ref = exact_reversals(sys_, v0, 50)
    tab = pf.simulate(sys_, v0, reversals=50, rtol=tol).reversals
    case = Case("tiny", 1e4, 2.0, 0.5, v0)
    assert reversal_error(case, tab.t, tab.x, tab.F, ref) <= 10 * tol
    assert np.max(np.abs(tab.F)) < 2 * a * sys_.friction.Fc


def test_start_at_rest_with_force_moves_against_it() -> None:
    """v0 = 0, F0 > 0: the motion starts in direction -sign(F0), as exact_reversals assumes."""
    sys_ = pf.Oscillator(pf.Dahl(1e3, 1.0, 2.0))
    ref = exact_reversals(sys_, 0.0, 20, F0=0.5)
    tab = pf.simulate(sys_, 0.0, F0=0.5, reversals=20, rtol=1e-9).reversals
    case = Case("rest", 1e3, 1.0, 1.0, 0.0, 0.5, 2.0)
    assert reversal_error(case, tab.t, tab.x, tab.F, ref, 20) <= 1e-8
    assert tab.x[0] < 0


def test_t_end_stops_between_reversals() -> None:
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0))
    ref = exact_reversals(sys_, 1.0, 30)
    t_end = 0.5 * (ref.t[9] + ref.t[10])
    res = pf.simulate(sys_, 1.0, t_end=t_end)
    assert res.status == 0 and res.success and "t_end" in res.message
    assert len(res.reversals) == 10
    res2 = pf.simulate(sys_, 1.0, t_end=t_end, reversals=5)
    assert res2.status == 1 and len(res2.reversals) == 5


def test_dense_samples_and_integrated_power() -> None:
    """E_k + E_f = E_k(0) by (2.3)/(2.8); dense output does not change the reversal table."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0), mass=2.0)
    v0 = 0.2
    ref = exact_reversals(sys_, v0, 12)
    # t_end half-way between the 10th and the 11th reversal (one at t_end exactly is found on
    # either side of it, within the error)
    t = np.linspace(0.0, 0.5 * (ref.t[9] + ref.t[10]), 400)
    res = pf.simulate(sys_, v0, t_end=float(t[-1]), dense=t, rtol=1e-9)
    np.testing.assert_array_equal(res.t, t)
    E0 = 0.5 * 2.0 * v0**2
    np.testing.assert_allclose(res.E_k + res.E_f, E0, rtol=1e-8, atol=0)
    np.testing.assert_allclose(res.E_k, 0.5 * 2.0 * res.v**2)
    case = Case("dense", 1e4, 1.0, 2.0, v0)
    tab = res.reversals
    assert len(tab) == 10
    assert reversal_error(case, tab.t, tab.x, tab.F, ref, 10) <= 1e-8
    # samples lie inside the envelope of the reversal positions of the pre-sliding cycles
    late = res.t > tab.t[1]
    assert np.all(res.x[late] <= np.max(tab.x[1:]) + 1e-12)
    assert np.all(res.x[late] >= np.min(tab.x[1:]) - 1e-12)
    auto = pf.simulate(sys_, v0, reversals=10, dense=True, rtol=1e-9)
    assert auto.t is not None and len(auto.t) > 100 and auto.t[-1] <= auto.reversals.t[-1]


def test_reversals_only_run_records_no_samples() -> None:
    res = pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0)), 1.0, reversals=3)
    assert res.t is None and res.x is None and res.E_f is None
    assert res.stats.calls >= 1 and res.stats.wall_time > 0
    assert math.isfinite(res.reversals.t[-1])


def test_sparse_dense_samples_with_many_reversals_between() -> None:
    """Many reversals between two samples (more than one call holds): none lost, energy balanced."""
    case = CASES[0]
    ref = exact_reversals(case.system, case.v0, 60)
    t = np.linspace(0.0, ref.t[55], 7)
    res = pf.simulate(case.system, case.v0, t_end=float(t[-1]), dense=t, rtol=1e-8)
    assert len(res.reversals) == 56
    assert reversal_error(case, res.reversals.t, res.reversals.x, res.reversals.F, ref) <= 1e-7
    np.testing.assert_allclose(res.E_k + res.E_f, 0.5 * case.mass * case.v0**2, rtol=1e-10, atol=0)


def test_result_reads_like_scipys_and_prints_compactly():
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0))
    res = pf.simulate(sys_, 1.0, t_end=0.01, dense=True)
    assert res.success and res.status == 0 and res.message == "reached t_end = 0.01 s"
    assert res.t[-1] == 0.01  # dense samples reach t_end
    ref = pf.exact_reversals(sys_, 0.005, 3)
    res = pf.simulate(sys_, 0.005, reversals=3)
    assert res.status == 1 and f"reached 3 reversals at t = {ref.t[-1]:.6g}"[:30] in res.message
    text = repr(res)
    assert text.startswith("SimulationResult(3 reversals, status 1") and len(text) < 200
    assert "reversals: 3" in res.summary() and "[" not in res.summary()  # no arrays printed
