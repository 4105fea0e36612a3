"""Branch functions of the Dahl model for general gamma, against mpmath at 50 digits."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from prefriction.analysis import branch as br

GAMMAS = [0.0, 0.3, 0.5, 1 - 1e-9, 1.0, 1 + 1e-9, 1.5, 2 - 1e-10, 2.0, 2.5, 5.0]


def mp_ratio(f: float, g: float) -> mp.mpf:
    """Q(f) = H(f)/f^2 = int_0^1 t (1 - f t)^-g dt at 50 digits."""
    with mp.workdps(50):
        fm, gm = mp.mpf(f), mp.mpf(g)
        return mp.quad(lambda t: t * (1 - fm * t) ** (-gm), [0, 1])


def mp_potential_of_log_gap(L: float, g: float) -> mp.mpf:
    with mp.workdps(50):
        Lm, c = mp.mpf(L), mp.mpf(g) - 1
        pts = [0, 1, Lm] if Lm > 1 else [0, Lm]
        return mp.quad(lambda x: -mp.expm1(-x) * mp.exp(c * x), pts)


def mp_distance(f1: float, f2: float, g: float) -> mp.mpf:
    with mp.workdps(50):
        a, d, gm = mp.mpf(f1), mp.mpf(f2) - mp.mpf(f1), mp.mpf(g)
        return d * mp.quad(lambda t: (1 - a - d * t) ** (-gm), [0, 1])


def rel(x: float, ref: mp.mpf) -> float:
    return float(abs((mp.mpf(x) - ref) / ref))


FORCES = np.concatenate(
    [-np.logspace(-300, 0, 13), np.logspace(-300, -1, 12), [0.5, 0.74, 0.76, 0.9, 0.99, 1 - 1e-6]]
)


@pytest.mark.parametrize("g", GAMMAS)
def test_potential_matches_mpmath_down_to_1e_minus_300(g: float) -> None:
    q = br.potential_ratio(FORCES, g)
    h = br.branch_potential(FORCES, g)
    for f, qq, hh in zip(FORCES, q, h):
        ref = mp_ratio(f, g)
        # conditioning of H near f = 1 is (gamma - 1) L: allow for it
        tol = 2e-15 * max(1.0, abs(g - 1) * float(-np.log1p(-f)))
        assert rel(qq, ref) <= tol, (f, g)
        if abs(f) > 1e-150:
            assert rel(hh, ref * mp.mpf(f) ** 2) <= tol + 1e-16, (f, g)


def test_potential_closed_forms_and_saturation() -> None:
    f = np.array([-1.0, -0.3, 0.2, 0.9])
    assert np.allclose(br.branch_potential(f, 1.0), -f - np.log1p(-f), rtol=1e-14, atol=0)
    assert np.allclose(br.branch_potential(f, 0.0), f * f / 2, rtol=1e-15, atol=0)
    assert br.branch_potential(np.array(1.0), 0.5) == pytest.approx(1 / (0.5 * 1.5), rel=1e-15)
    assert br.saturation_energy(0.5) == pytest.approx(4 / 3, rel=1e-15)
    assert np.isinf(br.branch_potential(np.array(1.0), 1.0))
    assert np.isinf(br.saturation_energy(2.0))


@pytest.mark.parametrize("g", [0.0, 0.5, 1.0, 2.0, 5.0])
def test_potential_of_log_gap_in_gross_sliding(g: float) -> None:
    L = np.array([1e-8, 0.5, 1.5, 30.0, 1e3, 1e6]) if g <= 1 else np.array([1e-8, 0.5, 1.5, 30.0])
    h = br.potential_of_log_gap(L, g)
    for LL, hh in zip(L, h):
        assert rel(hh, mp_potential_of_log_gap(LL, g)) <= 2e-15 * max(1.0, abs(g - 1) * LL)


@pytest.mark.parametrize("g", GAMMAS)
def test_branch_distance(g: float) -> None:
    f1 = np.array([-1.0, -0.5, -1e-12, 0.0, 0.3, 0.9, 0.999, -0.2])
    f2 = np.array([-0.9, -0.5 + 1e-14, 1e-12, 1e-300, 0.31, 0.99, 1 - 1e-12, 0.7])
    d = br.branch_distance(f1, f2, g)
    for a, b, x in zip(f1, f2, d):
        assert rel(x, mp_distance(a, b, g)) <= 3e-15 * max(1, g)


@pytest.mark.parametrize("g", [0.0, 0.5, 1.0, 1 + 1e-9, 2.0, 5.0])
def test_force_after_distance_closed_forms(g: float) -> None:
    f1 = np.array([-1.0, -0.5, -1e-12, 0.0, 0.3, 0.9])
    xi = np.array([1e-3, 1e-14, 2e-12, 1e-300, 0.3, 50.0])
    f2 = br.force_after_distance(f1, xi, g)
    L2, slide = br.log_gap_after_distance(f1, xi, g)
    with mp.workdps(400):  # xi = 1e-300 needs f2 - f1 resolved
        gm = mp.mpf(g)
        for a, x, ff, LL, s in zip(f1, xi, f2, L2, slide):
            w1 = 1 - mp.mpf(a)
            if g == 1:
                w2 = w1 * mp.exp(-mp.mpf(x))
            else:
                base = w1 ** (1 - gm) - (1 - gm) * mp.mpf(x)
                w2 = mp.mpf(0) if base <= 0 else base ** (1 / (1 - gm))
            assert rel(ff, 1 - w2) <= 2e-15
            if w2 > 0:
                assert float(abs(LL + mp.log(w2))) <= 2e-15 * max(1.0, float(abs(mp.log(w2))))
                assert s == 0.0
            else:
                assert rel(s, mp.mpf(x) - w1 ** (1 - gm) / (1 - gm)) <= 1e-14


@pytest.mark.parametrize("g", [0.0, 0.5, 1.0, 2.0])
def test_branch_started_in_saturation_stays_there(g: float) -> None:
    """From f1 = 1 the force stays 1 for any distance, also none: (3.2) has dF/dx = 0 there.

    ``gamma < 1`` reaches f = 1 at a finite distance and slides at Fc beyond it (the whole
    distance is slide); ``gamma >= 1`` never leaves f = 1 either, without a slide. A distance 0
    gave NaN (0 * inf) with a RuntimeWarning.
    """
    import warnings

    f1 = np.ones(3)
    xi = np.array([0.0, 1e-300, 0.3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f2 = br.force_after_distance(f1, xi, g)
        L2, slide = br.log_gap_after_distance(f1, xi, g)
    assert np.all(f2 == 1.0) and np.all(L2 == np.inf)
    assert np.array_equal(slide, xi if g < 1.0 else np.zeros(3))


@pytest.mark.parametrize("g", [0.0, 0.3, 0.5, 1.0, 1 + 1e-9, 2.0, 5.0])
def test_loading_end_inverts_potential(g: float) -> None:
    E = np.array([1e-40, 1e-20, 1e-8, 0.01, 0.3, 1.0, 10.0, 1e3, 1e6])
    end = br.loading_end_for_energy(E, g)
    f, slide = br.loading_force_for_energy(E, g)
    assert np.array_equal(f, end.f) and np.array_equal(slide, end.slide)
    for e, L, ff, xi, s in zip(E, end.L, end.f, end.xi, end.slide):
        if np.isinf(L):
            hs = 1 / ((1 - mp.mpf(g)) * (2 - mp.mpf(g)))
            assert g < 1 and ff == 1.0 and rel(s, e - hs) <= 1e-15
            assert rel(xi, 1 / (1 - mp.mpf(g)) + e - hs) <= 1e-15
        else:
            assert s == 0.0
            assert rel(e, mp_potential_of_log_gap(L, g)) <= 2e-15
            with mp.workdps(50):
                ref_xi = mp.quad(lambda x: mp.exp((mp.mpf(g) - 1) * x), [0, mp.mpf(L)])
            assert rel(xi, ref_xi) <= 2e-15 * max(1.0, abs(g - 1) * L)


def test_loading_end_gamma1_lambert_w() -> None:
    # docs/mathematics.md#reversal-map: L = c + 1 + W0(-exp(-(1 + c)))
    for c in [1e-6, 0.3, 5.0, 1e6]:
        with mp.workdps(60):
            ref = mp.mpf(c) + 1 + mp.lambertw(-mp.exp(-(1 + mp.mpf(c))))
        assert rel(float(br.loading_end_for_energy(np.array(c), 1.0).L), ref) <= 2e-15


@settings(max_examples=60, deadline=None)
@given(
    a=st.floats(min_value=1e-12, max_value=1.0),
    g=st.sampled_from([0.0, 0.5, 1.0, 2.0, 5.0]),
)
def test_reversal_map_contracts_and_inverts(a: float, g: float) -> None:
    E = br.branch_potential(np.array(-a), g)
    end = br.loading_end_for_energy(E, g)
    # the new amplitude stores the same energy on the loading side and is smaller (clockwise)
    assert 0 < end.f <= a * (1 + 4e-16)
    if g > 0 and a > 1e-6:  # below, a - f = O(gamma a^2) is under one ulp of a
        assert end.f < a
    assert br.branch_potential(end.f, g) == pytest.approx(E, rel=4e-15)
    # distance from the zero crossing agrees with the closed-form distance
    assert br.branch_distance(np.array(0.0), end.f, g) == pytest.approx(end.xi, rel=1e-14)


def test_gauss_legendre_nodes_integrate_polynomials() -> None:
    t, w = br.gauss_legendre_01(40)
    for k in (0, 7, 79):
        assert abs(float(np.sum(w * t**k)) - 1 / (k + 1)) <= 2e-16


def test_negative_gamma_and_energy_rejected() -> None:
    with pytest.raises(ValueError, match="gamma"):
        br.branch_potential(np.array(0.1), -0.5)
    with pytest.raises(ValueError, match="E must be finite and >= 0"):
        br.loading_end_for_energy(np.array([-1.0]), 1.0)
