"""exact_reversals against an independent mpmath reference (tanh-sinh quadrature, findroot).

The reference works in normalised units with the log-gap L = -ln(1 - f) on the loading side
(so that gross sliding with 1 - f ~ e^-1e6 stays representable), the closed-form branch
potential H evaluated with 40 guard digits, mp.findroot for the reversal force and mp.quad
(tanh-sinh) for t = int dxi / sqrt(2 K).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import prefriction as pf
from prefriction import Scales

DPS = 30
GUARD = 40


def mp_H_of_f(f, g):
    """Branch potential H(f) = int_0^f p (1 - p)^-g dp, closed form (f < 1)."""
    w = 1 - f
    if g == 1:
        return -f - mp.log(w)
    if g == 2:
        return mp.log(w) + 1 / w - 1
    return (w ** (2 - g) - 1) / (2 - g) - (w ** (1 - g) - 1) / (1 - g)


def mp_H_of_L(L, g):
    """H on the loading side as a function of L = -ln(1 - f) (exact for huge L)."""
    if g == 1:
        return L - 1 + mp.exp(-L)
    if g == 2:
        return -L + mp.exp(L) - 1
    return (mp.exp(-(2 - g) * L) - 1) / (2 - g) - (mp.exp(-(1 - g) * L) - 1) / (1 - g)


def mp_dist_L(La, Lb, g):
    """Distance int e^{(g-1) L} dL from La to Lb."""
    if g == 1:
        return Lb - La
    return (mp.exp((g - 1) * Lb) - mp.exp((g - 1) * La)) / (g - 1)


def mp_half_cycle(f_s, K_s, g, L_guess):
    """Duration, distance and end force of a half-cycle from force f_s with kinetic energy K_s.

    Returns (t, distance, f_end, L_end) as mpf; L_guess seeds findroot (the root is checked).
    """
    g = mp.mpf(g)
    f_s = mp.mpf(f_s)
    K_s = mp.mpf(K_s)
    with mp.workdps(DPS + GUARD):
        E = K_s + mp_H_of_f(f_s, g)
        t = mp.mpf(0)
        d = mp.mpf(0)
        if f_s < 0:
            # variable: distance delta = f - f_s from the start (exact near the singular end)
            def unload(delta):
                with mp.workdps(DPS + GUARD):
                    f = f_s + delta
                    return 1 / ((1 - f) ** g * mp.sqrt(2 * (E - mp_H_of_f(f, g))))

            with mp.workdps(DPS):
                t += mp.quad(unload, [0, -f_s / 2, -f_s])
            d += mp_dist_L(-mp.log(1 - f_s), 0, g)
            L_a = mp.mpf(0)
        else:
            L_a = -mp.log(1 - f_s)
        H_sat = 1 / ((1 - g) * (2 - g)) if g < 1 else mp.inf
        if E >= H_sat:  # saturation, then Coulomb slide at f = 1
            S = E - H_sat
            L_e = mp.inf
            f_e = mp.mpf(1)
            slide = S
        else:
            hi = mp.mpf(L_guess) if L_guess > 0 else mp.mpf(1)
            while mp_H_of_L(hi, g) < E:  # bracket the root independently of the guess
                hi *= 2
            lo = hi / 2
            while mp_H_of_L(lo, g) > E:
                lo, hi = lo / 2, lo
            L_e = mp.findroot(lambda L: mp_H_of_L(L, g) - E, (lo, hi), solver="anderson")
            assert abs(mp_H_of_L(L_e, g) - E) <= mp.mpf(10) ** (-DPS - 5) * (1 + E)
            f_e = -mp.expm1(-L_e)
            slide = mp.mpf(0)

        if L_e == mp.inf:

            # variable: the distance z before saturation, w = ((1 - g) z)^(1/(1 - g)) (smooth in z)
            def load(z):
                with mp.workdps(DPS + GUARD):
                    w = ((1 - g) * z) ** (1 / (1 - g))
                    return 1 / mp.sqrt(2 * (E - mp_H_of_f(1 - w, g)))

            z_a = mp.exp(-(1 - g) * L_a) / (1 - g)
            with mp.workdps(DPS):
                t += mp.quad(load, [0, z_a / 2, z_a])
        else:
            # variable: delta = L_e - L, exact near the singular end
            def load(delta):
                with mp.workdps(DPS + GUARD):
                    L = L_e - delta
                    return mp.exp((g - 1) * L) / mp.sqrt(2 * (E - mp_H_of_L(L, g)))

            span = L_e - L_a
            pts = [0, span]
            if span > 4:
                pts = sorted({mp.mpf(0), *(span * x for x in (1e-6, 1e-3, 0.5)), span - 2, span - 1, span})
            with mp.workdps(DPS):
                t += mp.quad(load, pts)
        t += mp.sqrt(2 * slide)
        d += (mp_dist_L(L_a, L_e, g) if L_e != mp.inf else mp.exp(-(1 - g) * L_a) / (1 - g)) + slide
        return t, d, f_e, L_e


def check_table(system, v0, F0, x0, n_check, table, tol=1e-13, late=()):
    """Compare reversals 1..n_check (and the half-cycles listed in late) with the reference."""
    sc = Scales.of(system)
    g = system.friction.gamma
    Fc = system.friction.Fc
    s = math.copysign(1.0, v0) if v0 != 0 else -math.copysign(1.0, F0)
    f = s * F0 / Fc
    K = 0.5 * (v0 / sc.v) ** 2
    t_ref = mp.mpf(0)
    x_ref = mp.mpf(x0) / sc.x
    for k in range(n_check):
        L_guess = -math.log1p(-min(abs(table.F[k]) / Fc, 1 - 1e-16)) if abs(table.F[k]) < Fc else 1.0
        if abs(table.F[k]) / Fc > 1 - 1e-12:
            L_guess = 1e6 + 1 if K > 1e5 else L_guess
        dt, dx, f_e, _ = mp_half_cycle(f, K, g, L_guess)
        t_ref += dt
        x_ref += s * dx
        assert abs(table.t[k] / sc.t / t_ref - 1) <= tol, (k, "t", float(table.t[k] / sc.t), float(t_ref))
        xs = max(abs(float(x_ref)), 1.0)
        assert abs(table.x[k] / sc.x - x_ref) <= tol * xs, (k, "x")
        assert abs(table.F[k] / Fc - s * f_e) <= tol * max(float(f_e), 1e-300), (k, "F")
        f, K, s = -f_e, mp.mpf(0), -s
    for k in late:  # half-cycle k from reversal k (index k - 1) to reversal k + 1
        a = abs(table.F[k - 1]) / Fc
        dt, dx, f_e, _ = mp_half_cycle(-a, 0, g, -math.log1p(-abs(table.F[k]) / Fc))
        assert abs((table.t[k] - table.t[k - 1]) / sc.t / dt - 1) <= tol, (k, "late t")
        assert abs(abs(table.x[k] - table.x[k - 1]) / sc.x / dx - 1) <= 10 * tol, (k, "late x")
        assert abs(abs(table.F[k]) / Fc / f_e - 1) <= tol, (k, "late F")


GAMMAS = [0.0, 0.5, 1.0, 2.0, 5.0]


@pytest.mark.parametrize("g", GAMMAS)
def test_moderate_excursion(g):
    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=g), mass=1.0)
    table = pf.exact_reversals(system, 0.01, 200, x0=1e-3)
    check_table(system, 0.01, 0.0, 1e-3, 3, table, late=(150,) if g > 0 else ())


@pytest.mark.parametrize("g", GAMMAS)
@pytest.mark.parametrize("F0", [0.999999, -0.999999])
def test_from_rest_near_saturation(g, F0):
    system = pf.Oscillator(pf.Dahl(sigma=1e10, Fc=2.0, gamma=g), mass=1e-6)
    table = pf.exact_reversals(system, 0.0, 3, F0=F0 * 2.0)
    check_table(system, 0.0, F0 * 2.0, 0.0, 3, table)


@pytest.mark.parametrize("g", [0.5, 1.0, 2.0, 5.0])
def test_moving_with_force_in_either_direction(g):
    system = pf.Oscillator(pf.Dahl(sigma=1e-2, Fc=3.0, gamma=g), mass=1e3)
    sc = Scales.of(system)
    for v0, F0 in [(0.7 * sc.v, 0.999999 * 3.0), (-1.3 * sc.v, 0.4 * 3.0), (2e-9 * sc.v, -0.5 * 3.0)]:
        table = pf.exact_reversals(system, v0, 2, F0=F0, x0=-5.0)
        check_table(system, v0, F0, -5.0, 2, table)


@pytest.mark.parametrize("g", GAMMAS)
@pytest.mark.parametrize("c", [1e-20, 1e6])
def test_extreme_first_excursions(g, c):
    # c = sigma m v0^2 / (2 Fc^2): gross sliding (1e6) and tiny oscillation (1e-20)
    sigma, Fc, m = 1e6, 0.5, 2.0
    system = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc, gamma=g), mass=m)
    v0 = math.sqrt(2 * c * Fc**2 / (sigma * m))
    table = pf.exact_reversals(system, v0, 2)
    check_table(system, v0, 0.0, 0.0, 2, table)
    assert table.E_0 == pytest.approx(c * Fc**2 / sigma, rel=1e-15)


@pytest.mark.parametrize("g", [0.0, 0.5])
def test_start_in_coulomb_sliding_below_gamma_one(g):
    # F0 = Fc along v0: saturated; the first half-cycle is a slide at deceleration Fc/m
    system = pf.Oscillator(pf.Dahl(sigma=50.0, Fc=2.0, gamma=g), mass=3.0)
    table = pf.exact_reversals(system, 0.4, 2, F0=2.0)
    assert table.t[0] == pytest.approx(0.4 * 3.0 / 2.0, rel=1e-15)
    assert table.x[0] == pytest.approx(0.5 * 3.0 * 0.4**2 / 2.0, rel=1e-15)
    assert table.F[0] == 2.0


def test_prandtl_stop_conserves_energy_after_saturation():
    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=0.0), mass=1.0)
    table = pf.exact_reversals(system, 0.05, 1000)
    sc = Scales.of(system)
    assert np.all(np.abs(table.F) == 1.0)
    assert np.all(table.E_p == 0.5 * sc.E)
    assert np.all(table.E_d[1:] == 0.0)
    k = np.arange(1000)
    assert np.allclose(table.t, table.t[0] + k * math.pi * sc.t, rtol=1e-14, atol=0)
    # first excursion: E_0 = c = 12.5 (units Fc^2/sigma): slide over c - 1/2 after saturation
    assert table.E_d[0] == pytest.approx((12.5 - 0.5) * sc.E, rel=1e-14)


def test_gamma1_amplitudes_follow_the_map_and_energy_bookkeeping():
    system = pf.Oscillator(pf.Dahl(sigma=3e5, Fc=0.2, gamma=1.0), mass=0.05)
    table = pf.exact_reversals(system, 0.0, 50, F0=-0.2)
    a = pf.dahl.amplitude_sequence(1.0, 50)[1:]
    assert np.allclose(np.abs(table.F) / 0.2, a, rtol=1e-15, atol=0)
    assert np.allclose(table.E_p, pf.dahl.potential_energy(table.F, 3e5, 0.2), rtol=1e-14, atol=0)
    # (2.11): E_0 = sum of dissipations + remaining potential energy
    assert table.E_0 == pytest.approx(table.E_d.sum() + table.E_p[-1], rel=1e-14)
    assert table.E_0 == pytest.approx(pf.dahl.max_potential_energy(3e5, 0.2), rel=1e-15)
    assert np.all(np.diff(table.E_p) < 0) and np.all(np.diff(table.t) > 0)
    assert np.all(np.sign(table.F[:-1]) == -np.sign(table.F[1:]))


@pytest.mark.parametrize("g", [0.5, 1.0, 5.0])
def test_ten_thousand_reversals_tend_to_the_linear_period(g):
    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=g), mass=1.0)
    table = pf.exact_reversals(system, 0.01, 10_000)  # timed in `prefriction bench`, not here
    # late half-cycles tend to the linear period pi sqrt(m / sigma)
    assert (table.t[-1] - table.t[-2]) == pytest.approx(math.pi * 1e-2, rel=1e-5)


@pytest.mark.parametrize(
    ("kwargs", "exc", "match"),
    [
        (dict(v0=0.0, F0=0.0), ValueError, r"v0 = 0 and F0 = 0.*nothing moves"),
        (dict(v0=0.1, F0=1.5), ValueError, r"F0 must lie in \[-Fc, Fc\] = \[-1.0, 1.0\] N, got 1.5"),
        (dict(v0=0.1, n=0), ValueError, r"n must be an integer >= 1, got 0"),
        (dict(v0=float("nan")), ValueError, r"v0 must be finite, got nan"),
        (dict(v0=0.1, x0=float("inf")), ValueError, r"x0 must be finite, got inf"),
        (dict(v0=0.1, F0=float("-inf")), ValueError, r"F0 must be finite, got -inf"),
        (dict(v0="fast"), TypeError, r"v0 must be a real number"),
        (dict(v0=0.1, n=2.0), TypeError, r"n must be an integer"),
        (dict(v0=-0.1, F0=-1.0), ValueError, r"F0 = -1.0 N equals Fc in the direction of v0.*infinite"),
        (dict(v0=0.0, F0=1e-320), ValueError, r"initial energy below the double-precision range"),
    ],
)
def test_argument_errors(kwargs, exc, match):
    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0), mass=1.0)
    args = dict(v0=0.1, n=3)
    args.update(kwargs)
    n = args.pop("n")
    v0 = args.pop("v0")
    with pytest.raises(exc, match=match):
        pf.exact_reversals(system, v0, n, **args)


def test_system_errors():
    forced = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0), mass=1.0, u=lambda t: 0.0)
    with pytest.raises(ValueError, match="unforced system"):
        pf.exact_reversals(forced, 0.1, 3)
    with pytest.raises(TypeError, match="system must be a prefriction.Oscillator"):
        pf.exact_reversals(pf.Dahl(sigma=1e4, Fc=1.0), 0.1, 3)
    with pytest.raises(TypeError, match="unexpected keyword"):
        pf.exact_reversals(pf.Oscillator(pf.Dahl(1e4, 1.0)), 0.1, 3, F_0=0.1)


def test_table_command_prints_the_default_case(capsys):
    from prefriction.cli.table import main

    assert main([]) == 0
    out = capsys.readouterr().out
    # default: sigma = 1e4, Fc = 1, m = 1, v0 = 0.01 -> first excursion stores c = 0.5 Fc^2/sigma;
    # first reversal force 1 - exp(-y), y = c + 1 + W0(-exp(-(1 + c))) (docs/mathematics.md#first-excursion)
    with mp.workdps(30):
        y = mp.mpf("1.5") + mp.lambertw(-mp.exp(-mp.mpf("1.5")))
        F1 = float(-mp.expm1(-y))
    assert f"{F1:.7f}" in out
    assert "t [s]" in out and "E_p [J]" in out
    assert "Bound (2.12)" in out and "holds" in out
    assert "0.5 Fc^2/sigma" in out
    rows = [line for line in out.splitlines() if line.strip()[:2].strip().isdigit()]
    assert len(rows) == 20


def test_table_command_options_and_bad_input(capsys):
    from prefriction.cli.table import main

    assert main(["--gamma", "0", "--v0", "0.05", "--n", "4", "--sigma", "1e6", "--Fc", "2"]) == 0
    out = capsys.readouterr().out
    assert "gamma = 0" in out and out.count(" -2 ") + out.count(" 2 ") >= 4
    assert main(["--sigma", "-1"]) == 2
    assert "sigma must be finite and > 0, got -1.0" in capsys.readouterr().out
    assert main(["--v0", "0", "--F0", "0"]) == 2
    assert "nothing moves" in capsys.readouterr().out


@settings(max_examples=25, deadline=None)
@given(
    g=st.sampled_from([0.0, 0.3, 1.0, 2.0, 5.0]),
    log_c=st.floats(min_value=-20, max_value=6),
    f0=st.floats(min_value=-1.0, max_value=1.0),
    log_sigma=st.floats(min_value=-2, max_value=10),
    log_m=st.floats(min_value=-6, max_value=3),
    Fc=st.floats(min_value=1e-3, max_value=1e3),
)
def test_normalised_table_is_independent_of_sigma_fc_and_mass(g, log_c, f0, log_sigma, log_m, Fc):
    """(2.1) with (3.2) in the units x Fc/sigma, t sqrt(m/sigma) is parameter-free (docs/mathematics.md#normalised-units)."""
    assume(not (g >= 1.0 and f0 == 1.0))  # infinite branch energy: rejected, tested above
    unit = pf.Oscillator(pf.Dahl(sigma=1.0, Fc=1.0, gamma=g), mass=1.0)
    other = pf.Oscillator(pf.Dahl(sigma=10.0**log_sigma, Fc=Fc, gamma=g), mass=10.0**log_m)
    sc = Scales.of(other)
    v = math.sqrt(2.0 * 10.0**log_c)
    a = pf.exact_reversals(unit, v, 6, F0=f0)
    b = pf.exact_reversals(other, v * sc.v, 6, F0=f0 * Fc)
    assert np.allclose(b.t / sc.t, a.t, rtol=1e-14, atol=0)
    assert np.allclose(b.x / sc.x, a.x, rtol=1e-14, atol=1e-14 * np.max(np.abs(a.x)))
    assert np.allclose(b.F / Fc, a.F, rtol=1e-14, atol=0)
    assert np.allclose(b.E_p / sc.E, a.E_p, rtol=1e-14, atol=0)
    # reversal invariants: alternating forces within [-Fc, Fc], increasing times, E_p not increasing
    assert np.all(np.abs(a.F) <= 1.0) and np.all(np.diff(a.t) > 0)
    assert np.all(a.F[:-1] * a.F[1:] < 0)
    assert np.all(np.diff(a.E_p) <= 0) and np.all(a.E_d >= 0)
