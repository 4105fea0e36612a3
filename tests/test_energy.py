"""Energy analysis (prefriction.analysis.energy) against closed forms and independent references.

References used: analytic signals (harmonic motion, polynomials), the closed-form Dahl
branches (3.4)-(3.7) for gamma = 1, the Prandtl stop (gamma = 0) parallelogram, the exact
gamma = 1 reversal map solved here with mpmath, and an independent scipy solve_ivp
simulation of the normalised Dahl oscillator (DOP853, rtol 1e-12, restarts at v = 0).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from prefriction import Dahl, Oscillator, ReversalTable
from prefriction import energy

mp.mp.dps = 40

# --------------------------------------------------------------------------- references


def g_closed(y):
    """Stored energy y + exp(-y) - 1 along a gamma = 1 branch from its zero crossing, (3.7)."""
    return y + mp.exp(-y) - 1


def exact_amplitudes(c0: float, n: int) -> list[float]:
    """|F_i|/Fc at the first n reversals, gamma = 1, from rest at the zero crossing with
    normalised energy c0, by root finding on (3.7) in mpmath (40 digits)."""
    out = []
    c = mp.mpf(c0)
    for _ in range(n):
        y = mp.findroot(lambda yy: g_closed(yy) - c, (mp.mpf(0) + mp.sqrt(2 * c), c + 2), solver="anderson")
        a = 1 - mp.exp(-y)
        out.append(float(a))
        c = a - mp.log(1 + a)  # (3.9)
    return out


def E_p_closed(a, sigma=1.0, Fc=1.0):
    """(3.9): E_p = (Fc^2/sigma) (a - ln(1 + a)), a = |F_i|/Fc."""
    return Fc**2 / sigma * np.array([float(ai - mp.log(1 + mp.mpf(ai))) for ai in np.atleast_1d(a)])


def dahl_samples(v0, n_rev, *, gamma=1.0, sigma=1.0, Fc=1.0, m=1.0, F0=0.0, pts=400, u=0.0, grid=None):
    """Independent reference: the Dahl oscillator (3.2) in normalised units by scipy's DOP853
    with a restart at every v = 0. Returns SI samples (t, x, v, F) and the reversal states.

    Without ``grid`` each half-cycle is sampled on its own with the reversal as its first
    sample; with ``grid`` (normalised times) the samples ignore the reversals. The last
    half-cycle is cut at half its length."""
    Tt, X, V = math.sqrt(m / sigma), Fc / sigma, Fc / math.sqrt(m * sigma)
    y = np.array([0.0, v0 / V, F0 / Fc])
    s = float(np.sign(y[1]) or -np.sign(y[2]))
    t0, segs, rev = 0.0, [], []
    for k in range(n_rev + 1):
        def rhs(t, z, s=s):
            return [z[1], u / Fc - z[2], z[1] * max(1.0 - s * z[2], 0.0) ** gamma]

        def ev(t, z):
            return z[1]

        ev.terminal, ev.direction = True, -s
        sol = solve_ivp(rhs, (t0, t0 + 1e3), y, method="DOP853", rtol=1e-12, atol=1e-14, events=ev, dense_output=True)
        te = float(sol.t_events[0][0])
        if k == n_rev:
            te = t0 + 0.5 * (te - t0)
        segs.append((t0, te, sol.sol))
        if k < n_rev:
            y = sol.y_events[0][0].copy()
            y[1] = 0.0
            rev.append((te, *y))
            t0, s = te, -s
    if grid is None:
        parts = [(np.linspace(a, b, pts, endpoint=(i == len(segs) - 1)), f) for i, (a, b, f) in enumerate(segs)]
        t = np.concatenate([p[0] for p in parts])
        z = np.concatenate([f(tt) for tt, f in parts], axis=1)
        for i in range(1, len(segs)):  # the reversal samples: v exactly 0
            z[1, i * pts] = 0.0
    else:
        t = grid[grid <= segs[-1][1]]
        z = np.empty((3, t.size))
        for a, b, f in segs:
            sel = (t >= a) & (t < b) if b != segs[-1][1] else (t >= a)
            if np.any(sel):
                z[:, sel] = f(t[sel])
    rev = np.array(rev)
    return (t * Tt, z[0] * X, z[1] * V, z[2] * Fc), (rev[:, 0] * Tt, rev[:, 1] * X, rev[:, 3] * Fc)


# --------------------------------------------------------------------------- reversal detection


@pytest.mark.parametrize("with_x", [True, False])
def test_reversals_of_cosine_velocity(with_x):
    t = np.linspace(0.0, 10.0, 1001)
    kw = {"x": np.sin(t), "F": 3.0 * np.sin(t)} if with_x else {}
    r = energy.find_reversals(t, np.cos(t), **kw)
    k = np.arange(3)
    np.testing.assert_allclose(r.t, np.pi / 2 + k * np.pi, rtol=0, atol=2e-8)
    np.testing.assert_array_equal(r.direction, [-1, 1, -1])
    assert r.initial_direction == 1
    np.testing.assert_array_equal(r.index, np.floor((np.pi / 2 + k * np.pi) / 0.01).astype(int))
    if with_x:
        np.testing.assert_allclose(r.x, [1, -1, 1], atol=1e-12)
        np.testing.assert_allclose(r.F, [3, -3, 3], atol=1e-10)
    else:
        assert r.x is None and r.F is None


def test_reversals_on_irregular_samples_are_third_order():
    rng = np.random.default_rng(1)
    errs = []
    for n in (200, 400):
        t = np.sort(np.concatenate(([0.0, 9.0], rng.uniform(0, 9, n))))
        v = np.cos(t) * np.exp(0.3 * t)  # v'' != 0 at the roots: linear interpolation is 2nd order
        x = (np.exp(0.3 * t) * (0.3 * np.cos(t) + np.sin(t)) - 0.3) / 1.09  # int v dt
        r = energy.find_reversals(t, v, x=x)
        roots = np.pi / 2 + np.arange(len(r)) * np.pi
        errs.append(np.max(np.abs(r.t - roots)))
        x_roots = (np.exp(0.3 * roots) * (0.3 * np.cos(roots) + np.sin(roots)) - 0.3) / 1.09
        np.testing.assert_allclose(r.x, x_roots, atol=1e-6)
    assert len(r) == 3
    assert errs[1] < errs[0] / 4  # better than second order on halving the step (random grid)


def test_touching_zero_without_sign_change_is_not_a_reversal():
    t = np.linspace(0.0, 4 * np.pi, 401)  # samples hit t = k pi exactly
    v = np.sin(t) ** 2
    v[[100, 200, 300]] = 0.0
    assert len(energy.find_reversals(t, v)) == 0
    assert len(energy.find_reversals(t, -v)) == 0


def test_reversal_on_zero_samples_is_counted_once():
    t = np.arange(10.0)
    v = np.array([2.0, 1.0, 0.0, -1.0, -2.0, -1.0, 0.0, 0.0, 0.0, 3.0])
    x = np.array([0.0, 1.0, 1.5, 1.0, -1.0, -3.0, -3.5, -3.5, -3.5, -2.0])
    F = x * 2
    r = energy.find_reversals(t, v, x=x, F=F)
    np.testing.assert_array_equal(r.t, [2.0, 6.0])  # the first zero sample of each run
    np.testing.assert_array_equal(r.x, [1.5, -3.5])
    np.testing.assert_array_equal(r.F, [3.0, -7.0])
    np.testing.assert_array_equal(r.direction, [-1, 1])
    # zeros at the ends are not reversals
    assert len(energy.find_reversals([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 0.0])) == 0


def test_reversal_force_is_extrapolated_along_the_incoming_branch():
    # Dahl gamma = 1 branch (3.5) in x, with x(t) = 1 - (t - 1.05)^2 reversing at t = 1.05:
    # the force at the reversal is f(1) exactly; linear interpolation in t would miss it.
    t = np.linspace(0.0, 2.0, 21)
    x = 1.0 - (t - 1.05) ** 2
    v = -2.0 * (t - 1.05)
    branch = 1.0 - 1.5 * np.exp(-(x + 1.0))  # (3.5), Fc = sigma = 1, F_i = -0.5 at x_i = -1
    F = np.where(t <= 1.05, branch, np.nan)
    F[11:] = branch[10] - 0.1  # descending side: any values
    r = energy.find_reversals(t, v, x=x, F=F)
    assert r.t[0] == pytest.approx(1.05, abs=1e-12)
    assert r.x[0] == pytest.approx(1.0, abs=1e-12)
    assert r.F[0] == pytest.approx(1.0 - 1.5 * math.exp(-2.0), abs=2e-5)


# --------------------------------------------------------------------------- integrated power (2.8)


def test_integrated_power_against_antiderivative():
    t = np.linspace(0.0, 7.0, 701)
    v, F = np.cos(t), t**2  # int t^2 cos t dt = t^2 sin t + 2 t cos t - 2 sin t
    exact = t**2 * np.sin(t) + 2 * t * np.cos(t) - 2 * np.sin(t)
    trap = energy.integrated_power(t, v, F)
    simp = energy.integrated_power(t, v, F, method="simpson")
    assert trap[0] == 0.0 and simp[0] == 0.0
    assert np.max(np.abs(trap - exact)) < 2e-3
    assert np.max(np.abs(simp - exact)) < 1e-6
    # trapezoid is second order
    t2 = np.linspace(0.0, 7.0, 1401)
    e2 = t2**2 * np.sin(t2) + 2 * t2 * np.cos(t2) - 2 * np.sin(t2)
    err2 = np.max(np.abs(energy.integrated_power(t2, np.cos(t2), t2**2) - e2))
    assert err2 == pytest.approx(np.max(np.abs(trap - exact)) / 4, rel=0.05)


def test_work_integral_of_single_valued_force_is_path_independent():
    t = np.linspace(0.0, 11.0, 20001)
    x = 0.7 * np.sin(t) + 0.2 * np.sin(3.1 * t)  # reverses many times
    W = energy.work_integral(x, x**3)
    np.testing.assert_allclose(W, (x**4 - x[0] ** 4) / 4, atol=5e-8)


def test_energy_balance_2_3_for_linear_oscillator_with_reset():
    m, k, A = 2.0, 50.0, 0.3
    w = math.sqrt(k / m)
    t = np.linspace(0.0, 3.0, 30001)
    x = A * np.sin(w * t + 0.4)
    v = A * w * np.cos(w * t + 0.4)
    F = k * x
    Ek = energy.kinetic_energy(v, mass=m)
    Ef = energy.integrated_power(t, v, F, method="simpson", reset_at_reversals=True)
    rev = energy.find_reversals(t, v)
    assert len(rev) >= 4
    first = t <= rev.t[0]
    np.testing.assert_allclose((Ek + Ef)[first], Ek[0], atol=1e-9 * k * A**2)
    np.testing.assert_allclose((Ek + Ef)[~first], 0.0, atol=1e-6 * k * A**2)


def test_kinetic_energy():
    np.testing.assert_allclose(energy.kinetic_energy([0.0, 2.0, -3.0], mass=0.5), [0.0, 1.0, 2.25])


# --------------------------------------------------------------------------- loop areas (2.5)-(2.7)


def test_linear_spring_closed_cycle_dissipates_nothing_2_6():
    k, A = 1e4, 2e-3
    t = np.linspace(0.0, 2 * np.pi, 1001)
    x = A * np.sin(t)
    E = energy.loop_integral(x, k * x)
    assert abs(E) < 1e-14 * k * A**2
    # also on an irregular, several-reversal closed path
    rng = np.random.default_rng(3)
    xs = np.concatenate(([0.0], np.cumsum(rng.normal(size=500))))
    xs[-1] = 0.0
    assert abs(energy.loop_integral(xs, k * xs)) < 1e-9 * k * np.ptp(xs) ** 2


@pytest.mark.parametrize("sigma, Fc, A", [(1.0, 1.0, 0.5), (1e4, 2.0, 3e-4), (1e7, 0.1, 1e-8)])
def test_dahl_gamma1_symmetric_loop_area_from_closed_forms(sigma, Fc, A):
    # Closed symmetric cycle between -A and A: ascending branch (3.5) from (-A, -F_A),
    # closing requires F_A = Fc tanh(sigma A / Fc); descending branch is its point mirror.
    FA = Fc * math.tanh(sigma * A / Fc)
    xi = np.linspace(-A, A, 20001)
    up = Fc - (Fc + FA) * np.exp(-sigma / Fc * (xi + A))
    down = -(Fc - (Fc + FA) * np.exp(-sigma / Fc * (A - xi)))  # (3.4) with sgn = -1 from (A, FA)
    x = np.concatenate((xi, xi[::-1][1:]))
    F = np.concatenate((up, down[::-1][1:]))
    # (3.7): int_{-A}^{A} f_+ dx = 2 A Fc - (Fc + F_A)(Fc/sigma)(1 - exp(-2 sigma A / Fc)); loop = twice it
    area = 2 * (2 * A * Fc - (Fc + FA) * Fc / sigma * (-math.expm1(-2 * sigma * A / Fc)))
    assert area > 0
    assert energy.loop_integral(x, F) == pytest.approx(area, rel=1e-8)
    # (2.7): the same as int (f_hat - f_check) dx
    two_branch = float(np.trapezoid(up - down, xi))
    assert two_branch == pytest.approx(area, rel=1e-8)


def test_prandtl_parallelogram_loop_area():
    # gamma = 0 (Prandtl stop): elastic with slope sigma, saturated at +-Fc; cycle -A..A.
    sigma, Fc, A = 200.0, 3.0, 0.05
    xs = -A + 2 * Fc / sigma  # end of elastic part of the ascending branch
    x = np.array([-A, xs, A, A - 2 * Fc / sigma, -A])
    F = np.array([-Fc, Fc, Fc, -Fc, -Fc])
    assert energy.loop_integral(x, F) == pytest.approx(4 * Fc * (A - Fc / sigma), rel=1e-14)
    # densely sampled, with every corner on a sample
    xx = np.concatenate([np.linspace(x[i], x[i + 1], 50, endpoint=False) for i in range(4)] + [[x[-1]]])
    FF = np.interp(np.arange(xx.size), np.arange(0, xx.size, 50), F)
    assert energy.loop_integral(xx, FF) == pytest.approx(4 * Fc * (A - Fc / sigma), rel=1e-12)
    # counter-clockwise traversal gives the negative
    assert energy.loop_integral(x[::-1], F[::-1]) == pytest.approx(-4 * Fc * (A - Fc / sigma), rel=1e-14)


def test_loop_integral_rejects_open_path():
    with pytest.raises(ValueError, match=r"the cycle is not closed: \|x\[-1\] - x\[0\]\| = 0\.5 m"):
        energy.loop_integral([0.0, 1.0, 0.5], [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="closure_tol must be finite and >= 0, got -1"):
        energy.loop_integral([0.0, 1.0, 0.0], [0.0, 1.0, 0.0], closure_tol=-1)
    with pytest.raises(ValueError, match="at least 3 points, got 2"):
        energy.loop_integral([0.0, 0.0], [0.0, 0.0])


# --------------------------------------------------------------------------- branch potential, bound


@pytest.mark.parametrize("sigma, Fc", [(1.0, 1.0), (1e6, 0.3), (1e-2, 50.0)])
def test_branch_energy_is_3_9_for_gamma1(sigma, Fc):
    a = np.array([1e-6, 1e-3, 0.1, 0.5, 0.9, 1.0])
    E = energy.branch_energy(a * Fc, -1, friction=Dahl(sigma, Fc))  # reversal after positive motion
    np.testing.assert_allclose(E, E_p_closed(a, sigma, Fc), rtol=1e-12)
    E2 = energy.branch_energy(-a * Fc, +1, friction=Dahl(sigma, Fc))
    np.testing.assert_allclose(E2, E, rtol=1e-15)


@pytest.mark.parametrize(
    "gamma, closed",
    [
        (0.0, lambda f: f * f / 2),
        (2.0, lambda f: 1 / (1 - f) + mp.log(1 - f) - 1),
        (0.5, lambda f: (4 - (1 - f) ** 0.5 * (2 * f + 4)) / 3),
    ],
)
def test_branch_energy_other_gamma_closed_forms(gamma, closed):
    # H_gamma(f) = int_0^f phi (1 - phi)^-gamma dphi, integrated in closed form by hand.
    f = np.array([-1.0, -0.4, -1e-3, 0.3, 0.8])
    got = energy.branch_energy(f * 2.0, np.ones_like(f), friction=Dahl(4.0, 2.0, gamma))
    ref = [float(closed(mp.mpf(fi))) * 2.0**2 / 4.0 for fi in f]
    np.testing.assert_allclose(got, ref, rtol=1e-12)
    quad = [float(mp.quad(lambda p: p * (1 - p) ** -gamma, [0, fi])) for fi in f]
    np.testing.assert_allclose(got, np.array(quad), rtol=1e-12)


def test_bound_check_reports_margin_and_sharp_bound():
    d = Dahl(sigma=1e3, Fc=2.0)
    unit = 4.0 / 1e3
    full = energy.branch_energy(2.0, -1, friction=d)  # reversal at full saturation
    bc = energy.bound_check([full, 0.1 * unit], friction=d, E_0=3.0 * unit)
    assert bc.bound == pytest.approx(0.5 * unit, rel=1e-15)
    assert bc.bound_sharp == pytest.approx((1 - math.log(2)) * unit, rel=1e-14)
    assert bc.ratio == pytest.approx(2 * (1 - math.log(2)), rel=1e-13)
    assert bc.margin == pytest.approx((math.log(2) - 0.5) * unit, rel=1e-12)
    assert bc.ratio_sharp == pytest.approx(1.0, rel=1e-13)
    assert bc.holds and bc.strict and bc.holds_sharp and bc.index == 0
    assert bc.initial_ratio == pytest.approx(6.0)
    text = bc.format()
    assert "holds" in text and "gross sliding" in text
    over = energy.bound_check([0.51 * unit], friction=d)
    assert not over.holds and over.margin < 0 and "VIOLATED" in over.format()


def test_bound_check_prandtl_equality():
    d = Dahl(sigma=10.0, Fc=1.0, gamma=0.0)
    E = energy.branch_energy(1.0, -1, friction=d)
    bc = energy.bound_check([E], friction=d)
    assert bc.ratio == pytest.approx(1.0, rel=1e-15)
    assert bc.holds and bc.holds_sharp and not bc.strict
    assert "with equality" in bc.format()


def test_dissipation_and_series_2_10_2_11():
    k = np.arange(6.0)
    E_p = 1.0 / (k + 1) ** 2
    E_d = energy.dissipation(E_p)
    np.testing.assert_allclose(E_d, 1 / (k[:-1] + 1) ** 2 - 1 / (k[:-1] + 2) ** 2, rtol=1e-14)
    S, R = energy.series(E_p, E_d)
    np.testing.assert_allclose(S, 1 / (k + 1) ** 2 - 1 / 36, atol=1e-16)
    np.testing.assert_allclose(R, 1 / 36, rtol=1e-14)
    np.testing.assert_allclose(energy.dissipation(E_p, input_work=np.ones(5)), E_d + 1)
    with pytest.raises(ValueError, match=r"input_work has 4 values, expected len\(E_p\) - 1 = 5"):
        energy.dissipation(E_p, input_work=np.ones(4))
    with pytest.raises(ValueError, match=r"E_d must hold len\(E_p\) - 1 = 5 values, got 4"):
        energy.series(E_p, E_d[:-1])


# --------------------------------------------------------------------------- full analysis


@pytest.mark.parametrize("sigma, Fc, m", [(1.0, 1.0, 1.0), (2e5, 0.5, 3e-3)])
def test_analyze_samples_matches_exact_gamma1_map(sigma, Fc, m):
    c0 = 2.0  # normalised initial kinetic energy, start at the force zero crossing
    v0 = math.sqrt(2 * c0) * Fc / math.sqrt(m * sigma)
    (t, x, v, F), (tr, xr, Fr) = dahl_samples(v0, 6, sigma=sigma, Fc=Fc, m=m)
    sysm = Oscillator(Dahl(sigma, Fc), mass=m)
    rep = energy.analyze_samples(t, x, v, F, system=sysm)
    a = exact_amplitudes(c0, 6)
    assert len(rep) == 6
    np.testing.assert_allclose(np.abs(rep.F) / Fc, a, rtol=1e-9)
    np.testing.assert_allclose(rep.t, tr, rtol=1e-12)
    np.testing.assert_allclose(rep.E_p, E_p_closed(a, sigma, Fc), rtol=1e-8)
    assert rep.E_0 == pytest.approx(c0 * Fc**2 / sigma, rel=1e-14)
    assert rep.E_d[0] == pytest.approx(rep.E_0 - E_p_closed(a[0], sigma, Fc)[0], rel=1e-8)
    np.testing.assert_allclose(rep.E_d[1:], -np.diff(E_p_closed(a, sigma, Fc)), rtol=1e-7)
    assert rep.E_p_decreasing
    # model-free check: peak kinetic energy per half-cycle equals E_p (note after (3.9))
    assert rep.E_p_check.shape == (5,)
    assert rep.E_p_check_max_rel_dev < 1e-6
    assert rep.residual_2_10 < 1e-4  # (2.10) against int F dx by the trapezoid rule on the samples
    np.testing.assert_allclose(rep.series_remainder, rep.E_p[-1], rtol=1e-9)
    # the check can fail: a force that did not act (its work booked into E_d) breaks the balance
    wrong = energy.analyze_samples(t, x, v, F, system=sysm, u=np.full(t.size, 0.05 * Fc))
    assert wrong.residual_2_10 > 100 * rep.residual_2_10 and wrong.residual_2_10 > 1e-3
    assert rep.bound.holds and rep.bound.holds_sharp
    assert rep.bound.initial_ratio == pytest.approx(2 * c0)  # gross sliding start reported
    np.testing.assert_array_equal(rep.direction, [-1, 1, -1, 1, -1, 1])


def test_analyze_samples_interpolates_between_samples():
    grid = np.linspace(0.0, 40.0, 8001) + 0.00123  # never on a reversal
    (t, x, v, F), (tr, xr, Fr) = dahl_samples(1.5, 6, grid=grid)
    rep = energy.analyze_samples(t, x, v, F, system=Oscillator(Dahl(1.0, 1.0)))
    n = len(rep)
    assert n >= 5
    np.testing.assert_allclose(rep.t, tr[:n], atol=1e-8)
    np.testing.assert_allclose(rep.x, xr[:n], atol=1e-9)
    np.testing.assert_allclose(rep.F, Fr[:n], atol=1e-8)
    a = exact_amplitudes(1.5**2 / 2, n)
    np.testing.assert_allclose(rep.E_p, E_p_closed(a), rtol=1e-7)


def test_total_energy_is_constant_on_branches_and_drops_by_E_d():
    (t, x, v, F), (tr, xr, Fr) = dahl_samples(1.0, 4, gamma=1.0)
    sysm = Oscillator(Dahl(1.0, 1.0))
    E = energy.total_energy(t, v, F, system=sysm)
    rep = energy.analyze_samples(t, x, v, F, system=sysm)
    edges = np.concatenate(([0], np.searchsorted(t, rep.t), [t.size]))
    levels = [rep.E_0] + list(rep.E_p)
    for k in range(len(edges) - 1):
        seg = E[edges[k] : edges[k + 1]]
        np.testing.assert_allclose(seg, levels[k], rtol=1e-10)


def test_forced_dissipation_equals_energy_jump_at_reversals():
    # Constant input u: the Dahl model stores H and dissipates only at reversals, where the
    # stored energy changes from H(f) to H(-f), f = s F / Fc with s the direction before the
    # reversal: a drop of 2 (artanh f - f) for gamma = 1 (a gain if forcing reverses the
    # motion before the force zero crossing, f < 0).
    U = 0.3
    (t, x, v, F), (tr, xr, Fr) = dahl_samples(1.2, 5, u=U, pts=2000)
    sysm = Oscillator(Dahl(1.0, 1.0), u=lambda tt: U)
    rep = energy.analyze_samples(t, x, v, F, system=sysm, method="simpson")
    s_before = np.array([1.0, -1.0, 1.0, -1.0, 1.0])
    f = s_before * Fr
    assert np.any(f < 0)  # one reversal before the zero crossing
    jump = 2 * (np.arctanh(f) - f)
    np.testing.assert_allclose(rep.E_d[1:], jump[1:], rtol=1e-7)
    assert rep.E_p_check is None
    sysm_samples = Oscillator(Dahl(1.0, 1.0), u=(np.array([0.0, 100.0]), np.array([U, U])))
    rep2 = energy.analyze_samples(t, x, v, F, system=sysm_samples, method="simpson")
    np.testing.assert_allclose(rep2.E_d, rep.E_d, rtol=1e-12)


def test_analyze_table_and_format():
    sigma, Fc = 1e4, 2.0
    a = exact_amplitudes(0.9, 5)
    E_p = E_p_closed(a, sigma, Fc)
    E_0 = 0.9 * Fc**2 / sigma
    F = Fc * np.array(a) * np.array([1, -1, 1, -1, 1])
    x = np.cumsum(np.sign(F)) * 1e-4
    table = ReversalTable(
        t=np.arange(1.0, 6.0), x=x, F=F, E_p=E_p, E_d=np.concatenate(([E_0 - E_p[0]], -np.diff(E_p))), E_0=E_0
    )
    rep = energy.analyze_table(table, system=Oscillator(Dahl(sigma, Fc)))
    np.testing.assert_array_equal(rep.direction, [-1, 1, -1, 1, -1])
    assert rep.residual_2_10 < 1e-15
    assert rep.E_p_check_max_rel_dev < 1e-12
    assert rep.E_d[0] == table.E_d[0]
    text = rep.format()
    for word in ("E_p [J]", "E_d(i) [J]", "(2.10)", "(2.11)", "(2.12)", "reversal table"):
        assert word in text
    assert len(text.splitlines()) > 8
    short = rep.format(max_rows=2)
    assert "..." in short


# --------------------------------------------------------------------------- validation


def test_sample_validation_messages():
    t = np.linspace(0, 1, 5)
    with pytest.raises(ValueError, match="v has length 4 but t has length 5"):
        energy.find_reversals(t, np.ones(4))
    with pytest.raises(ValueError, match=r"t must be strictly increasing, got t\[2\] = 0.25 <= t\[1\] = 0.25"):
        energy.find_reversals([0.0, 0.25, 0.25, 1.0], np.ones(4))
    with pytest.raises(ValueError, match=r"F must be finite, got F\[1\] = nan"):
        energy.integrated_power(t, np.ones(5), [0.0, np.nan, 0, 0, 0])
    with pytest.raises(ValueError, match=r"v must be a 1-D array, got an array of shape \(5, 1\)"):
        energy.find_reversals(t, np.ones((5, 1)))
    with pytest.raises(ValueError, match="t must hold at least 2 samples, got 1"):
        energy.find_reversals([0.0], [1.0])
    with pytest.raises(TypeError, match="x must be a 1-D array of real numbers"):
        energy.work_integral("abc", [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"method must be one of \('trapezoid', 'simpson'\), got 'euler'"):
        energy.integrated_power(t, t, t, method="euler")
    with pytest.raises(TypeError):
        energy.integrated_power(t, t, t, methd="simpson")  # unknown keyword
    with pytest.raises(ValueError, match="mass must be finite and > 0, got -1.0"):
        energy.kinetic_energy([1.0], mass=-1.0)


def test_model_validation_messages():
    d = Dahl(1.0, 2.0)
    with pytest.raises(ValueError, match=r"F must be finite and in \[-Fc, Fc\] = \[-2.0, 2.0\] \(every entry\), got F\[1\] = 2.5"):
        energy.branch_energy([1.0, 2.5], 1, friction=d)
    with pytest.raises(ValueError, match="direction must be \\+1 or -1 \\(every entry\\), got 0.0"):
        energy.branch_energy([1.0], 0, friction=d)
    with pytest.raises(TypeError, match="friction must be a prefriction.FrictionModel such as Dahl"):
        energy.branch_energy([1.0], 1, friction="dahl")
    with pytest.raises(TypeError, match="system must be a prefriction.Oscillator"):
        energy.analyze_samples([0, 1], [0, 1], [1, -1], [0, 0], system=d)
    t = np.linspace(0, 1, 4)
    with pytest.raises(ValueError, match=r"F must lie in \[-Fc, Fc\] = \[-2.0, 2.0\] \(every sample\), got F\[2\] = -2.1"):
        energy.analyze_samples(t, t, [1.0, -1.0, 1.0, -1.0], [0.0, 1.0, -2.1, 0.0], system=Oscillator(d))
    with pytest.raises(ValueError, match="v changes sign nowhere in the 4 samples"):
        energy.analyze_samples(t, t, np.ones(4), np.zeros(4), system=Oscillator(d))
    with pytest.raises(ValueError, match="v is zero at every sample: nothing moves"):
        energy.total_energy(t, np.zeros(4), np.zeros(4), system=Oscillator(d))
    one = dict(x=np.zeros(2), F=np.array([1.0, -0.5]), E_p=np.array([0.1, 0.05]), E_d=np.array([0.1, 0.05]), E_0=0.2)
    with pytest.raises(ValueError, match=r"table.t must be finite, got a non-finite entry at index 1 \(reversal 2\)"):
        energy.analyze_table(ReversalTable(t=np.array([1.0, np.inf]), **one), system=Oscillator(d))
    with pytest.raises(ValueError, match=r"table.t must be strictly increasing, got t\[1\] = 1.0 <= t\[0\] = 1.0"):
        energy.analyze_table(ReversalTable(t=np.array([1.0, 1.0]), **one), system=Oscillator(d))
    with pytest.raises(TypeError, match="table must be a prefriction.ReversalTable"):
        energy.analyze_table({"t": [1.0]}, system=Oscillator(d))
