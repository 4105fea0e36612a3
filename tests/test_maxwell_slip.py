"""Maxwell-slip friction (N elasto-plastic elements in parallel) through the protocol.

References, independent of the simulator:

- the event-by-event closed form ``prefriction.analysis.maxwell_slip_exact.maxwell_slip_trajectory``
  (harmonic or uniformly decelerated motion between slips and reversals, event times by
  ``atan2``);
- the Masing map (``masing_next``), derived from the virgin curve alone: it shares no code and
  no reasoning with the event-by-event form, so the two check each other;
- closed forms of special cases: one element (the elastic-perfectly-plastic element of
  ``tests/test_protocol.py``), huge slip forces (a linear spring ``sigma``: python-control's
  linear loop, harmonic reversal times).

All models here have three elements (one compiled plant per kind of run) except where a
special case needs another number.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.analysis.maxwell_slip_exact import (
    dissipation_limit,
    first_reversal,
    masing_amplitudes,
    masing_next,
    maxwell_slip_reversals,
    maxwell_slip_trajectory,
)
from prefriction.testing import check_model

# kappa_1 = 0.6 > 1/2 (smallest slip deflection 5 um): dissipation stops after 3 half-cycles
FINITE = dict(stiffness=[6e4, 3e4, 1e4], slip_force=[0.3, 0.4, 0.3])
# kappa_1 = 0.3 < 1/2: the weakest element slips in every half-cycle, amplitudes -> 1 N
ENDLESS = dict(stiffness=[3e4, 2e4, 5e4], slip_force=[0.3, 0.5, 1.0])
# two elements with equal slip deflections (their slips coincide: ties), kappa_1 = 0.6
TIES = dict(stiffness=[1e4, 2e4, 2e4], slip_force=[0.1, 0.2, 0.65])


def system(params, mass=0.1):
    return pf.Oscillator(pf.MaxwellSlip(**params), mass=mass)


def rel_err(res, ref):
    """Largest relative error of reversal times, positions and forces (x and F relative to
    their largest magnitude in the run)."""
    return max(
        float(np.max(np.abs(res.t / ref.t - 1.0))),
        float(np.max(np.abs(res.x - ref.x)) / np.max(np.abs(ref.x))),
        float(np.max(np.abs(res.F - ref.F)) / np.max(np.abs(ref.F))),
    )


def slips_seen(model, sys_, v0, n, rtol, **kw):
    """Simulate and return the result and the element slips the simulator counted in each
    half-cycle (``result.events``, one count per reversal; ``model`` is the system's friction)."""
    res = pf.simulate(sys_, v0, reversals=n, rtol=rtol, **kw)
    return res, np.asarray(res.events)


# ------------------------------------------------------------------------------ the model
@pytest.mark.parametrize(
    ("stiffness", "slip_force", "err", "words"),
    [
        ([1.0, -2.0], [1.0, 1.0], ValueError, ["stiffness[1]", "-2.0", "0 < stiffness[i] < inf", "N/m"]),
        ([1.0, 2.0], [1.0, math.nan], ValueError, ["slip_force[1]", "nan", "0 < slip_force[i] < inf", "[N]"]),
        ([1.0, math.inf], [1.0, 1.0], ValueError, ["stiffness[1]", "inf"]),
        ([1.0, 2.0], [0.0, 1.0], ValueError, ["slip_force[0]", "0.0"]),
        ([1.0, 2.0], [1.0], ValueError, ["same length", "2 and 1"]),
        ([], [], ValueError, ["stiffness", "1 to 100", "got 0"]),
        ([1.0] * 101, [1.0] * 101, ValueError, ["stiffness", "1 to 100", "got 101"]),
        ([[1.0, 2.0]], [[1.0, 2.0]], ValueError, ["stiffness", "shape (1, 2)"]),
        ("12", [1.0], TypeError, ["stiffness", "'12'"]),
        ([1.0], [True], TypeError, ["slip_force", "bool"]),
        ([1.0], None, TypeError, ["slip_force", "None"]),
    ],
)
def test_invalid_parameters_are_named_with_value_and_range(stiffness, slip_force, err, words):
    with pytest.raises(err) as info:
        pf.MaxwellSlip(stiffness, slip_force)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_model_is_immutable_hashable_and_normalised():
    m = pf.MaxwellSlip(**FINITE)
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.stiffness = np.ones(3)
    with pytest.raises(ValueError):  # read-only copy, not the caller's list
        m.stiffness[0] = 1.0
    k = np.array([6e4, 3e4, 1e4])
    m2 = pf.MaxwellSlip(k, [0.3, 0.4, 0.3])
    k[0] = 1.0  # the caller's array is copied
    assert m == m2 and hash(m) == hash(m2) and m != pf.MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.4])
    assert (m.sigma, m.Fc, m.n_states, m.n_flags, m.n_events) == (1e5, 1.0, 4, 3, 3)
    np.testing.assert_allclose(m.runtime_params(), [0.6, 0.3, 0.1, 0.3, 0.4, 0.3], rtol=1e-15)
    assert m.structure_key() == pf.MaxwellSlip([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]).structure_key()
    assert m.structure_key() != pf.MaxwellSlip([1.0, 2.0], [4.0, 5.0]).structure_key()
    np.testing.assert_allclose(m.virgin_curve([2e-6, -1e-5, 1.0]), [0.2, -(0.3 + 0.3 + 0.1), 1.0], rtol=1e-14)


def test_initial_state_lies_on_the_virgin_curve():
    m = pf.MaxwellSlip(**FINITE)
    q = m.runtime_params()
    for f0 in (0.2, 0.5, 0.8, -0.8, 1.0, -1.0):
        for s in (1.0, -1.0):
            z, flags = m.initial_state(f0, s)
            assert math.isclose(sum(z[:3]), f0, rel_tol=1e-14) and z[3] == 0.0
            y = abs(f0) if abs(f0) <= 0.5 else None
            if y is not None:  # below the first slip force: every element at kappa_i y
                np.testing.assert_allclose(np.abs(z[:3]), q[:3] * y, rtol=1e-14)
            # slipping: at the limit and moving along f0
            at = np.isclose(np.abs(z[:3]), q[3:], rtol=1e-14, atol=0)
            assert list(flags) == [1.0 if (a and s * f0 > 0) else 0.0 for a in at]


def test_branch_energy_state_based_and_of_force():
    """The state-based branch energy (exact work to the zero crossing) against a brute-force
    integration of the element law, and against the Masing formula on Masing states."""
    m = pf.MaxwellSlip(**ENDLESS)
    q = m.runtime_params()
    kap, w = q[:3], q[3:]
    rng = np.random.default_rng(3)
    for _ in range(20):
        s = float(rng.choice([-1.0, 1.0]))
        g = rng.uniform(-1, 1, 3) * w  # any state, in the direction of motion
        if g.sum() > 0:
            g = -g
        z = list(s * g) + [0.0]
        d = np.linspace(0.0, 5.0, 500_001)
        f = np.sum(g[:, None] + np.minimum(kap[:, None] * d, (w - g)[:, None]), axis=0)
        i0 = int(np.argmax(f >= 0.0))
        brute = -np.trapezoid(f[:i0], d[:i0])  # grid step 1e-5: error ~1e-10
        assert m.branch_energy(z, [0.0] * 3, s, q) == pytest.approx(brute, abs=2e-9)
    # after a reversal of unforced motion the state-based energy is the Masing one
    sys_ = system(ENDLESS)
    traj = maxwell_slip_trajectory(sys_, 2.0 * pf.Scales.of(sys_).v, 12)
    sc = pf.Scales.of(sys_)
    s_after = -np.sign(np.diff(np.concatenate(([0.0], traj.table.x))))
    masing = m.branch_energy_of_force(traj.table.F / sc.F, s_after) * sc.E
    np.testing.assert_allclose(traj.table.E_p, masing, rtol=1e-13)
    # 4 Phi*(a/2) = a^2/2 while a <= 2 Delta_min (all of [0, 1] here), more beyond: an element
    # slips before the zero crossing (Delta_min = 0.4 below)
    a = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(m.branch_energy_of_force(-a, 1.0), 0.5 * a**2, rtol=1e-14)
    big = pf.MaxwellSlip([1e4, 2e4, 3e4], [0.05, 0.4, 0.3]).branch_energy_of_force(-a, 1.0)
    lin = a <= 0.8 + 1e-12
    assert np.all(big[~lin] > 0.5 * a[~lin] ** 2) and np.allclose(big[lin], 0.5 * a[lin] ** 2, rtol=1e-14)


def test_force_only_energy_holds_when_reversal_forces_alternate():
    """Random displacement histories from the virgin state (the element law, any forcing):
    at an unloading reversal the force-only E_p = 4 Phi*(|F|/2) is the state-based one when
    the preceding reversal force has the other sign (always so unforced); a reversal before
    the force zero crossing (same sign twice, forced only) can break it."""
    rng = np.random.default_rng(2)
    worst_alt, worst_same = 0.0, 0.0
    for _ in range(40):
        n_el = int(rng.integers(1, 6))
        m = pf.MaxwellSlip(rng.uniform(0.1, 1, n_el), rng.uniform(0.1, 1, n_el))
        q = m.runtime_params()
        kap, w = q[:n_el], q[n_el:]
        for _ in range(50):
            n = int(rng.integers(2, 10))
            steps = rng.uniform(0.01, 2.5, n) * np.max(w / kap) * rng.choice([1.0, 0.1, 0.01], n)
            xs = np.cumsum(steps * np.where(np.arange(n) % 2, -1.0, 1.0))
            g, x, forces = np.zeros(n_el), 0.0, [0.0]
            for xn in xs:
                g = np.clip(g + kap * (xn - x), -w, w)
                x = xn
                forces.append(g.sum())
            s_new = -np.sign(xs[-1] - (xs[-2] if n > 1 else 0.0))
            if s_new * forces[-1] >= 0.0:
                continue
            exact = m.branch_energy(list(g) + [0.0], [0.0] * n_el, s_new, q)
            dev = abs(float(m.branch_energy_of_force(np.array([forces[-1]]), s_new)[0]) / exact - 1.0)
            if forces[-2] * forces[-1] <= 0.0:
                worst_alt = max(worst_alt, dev)
            else:
                worst_same = max(worst_same, dev)
    assert worst_alt <= 1e-13 and worst_same > 1e-3


# -------------------------------------------------------------- closed forms cross-checked
def test_one_element_is_the_elastic_plastic_closed_form():
    sys_ = pf.Oscillator(pf.MaxwellSlip([2e5], [0.5]), mass=0.3)
    sc = pf.Scales.of(sys_)
    v0n = 3.0
    tab = maxwell_slip_reversals(sys_, v0n * sc.v, 7)
    t1 = math.asin(1.0 / v0n)
    np.testing.assert_allclose(tab.t / sc.t, t1 + math.sqrt(v0n**2 - 1.0) + math.pi * np.arange(7), rtol=1e-15)
    np.testing.assert_allclose(tab.x / sc.x, (v0n**2 + 1.0) / 2.0 - 2.0 * (np.arange(7) % 2), rtol=1e-15)
    np.testing.assert_allclose(tab.F / sc.F, (-1.0) ** np.arange(7), rtol=1e-15)


@pytest.mark.parametrize("params", [FINITE, ENDLESS, TIES])
def test_event_closed_form_agrees_with_the_masing_map(params):
    """Two derivations: element by element in time, and the Masing map of the virgin curve."""
    sys_ = system(params)
    m, sc = sys_.friction, pf.Scales.of(sys_)
    v0n = 1.7
    tab = maxwell_slip_reversals(sys_, v0n * sc.v, 30)
    y1, a1 = first_reversal(m, 0.5 * v0n**2)
    a = masing_amplitudes(m, a1, 30)
    np.testing.assert_allclose(np.abs(tab.F) / sc.F, a, rtol=1e-13)
    spans = masing_next(m, a[:-1])[1]
    np.testing.assert_allclose(np.abs(np.diff(tab.x)) / sc.x, spans, rtol=1e-12)
    assert tab.x[0] / sc.x == pytest.approx(y1, rel=1e-14)
    # energies: E_0 = v0^2/2, E_p the Masing energy, E_d >= 0
    assert tab.E_0 / sc.E == pytest.approx(0.5 * v0n**2, rel=1e-15)
    assert np.all(tab.E_d >= -1e-15 * tab.E_0)


# ------------------------------------------------------------------- simulator vs exact
@pytest.mark.parametrize(("params", "F0"), [(FINITE, 0.0), (ENDLESS, 0.0), (TIES, 0.0), (ENDLESS, -0.6), (FINITE, 1.0)])
def test_simulator_at_rtol_1e13_matches_the_closed_form(params, F0):
    sys_ = system(params)
    sc = pf.Scales.of(sys_)
    ref = maxwell_slip_reversals(sys_, 2.2 * sc.v, 14, F0=F0)
    res = pf.simulate(sys_, 2.2 * sc.v, reversals=14, rtol=1e-13, F0=F0)
    assert rel_err(res.reversals, ref) <= 1e-12  # measured 6e-15 .. 1.3e-14
    np.testing.assert_allclose(res.reversals.E_p, ref.E_p, rtol=1e-11, atol=1e-12 * ref.E_0)
    assert res.reversals.E_0 == pytest.approx(ref.E_0, rel=1e-15)


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8, 1e-10])
def test_simulator_within_ten_rtol(rtol):
    for params in (FINITE, ENDLESS, TIES):
        sys_ = system(params)
        sc = pf.Scales.of(sys_)
        ref = maxwell_slip_reversals(sys_, 2.2 * sc.v, 14)
        res = pf.simulate(sys_, 2.2 * sc.v, reversals=14, rtol=rtol)
        assert rel_err(res.reversals, ref) <= 10 * rtol, params


def slip_bounds(traj, tol=1e-6):
    """Least and most slips per half-cycle a simulation may see: a slip within ``tol``
    (normalised distance) of its reversal, or an element touching its slip force at the
    reversal (margin below ``tol``), is a near-coincidence resolved either way."""
    sc = traj._scales
    groups = np.split(traj.slip_gap / sc.x, np.cumsum(traj.slips)[:-1])
    lo = np.array([int(np.sum(g >= tol)) for g in groups])
    touch = np.sum(np.nan_to_num(traj.margin, nan=1.0) < tol, axis=1)
    return lo, traj.slips + touch


@pytest.mark.parametrize(("params", "v0n", "n"), [(FINITE, 2.2, 12), (ENDLESS, 2.2, 10), (TIES, 1.3, 8)])
def test_every_slip_is_located(params, v0n, n):
    """Slips per half-cycle seen by the simulator = the closed form's. ENDLESS: the weakest
    element slips shortly before each reversal (ever closer); TIES: two elements slip at once."""
    sys_ = system(params)
    sc = pf.Scales.of(sys_)
    traj = maxwell_slip_trajectory(sys_, v0n * sc.v, n)
    res, seen = slips_seen(sys_.friction, sys_, v0n * sc.v, n, 1e-10)
    lo, hi = slip_bounds(traj)
    assert np.all(lo <= seen) and np.all(seen <= hi), (seen, traj.slips, lo, hi)
    assert int(np.sum(lo < hi)) <= n // 2  # only touches in the undamped regime are ambiguous here
    assert traj.slips.sum() == traj.slip_t.size == traj.slip_element.size == traj.slip_gap.size
    assert rel_err(res.reversals, traj.table) <= 1e-9


def test_masing_rule_on_dense_output():
    """Between reversals the simulated force follows the virgin curve (first excursion) and
    then the virgin curve stretched by 2 in both axes from each reversal."""
    sys_ = system(ENDLESS)
    m, sc = sys_.friction, pf.Scales.of(sys_)
    res = pf.simulate(sys_, 1.8 * sc.v, reversals=8, rtol=1e-10, dense=True)
    tab = res.reversals
    t, x, F = res.t, res.x, res.F
    first = t < tab.t[0]
    np.testing.assert_allclose(F[first], m.virgin_curve(x[first]), rtol=0, atol=1e-9 * m.Fc)
    checked = 0
    for k in range(len(tab.t) - 1):
        on = (t > tab.t[k]) & (t < tab.t[k + 1])
        s = -np.sign(tab.x[k] - (tab.x[k - 1] if k else 0.0))
        masing = tab.F[k] + 2.0 * s * m.virgin_curve(s * (x[on] - tab.x[k]) / 2.0)
        np.testing.assert_allclose(F[on], masing, rtol=0, atol=1e-9 * m.Fc)
        checked += int(on.sum())
    assert checked > 200
    # and the dense output agrees with the closed form's samples
    xe, ve, Fe = maxwell_slip_trajectory(sys_, 1.8 * sc.v, 8).sample(t[t < tab.t[-1]])
    np.testing.assert_allclose(F[t < tab.t[-1]], Fe, rtol=0, atol=1e-9 * m.Fc)


def test_check_model_passes_for_two_instances_of_one_structure():
    """The reusable checks; two instances of N = 3 in one process share the plant, so numbers
    baked into it (not taken from q) would fail the second."""
    for params in (FINITE, dict(stiffness=[1e4, 2e4, 3e4], slip_force=[0.05, 0.4, 0.3])):
        out = check_model(pf.MaxwellSlip(**params), v0=1.5, reversals=12)
        assert out.n_reversals == 12 and out.max_error <= 1e-8 and out.branch_energy_error <= 1e-8


def test_k_min_and_the_bound_2_12():
    """With a small slip deflection an element slips before the zero crossing of an unloading
    branch: E_p after a reversal at Fc exceeds Fc^2/(2 sigma), and k_min < sigma keeps (2.12)."""
    m = pf.MaxwellSlip([1e4, 2e4, 3e4], [0.05, 0.4, 0.3])  # Delta = 0.4, 1.6, 0.8 (normalised)
    assert m.k_min == pytest.approx(m.sigma * 5.0 / 6.0, rel=1e-14)
    assert pf.MaxwellSlip(**FINITE).k_min == pf.MaxwellSlip(**FINITE).sigma
    sys_ = pf.Oscillator(m, mass=0.2)
    sc = pf.Scales.of(sys_)
    tab = pf.simulate(sys_, 4.0 * sc.v, reversals=6, rtol=1e-10).reversals  # first reversal at Fc
    assert tab.F[0] == pytest.approx(m.Fc, rel=1e-12)
    assert tab.E_p[0] > 0.5 * m.Fc**2 / m.sigma * 1.007  # 0.504 Fc^2/sigma
    check = pf.energy.bound_check(tab.E_p, friction=m)
    assert check.holds and check.max_E_p <= check.bound_sharp * (1 + 1e-9)


# ------------------------------------------------------------------ energy analysis
def test_energy_analysis_on_tables_and_samples():
    sys_ = system(FINITE)
    sc = pf.Scales.of(sys_)
    ref = maxwell_slip_reversals(sys_, 1.8 * sc.v, 8)
    rep = pf.energy.analyze_table(ref, system=sys_)
    assert rep.residual_2_10 <= 1e-14 and rep.E_p_check_max_rel_dev <= 1e-13 and rep.bound.holds
    res = pf.simulate(sys_, 1.8 * sc.v, reversals=8, rtol=1e-10, dense=True)
    rep = pf.energy.analyze_samples(res.t, res.x, res.v, res.F, system=sys_)
    n = len(rep)
    np.testing.assert_allclose(rep.E_p, ref.E_p[:n], rtol=1e-5)  # reversals interpolated between samples
    assert rep.E_p_check_max_rel_dev <= 1e-3  # peak kinetic energy (64 samples per cycle)
    assert rep.E_d[0] == pytest.approx(ref.E_d[0], rel=1e-5)


# ------------------------------------------------------------------ the prediction
def test_finite_dissipation_when_the_weakest_elements_are_stiff():
    """kappa_1 > 1/2: after finitely many half-cycles no element slips again; the motion is
    then an undamped oscillation of stiffness sigma with constant reversal force <= sigma d_min."""
    sys_ = system(FINITE)
    m, sc = sys_.friction, pf.Scales.of(sys_)
    lim = dissipation_limit(m)
    assert lim.kappa_1 == pytest.approx(0.6) and lim.finite is True
    assert lim.force == pytest.approx(0.5 * m.Fc)
    # Masing prediction: the first reversal at |F| <= sigma d_min
    _, a1 = first_reversal(m, 0.5 * 2.2**2)
    a = masing_amplitudes(m, a1, 40)
    n_last = int(np.argmax(a <= lim.force / m.Fc))
    assert n_last == 2 and np.all(a[n_last:] == a[n_last])
    res, seen = slips_seen(m, sys_, 2.2 * sc.v, 40, 1e-10)
    tab = res.reversals
    lo, hi = slip_bounds(maxwell_slip_trajectory(sys_, 2.2 * sc.v, 40))
    assert np.all(lo[: n_last + 1] > 0) and np.all(lo[n_last + 1:] == 0)  # no slip after n_last,
    assert np.all((lo <= seen) & (seen <= hi))  # but the last to slip touch W_i at every other reversal
    assert np.max(np.abs(tab.E_d[n_last + 1:])) <= 1e-9 * tab.E_0  # no dissipation
    np.testing.assert_allclose(np.abs(tab.F[n_last:]), a[n_last] * m.Fc, rtol=1e-9)
    np.testing.assert_allclose(np.diff(tab.t[n_last:]), math.pi * sc.t, rtol=1e-9)
    np.testing.assert_allclose(tab.E_p[n_last:], 0.5 * tab.F[n_last:] ** 2 / m.sigma, rtol=1e-9)


def test_endless_geometric_approach_when_the_weakest_elements_are_soft():
    """kappa_1 < 1/2 with reversals below the single-group force: the weakest element slips in
    every half-cycle and a_n - Delta_min shrinks by 1 - 2 kappa_1 per half-cycle, never 0."""
    sys_ = system(ENDLESS)
    m, sc = sys_.friction, pf.Scales.of(sys_)
    lim = dissipation_limit(m)
    assert lim.kappa_1 == pytest.approx(0.3) and lim.finite is None
    traj = maxwell_slip_trajectory(sys_, 2.0 * sc.v, 40)
    a = np.abs(traj.table.F) / m.Fc
    d = a - lim.force / m.Fc
    assert a[1] <= lim.single_group_force / m.Fc
    assert np.all(d > 0) and np.all(traj.slips >= 1) and np.all(np.diff(d) < 0)
    ratio = d[1:21] / d[:20]  # d ~ 1e-8 by then (beyond, the differences reach round-off)
    np.testing.assert_allclose(ratio[12:], 1.0 - 2.0 * lim.kappa_1, rtol=1e-4)
    assert np.all(traj.table.E_d[1:] > 0)
    # the simulator sees the same: dissipation in every half-cycle
    res = pf.simulate(sys_, 2.0 * sc.v, reversals=12, rtol=1e-12)
    assert np.all(res.reversals.E_d > 0)
    np.testing.assert_allclose(res.reversals.F, traj.table.F[:12], rtol=1e-10)


# ------------------------------------------------------------------ loops and sweeps
def test_simulate_loop_in_the_linear_regime_is_the_linear_loop():
    """Slip forces far beyond the loop's forces: a spring sigma = sum k_i, so the PD loop is
    python-control's linear closed loop."""
    import control

    from prefriction import controllers

    k, m, kp, kd, tau, r0 = np.array([2e5, 3e5, 5e5]), 1.0, 2e6, 2000.0, 5e-5, 1e-6
    stage = pf.Oscillator(pf.MaxwellSlip(k, [1e8, 1e8, 1e8]), mass=m)
    res = controllers.simulate_loop(stage, controllers.pd(kp, kd, tau=tau), r0, 0.02)
    C = control.tf([kd + kp * tau, kp], [tau, 1.0])
    T = control.feedback(control.tf([1.0], [m, 0.0, k.sum()]) * C, 1)
    lin = control.forced_response(T, res.t, np.full(res.t.shape, r0)).outputs
    assert float(np.max(np.abs(res.x - lin)) / np.max(np.abs(lin))) <= 1e-6


def test_sweep_over_instances_of_one_structure():
    from prefriction.simulation.integrator import _CACHE

    systems = [pf.Oscillator(pf.MaxwellSlip(k, W), mass=mass) for k, W, mass in [
        ([6e4, 3e4, 1e4], [0.3, 0.4, 0.3], 0.1),
        ([1e3, 5e3, 2e3], [2.0, 1.0, 3.0], 2.0),
        ([3e4, 2e4, 5e4], [0.45, 0.25, 0.8], 1e-3),
    ]]
    v0 = [1.9 * pf.Scales.of(s).v for s in systems]
    pf.simulate(systems[0], v0[0], reversals=2)  # plant built (or cached) before counting
    before = len(_CACHE)
    out = pf.sweep(systems, v0, reversals=6, rtol=1e-10)
    assert not out.failed and len(_CACHE) == before  # one plant for every N = 3 model
    for s, v, r in zip(systems, v0, out):
        assert rel_err(r.reversals, maxwell_slip_reversals(s, v, 6)) <= 1e-9


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_figure_script_draws_both_figures(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from prefriction.cli.paper import load_example

    out = load_example("maxwell_slip_figures").main(tmp_path, quick=True)
    for png in out["pngs"]:
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    stiff = out["tables"]["stiff weakest elements"]
    np.testing.assert_allclose(np.abs(stiff.F[2:]), np.abs(stiff.F[2]), rtol=1e-14)  # undamped from reversal 3
    assert out["limits"]["soft weakest element"].kappa_1 == pytest.approx(0.3)
