"""Energy analysis on the trajectories of every model: LuGre's viscous and hysteretic
dissipation apart, Maxwell-slip, and GMS in its rate-independent configuration.

References, independent of the code under test:

- LuGre (Canudas de Wit et al. 1995): the oscillator ``m x'' = u - F`` written here in SI from
  the paper's equations and integrated by scipy ``Radau`` (rtol 1e-9; its error is below 1e-9 relative, 10x under the tolerances), restarted at every
  velocity reversal, with the energy integrals accumulated as extra ODE states:
  ``int sigma2 v^2``, ``int sigma1 z' v``, ``int sigma0 z (v - z')`` and ``int u v``;
- Maxwell-slip: the closed-form event sequence (``exact_reversals``) and the peak kinetic
  energy of each half-cycle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import energy

RTOL_REF = 1e-9  # Radau: the tolerances below are 10-100x its error
PAPER = (1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3)  # sigma0, sigma1, sigma2, Fc, Fs, vs (1995, Table I)


def radau_lugre(p, m, v0, F0, t_end, times, u=lambda t: 0.0):
    """LuGre oscillator, states ``[x, v, z, D_sigma2, D_sigma1, D_hysteretic, W_u]`` at ``times``
    and at the reversals (list of ``(t, state)``)."""
    s0, s1, s2, Fc, Fs, vs = p
    V, X = Fc / math.sqrt(m * s0), Fc / s0
    y = np.array([0.0, v0, F0 / s0, 0.0, 0.0, 0.0, 0.0])
    atol = 1e-12 * np.array([X, V, X, X * Fc, X * Fc, X * Fc, X * Fc])
    s = math.copysign(1.0, v0) if v0 else -math.copysign(1.0, F0 - u(0.0))
    t, revs, out = 0.0, [], np.full((7, len(times)), np.nan)
    while t < t_end:
        def rhs(tt, yy, s=s):
            v, z = yy[1], yy[2]
            g = Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))
            zd = v - s0 * s * v * z / g
            F = s0 * z + s1 * zd + s2 * v
            return [v, (u(tt) - F) / m, zd, s2 * v * v, s1 * zd * v, s0 * z * (v - zd), u(tt) * v]

        def reversal(tt, yy, s=s):
            return s * yy[1]

        reversal.terminal, reversal.direction = True, -1
        sol = solve_ivp(rhs, (t, t_end), y, method="Radau", rtol=RTOL_REF, atol=atol, events=[reversal], dense_output=True)
        sel = (times >= t) & (times <= sol.t[-1])
        if sel.any():
            out[:, sel] = sol.sol(times[sel])
        y = sol.y[:, -1].copy()
        if sol.status == 1:
            y[1] = 0.0
            revs.append((sol.t[-1], y.copy()))
            s = -s
        t = sol.t[-1]
    return out, revs


@pytest.fixture(scope="module")
def released():
    """A LuGre oscillator released from rest with the bristle force 0.9 Fc: simulate and reference."""
    system = pf.Oscillator(pf.LuGre(*PAPER), mass=1.0)
    T = 4 * 2 * math.pi * pf.Scales.of(system).t
    times = np.linspace(0.0, T, 1601)
    sim = pf.simulate(system, 0.0, F0=0.9, t_end=T, dense=times, rtol=1e-10)
    ref, revs = radau_lugre(PAPER, 1.0, 0.0, 0.9, T, times)
    return system, sim, ref, revs


def test_lugre_split_matches_radau_integrals(released):
    system, sim, ref, revs = released
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system, method="simpson")
    assert isinstance(rep, energy.LuGreEnergyReport)
    n = 6  # beyond, the reversal energies fall below 1e-20 of E_0 (overdamped bristles)
    assert len(rep) >= n and len(revs) >= n
    t_r = np.array([r[0] for r in revs[:n]])
    Y = np.array([r[1] for r in revs[:n]]).T
    E_0 = 0.5 * PAPER[0] * (0.9 / PAPER[0]) ** 2
    assert rep.E_0 == pytest.approx(E_0, rel=1e-12)
    np.testing.assert_allclose(rep.t[:n], t_r, rtol=1e-8)
    np.testing.assert_allclose(rep.E_p[:n], 0.5 * PAPER[0] * Y[2] ** 2, rtol=1e-6, atol=1e-9 * E_0)
    # per half-cycle: differences of the accumulated integrals between reversals
    D2, D1, Dh = (np.diff(Y[k]) for k in (3, 4, 5))
    tol = 1e-7 * E_0
    np.testing.assert_allclose(rep.D_sigma2[1:n], D2, atol=tol)
    np.testing.assert_allclose(rep.D_sigma1[1:n], D1, atol=tol)
    np.testing.assert_allclose(rep.D_hysteretic[1:n], Dh, atol=tol)
    assert rep.D_viscous[0] == pytest.approx(Y[3, 0] + Y[4, 0], rel=1e-6)
    assert rep.D_hysteretic[0] == pytest.approx(Y[5, 0], rel=1e-6)
    # the sum is the energy lost: E_0 - E_p(1) and E_p(i) - E_p(i+1)
    assert rep.D_viscous[0] + rep.D_hysteretic[0] == pytest.approx(E_0 - 0.5 * PAPER[0] * Y[2, 0] ** 2, rel=1e-6)
    assert rep.residual < 1e-6
    assert np.all(rep.D_hysteretic >= 0.0) and np.all(rep.D_sigma2 >= 0.0)
    assert rep.bound.holds and rep.interpolated == 0


def test_lugre_trapezoid_on_coarse_samples_reports_its_error(released):
    system, sim, _, _ = released
    coarse = slice(None, None, 10)  # 160 samples over 4 periods
    rep = energy.analyze_samples(sim.t[coarse], sim.x[coarse], sim.v[coarse], sim.F[coarse], system=system)
    fine = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system, method="simpson")
    err = abs(rep.total_hysteretic - fine.total_hysteretic) / fine.E_0
    assert 1e-7 < err < 1e-2 and rep.residual > fine.residual  # coarser, less accurate, and says so
    assert "LuGreEnergyReport(" in repr(rep) and len(repr(rep)) < 200
    assert "hysteretic" in rep.summary() and "viscous" in rep.format(max_rows=4)


def test_bristle_deflection_against_radau(released):
    system, sim, ref, _ = released
    z = energy.bristle_deflection(sim.t, sim.v, sim.F, friction=system.friction)
    np.testing.assert_allclose(z, ref[2], atol=1e-8 * 0.9 / PAPER[0])


def test_lugre_table_energy_and_initial_bristle_energy(released):
    system, sim, _, revs = released
    rep = energy.analyze_table(sim.reversals, system=system, F0=0.9)
    n = 6
    Y = np.array([r[1] for r in revs[:n]]).T
    np.testing.assert_allclose(rep.E_p[:n], 0.5 * PAPER[0] * Y[2] ** 2, rtol=1e-6, atol=1e-15)
    assert rep.E_0 == pytest.approx(0.5 * 0.9**2 / PAPER[0], rel=1e-12)
    assert rep.E_d[0] == pytest.approx(rep.E_0 - 0.5 * PAPER[0] * Y[2, 0] ** 2, rel=1e-6)
    with pytest.raises(ValueError, match=r"F0 must lie in \[-Fc, Fc\] = \[-1.0, 1.0\] N, got 2.0"):
        energy.analyze_table(sim.reversals, system=system, F0=2.0)


def test_lugre_without_damping_terms_is_all_hysteretic():
    lg = pf.LuGre(sigma0=1e5, sigma1=0.0, sigma2=0.0, Fc=1.0, Fs=1.5, vs=1e-3)
    system = pf.Oscillator(lg, mass=1.0)
    T = 2 * 2 * math.pi * pf.Scales.of(system).t
    times = np.linspace(0.0, T, 801)
    sim = pf.simulate(system, 0.0, F0=0.9, t_end=T, dense=times, rtol=1e-10)
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system, method="simpson")
    _, revs = radau_lugre((1e5, 0.0, 0.0, 1.0, 1.5, 1e-3), 1.0, 0.0, 0.9, T, times)
    assert np.all(rep.D_viscous == 0.0)
    Dh = np.diff([r[1][5] for r in revs])
    k = min(len(Dh), len(rep.D_hysteretic) - 1, 4)
    np.testing.assert_allclose(rep.D_hysteretic[1:k + 1], Dh[:k], rtol=1e-5)


def test_forced_lugre_counts_the_input_work():
    system = pf.Oscillator(pf.LuGre(*PAPER), mass=1.0, u=pf.signals.Sine(amplitude=0.5, frequency=20.0))
    T = 0.09
    times = np.linspace(0.0, T, 1801)
    sim = pf.simulate(system, 0.0, F0=-0.2, t_end=T, dense=times, rtol=1e-10)  # from rest, net force 0.2 N
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system, method="simpson")
    _, revs = radau_lugre(PAPER, 1.0, 0.0, -0.2, T, times, u=lambda t: 0.5 * math.sin(2 * math.pi * 20.0 * t))
    n = min(len(rep), len(revs), 5)
    assert n >= 3
    W = np.array([r[1][6] for r in revs[:n]])
    scale = float(np.max(np.abs(W)))
    np.testing.assert_allclose(rep.W_u[1:n], np.diff(W), atol=1e-6 * scale)
    assert rep.W_u[0] == pytest.approx(W[0], abs=1e-6 * scale)
    assert rep.residual < 1e-5
    tab = energy.analyze_table(sim.reversals, system=system, F0=-0.2, work_input=sim.work_input)
    np.testing.assert_allclose(tab.E_d[: n - 1], rep.E_d[: n - 1], atol=1e-6 * scale)
    with pytest.raises(ValueError, match="work_input is required for the table of a forced system"):
        energy.analyze_table(sim.reversals, system=system)


# ------------------------------------------------------------------ rate-independent models
MS = pf.MaxwellSlip([6e4, 3e4, 1e4], [0.2, 0.3, 0.5])


@pytest.fixture(scope="module")
def maxwell_run():
    system = pf.Oscillator(MS, mass=1.0)
    sc = pf.Scales.of(system)
    times = np.linspace(0.0, 4 * 2 * math.pi * sc.t, 4001)
    sim = pf.simulate(system, 2.0 * sc.v, t_end=times[-1], dense=times, rtol=1e-10)
    return system, sim, pf.exact_reversals(system, 2.0 * sc.v, 10)


def test_maxwell_slip_samples_against_the_closed_form(maxwell_run):
    system, sim, exact = maxwell_run
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system)
    n = len(rep)
    assert n >= 6
    np.testing.assert_allclose(rep.t, exact.t[:n], rtol=1e-8)
    np.testing.assert_allclose(rep.E_p, exact.E_p[:n], rtol=1e-6)
    assert rep.E_p_check_max_rel_dev < 1e-5  # peak kinetic energy of each half-cycle = E_p
    assert rep.bound.holds


def test_gms_in_its_rate_independent_configuration_is_analysed_as_maxwell_slip(maxwell_run):
    _, sim, exact = maxwell_run
    gms = pf.GMS(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.0, vs=1e-3, C=2e3)
    system = pf.Oscillator(gms, mass=1.0)
    rep = energy.analyze_samples(sim.t, sim.x, sim.v, sim.F, system=system)
    np.testing.assert_allclose(rep.E_p, exact.E_p[: len(rep)], rtol=1e-6)
    tab = energy.analyze_table(exact, system=pf.Oscillator(MS, mass=1.0))
    np.testing.assert_allclose(tab.E_p, exact.E_p)
    with pytest.raises(TypeError, match="this GMS is rate-dependent .*Fs = 1.5 N"):
        energy.analyze_samples(sim.t, sim.x, sim.v, sim.F,
                               system=pf.Oscillator(pf.GMS(k=[1e5], alpha=[1.0], Fc=1.0, Fs=1.5, vs=1e-3, C=2e3)))
