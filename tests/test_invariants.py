"""Property tests (hypothesis) of the paper's energy invariants over wide parameter ranges.

- (2.6): a memory-free (single-valued) restoring force dissipates nothing on a closed cycle;
- (2.7): a clockwise Dahl hysteresis loop encloses a positive area, for every gamma > 0;
- (2.12): the potential energy at any reversal of a Dahl model stays below Fc^2/(2 sigma);
- on the exact reference trajectory (prefriction.exact_reversals): E_p strictly decreasing
  (gamma > 0), (2.10) and (2.11) to rounding, (2.12) after the first reversal, gamma = 0
  conserving energy after saturation, E_p equal to (3.9) for gamma = 1 (mpmath), and the
  energy analysis of prefriction.analysis.energy agreeing with the table;
- samples from prefriction.simulate, analysed by prefriction.energy.analyze_samples, agree with
  the exact table and with the simulator's own integrated power (2.8) and input work.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq

from prefriction import Dahl, Oscillator, energy
from prefriction.analysis.exact import exact_reversals

EPS = np.finfo(float).eps
FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def log_uniform(lo: float, hi: float):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


# --------------------------------------------------------------------------- (2.6), (2.7)


@FAST
@given(
    steps=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=60),
    k=log_uniform(1e-2, 1e10),
    c=st.floats(0.0, 10.0),
    scale=log_uniform(1e-9, 1e3),
)
def test_memory_free_force_dissipates_nothing_on_closed_cycles(steps, k, c, scale):
    # a closed path reversing at random, force k x (1 + c (x/scale)^2): single-valued, so
    # oint F dx = 0 (2.6); the trapezoid rule is exact for the linear part and errs by at
    # most h^3/12 max|F''| per step for the cubic part.
    x = scale * np.concatenate(([0.0], np.cumsum(steps), [0.0]))
    F = k * x * (1.0 + c * (x / scale) ** 2)
    E = energy.loop_integral(x, F)
    rounding = 64 * EPS * float(np.sum(np.abs(F[1:] + F[:-1]) * np.abs(np.diff(x)))) + 1e-300
    d2F = 6.0 * c * k * float(np.max(np.abs(x))) / scale**2
    assert abs(E) <= rounding + d2F * float(np.sum(np.abs(np.diff(x)) ** 3)) / 12.0


def _gap_after(w0: float, xi: np.ndarray, gamma: float) -> np.ndarray:
    """w = 1 - s F/Fc after normalised distance xi on a Dahl branch (3.2), closed forms."""
    if gamma == 0.0:
        return np.maximum(w0 - xi, 0.0)
    if gamma == 0.5:
        return np.maximum(math.sqrt(w0) - xi / 2, 0.0) ** 2
    if gamma == 1.0:
        return w0 * np.exp(-xi)
    return w0 / (1.0 + w0 * xi)  # gamma = 2


@FAST
@given(
    gamma=st.sampled_from([0.0, 0.5, 1.0, 2.0]),
    A=log_uniform(1e-3, 30.0),  # half-amplitude in units Fc / sigma
    sigma=log_uniform(1e-2, 1e10),
    Fc=log_uniform(1e-3, 1e3),
)
def test_clockwise_dahl_loop_area(gamma, A, sigma, Fc):
    # symmetric closed cycle -A..A: the ascending branch from (-A, -a) must reach (A, a)
    def mismatch(a):
        return 1.0 - _gap_after(1.0 + a, np.array(2 * A), gamma) - a

    a = 1.0 if mismatch(1.0) >= 0.0 else brentq(mismatch, 0.0, 1.0, xtol=1e-15, rtol=4 * EPS)
    xi = 2 * A * np.linspace(0.0, 1.0, 4001) ** 2  # dense where the branch bends most
    saturation = {0.0: 1.0 + a, 0.5: 2.0 * math.sqrt(1.0 + a)}.get(gamma, math.inf)
    if saturation < 2 * A:  # put the kink of gamma < 1 on a sample
        xi = np.unique(np.append(xi, saturation))
    up = 1.0 - _gap_after(1.0 + a, xi, gamma)
    x = np.concatenate((xi - A, (A - xi)[1:])) * Fc / sigma
    F = np.concatenate((up, -up[1:])) * Fc
    E = energy.loop_integral(x, F, closure_tol=1e-9)
    # loop = 2 int_{-A}^{A} f_+ dx (2.5) by symmetry, here by adaptive quadrature
    kinks = [saturation] if saturation < 2 * A else None
    branch = quad(lambda q: 1.0 - float(_gap_after(1.0 + a, np.array(q), gamma)), 0.0, 2 * A, limit=200, points=kinks)[0]
    ref = 2 * branch * Fc**2 / sigma
    floor = 1e-12 * Fc**2 / sigma * A  # round-off of the trapezoid sum over a loop of size A
    if gamma == 0.0 and A <= 1.0:
        assert abs(E) <= floor  # elastic: the linear spring of (2.6)
    else:
        assert E > 0.0  # clockwise hysteresis (2.7)
        # gamma = 0 just past saturation (A = 1 + 1e-11) dissipates less than the floor itself
        assert E == pytest.approx(ref, rel=1e-6, abs=floor)


# --------------------------------------------------------------------------- (2.12) for any state


@FAST
@given(
    gamma=st.floats(0.0, 5.0),
    a=st.floats(0.0, 1.0),
    sigma=log_uniform(1e-2, 1e10),
    Fc=log_uniform(1e-3, 1e3),
)
def test_reversal_potential_never_exceeds_bound_2_12(gamma, a, sigma, Fc):
    d = Dahl(sigma, Fc, gamma)
    # a reversal ends a loading branch: the new branch starts on its unloading side
    E = energy.branch_energy(a * Fc, -1, friction=d)
    bc = energy.bound_check(E, friction=d)
    assert bc.holds and bc.holds_sharp
    assert bc.ratio <= 1.0 + 1e-15
    # strict (2.12) except at full saturation when 1/2 - H_gamma(-1) ~ gamma/3 is below rounding
    assert (bc.ratio < 1.0) or (a == 1.0 and gamma < 1e-14)
    # the sharp bound H_gamma(-1) = int_0^1 u (1 + u)^-gamma du, by quadrature
    H1 = quad(lambda u: u * (1 + u) ** -gamma, 0.0, 1.0, epsabs=0, epsrel=1e-13)[0]
    assert bc.bound_sharp == pytest.approx(H1 * Fc**2 / sigma, rel=1e-12)


# --------------------------------------------------------------------------- exact reference trajectory


@st.composite
def unforced_cases(draw, gammas=None):
    """A Dahl oscillator and initial state over the ranges of issue #2, in SI units."""
    gamma = draw(gammas if gammas is not None else st.one_of(st.just(1.0), st.just(0.0), st.floats(0.0, 5.0)))
    Fc = draw(log_uniform(1e-3, 1e3))
    sigma = Fc * draw(log_uniform(1e-2, 1e10))
    mass = draw(log_uniform(1e-6, 1e3))
    f0 = draw(st.one_of(st.just(0.0), st.floats(-0.999, 0.999)))
    c0 = draw(log_uniform(1e-20, 1e6))  # normalised initial kinetic energy sigma m v0^2 / (2 Fc^2)
    sign = draw(st.sampled_from([-1.0, 1.0]))
    v0 = sign * math.sqrt(2.0 * c0) * Fc / math.sqrt(mass * sigma)
    return Oscillator(Dahl(sigma, Fc, gamma), mass=mass), v0, f0 * Fc


N_REV = 8


def _table(case):
    system, v0, F0 = case
    return system, exact_reversals(system, v0, N_REV, F0=F0)


@FAST
@given(case=unforced_cases())
# start on the unloading side with a force far below Fc (|F0|/Fc < 1e-154: its square underflows)
@example(case=(Oscillator(Dahl(1.0, 1.0, 1.0)), -1.4142135623730951, 1e-200))
def test_exact_table_energy_invariants(case):
    system, table = _table(case)
    d = system.friction
    unit = d.Fc**2 / d.sigma
    E_p, E_d, E_0 = np.asarray(table.E_p), np.asarray(table.E_d), float(table.E_0)
    assert len(table) == N_REV and np.all(np.isfinite(E_p)) and np.all(E_p >= 0.0)
    for name in ("t", "x", "F", "E_d"):
        assert np.all(np.isfinite(getattr(table, name))), f"table.{name} = {getattr(table, name)}"
    a = np.abs(np.asarray(table.F)) / d.Fc
    assert np.all(a <= 1.0)
    # unforced: every reversal lies on the loading side, so the force alternates in sign
    assert np.all(np.sign(table.F[1:]) == -np.sign(table.F[:-1]))
    assert np.all(np.diff(table.t) > 0.0)
    # (2.10): E_p(i) = E_d(i) + E_p(i+1), to rounding; and E_d[0] = E_0 - E_p[0]
    np.testing.assert_array_less(np.abs(E_p[:-1] - E_d[1:] - E_p[1:]), 16 * EPS * E_p[:-1] + 1e-300)
    assert abs(E_0 - E_d[0] - E_p[0]) <= 16 * EPS * E_0
    assert np.all(E_d >= -16 * EPS * np.concatenate(([E_0], E_p[:-1])))
    # E_p strictly decreasing where the decrement (about 2 gamma a E_p) is above rounding
    drop = E_p[:-1] - E_p[1:]
    resolvable = d.gamma * a[:-1] > 1e-12
    assert np.all(drop[resolvable] > 0.0)
    assert np.all(drop >= -16 * EPS * E_p[:-1])
    # (2.11): the truncated series leaves exactly the last E_p, to rounding
    S, R = energy.series(E_p, E_d[1:])
    np.testing.assert_array_less(np.abs(R - E_p[-1]), 16 * N_REV * EPS * E_p + 1e-300)
    # (2.12) at every reversal, including the first one after a gross-sliding start
    assert np.all(E_p <= 0.5 * unit * (1 + 4 * EPS))
    H1 = quad(lambda u: u * (1 + u) ** -d.gamma, 0.0, 1.0, epsabs=0, epsrel=1e-13)[0]
    assert np.all(E_p <= H1 * unit * (1 + 1e-12))


@FAST
@given(case=unforced_cases())
def test_energy_analysis_of_exact_table(case):
    system, table = _table(case)
    rep = energy.analyze_table(table, system=system)
    d = system.friction
    # independent recomputation of E_p from the tabulated forces (branch potential)
    assert rep.E_p_check_max_rel_dev < 1e-12
    assert rep.residual_2_10 < 32 * EPS
    assert rep.bound.holds and rep.bound.holds_sharp
    assert rep.bound.initial_ratio == pytest.approx(table.E_0 / (0.5 * d.Fc**2 / d.sigma), rel=1e-15)
    if d.gamma > 0 and rep.bound.initial_ratio > 1.0:
        # gross sliding start: reported, the first reversal is still bounded
        assert rep.bound.max_E_p < rep.bound.E_0
    np.testing.assert_array_equal(rep.direction, -np.sign(table.F))
    assert len(rep.format().splitlines()) > N_REV


@FAST
@given(case=unforced_cases(gammas=st.just(1.0)))
def test_exact_E_p_is_3_9_for_gamma1(case):
    system, table = _table(case)
    d = system.friction
    with mp.workdps(40):
        ref = [
            float(d.Fc**2 / d.sigma * (mp.mpf(a) - mp.log1p(mp.mpf(a))))
            for a in np.abs(np.asarray(table.F)) / d.Fc
        ]
    np.testing.assert_allclose(table.E_p, ref, rtol=1e-12, atol=0)


@FAST
@given(case=unforced_cases(gammas=st.just(0.0)))
def test_prandtl_conserves_energy_after_saturation(case):
    system, table = _table(case)
    d = system.friction
    unit = d.Fc**2 / d.sigma
    E_0 = float(table.E_0)
    # elastic below saturation, so every reversal keeps min(E_0, Fc^2 / (2 sigma)): the
    # equality case of (2.12) once the first excursion saturates
    expected = min(E_0, 0.5 * unit)
    np.testing.assert_allclose(table.E_p, expected, rtol=1e-13, atol=0)
    np.testing.assert_allclose(table.E_d[1:], 0.0, atol=1e-13 * expected)
    if E_0 > 0.5 * unit * (1 + 1e-12):
        np.testing.assert_allclose(np.abs(table.F), d.Fc, rtol=1e-14)
        bc = energy.bound_check(table.E_p, friction=d, E_0=E_0)
        assert bc.ratio == pytest.approx(1.0, rel=1e-13) and bc.holds


# --------------------------------------------------------------------------- simulated samples


def test_sampled_analysis_of_simulation_agrees_with_exact_table():
    # prefriction.simulate (CasADi) samples, analysed model-free and with the Dahl potential,
    # against the exact reversal table: (2.8)-(2.12) on a trajectory nobody tabulated.
    from prefriction.simulation.simulate import simulate

    system = Oscillator(Dahl(1e4, 2.0, 1.0), mass=0.5)
    sim = simulate(system, 0.3, reversals=6, rtol=1e-10, dense=np.linspace(0.0, 0.2, 20001), jit=False)
    table = exact_reversals(system, 0.3, 6)
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system)
    n = len(rep)
    assert n >= 5
    np.testing.assert_allclose(rep.t, table.t[:n], rtol=1e-9)
    np.testing.assert_allclose(rep.E_p, table.E_p[:n], rtol=1e-9)
    np.testing.assert_allclose(rep.E_d, table.E_d[:n], rtol=1e-8)  # one convention: ending at reversal k
    assert rep.E_0 == pytest.approx(table.E_0, rel=1e-14)
    assert rep.E_p_check_max_rel_dev < 1e-8  # peak kinetic energy = E_p (note after (3.9))
    assert rep.E_p_decreasing and rep.bound.holds and rep.bound.holds_sharp
    # (2.8): the simulator's integrated power against ours
    E_f = energy.integrated_power(sim.t, sim.v, sim.F, method="simpson")
    np.testing.assert_allclose(E_f, sim.E_f, atol=1e-9 * float(np.max(np.abs(sim.E_f))))


def test_sampled_analysis_of_forced_simulation_counts_input_work():
    from prefriction.simulation.simulate import simulate

    U = 0.6
    system = Oscillator(Dahl(1e4, 2.0, 1.0), mass=0.5, u=lambda t: U + 0 * t)
    sim = simulate(system, 0.3, reversals=6, t_end=0.2, rtol=1e-10, dense=np.linspace(0.0, 0.2, 20001), jit=False)
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system, method="simpson")
    n = len(rep)
    assert n >= 4
    # the simulator's table: E_d[k] = E_p[k-1] + W_u[k] - E_p[k], with its own input work
    np.testing.assert_allclose(rep.E_p, sim.reversals.E_p[:n], rtol=1e-9)
    np.testing.assert_allclose(rep.E_d, sim.reversals.E_d[:n], rtol=1e-6)
    assert rep.E_p_check is None
