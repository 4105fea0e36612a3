"""controllers.simulate_loop: linear-regime match with python-control, PD bound, PID integral action.

References: python-control's own linear closed loops (``control.feedback`` of the textbook
plant and controller, ``control.forced_response``; for sampled loops the exact ZOH
discretisation ``control.c2d`` of the plant), the static balance ``|e| <= Fc/kp`` of a PD loop
at rest, the final value theorem, the closed-form Dahl branch (3.4) for gamma = 1, and scipy LSODA on
m x'' = u - F, F' = sigma (v - |v| F/Fc) for loops that rest and move again.
"""

from __future__ import annotations

import warnings

import control
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from prefriction import controllers
import prefriction

M, SIGMA = 1.0, 1e6
TS = 1e-4


def linear_stage():
    """Fc so large that |F|/Fc stays below 1e-8: the Dahl friction is the spring sigma."""
    return prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=1e8), mass=M)


def stage(Fc=1.0):
    return prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=Fc), mass=M)


def plant_tf():
    return control.tf([1.0], [M, 0.0, SIGMA])


def pid_tf(kp, ki, kd, tau):
    """kp + ki/s + kd s/(tau s + 1) over the common denominator s (tau s + 1) (PD: tau s + 1)."""
    if ki == 0.0:
        return control.tf([kd + kp * tau, kp], [tau, 1.0])
    return control.tf([kd + kp * tau, kp + ki * tau, ki], [tau, 1.0, 0.0])


def rel_err(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


GAINS = [  # kp [N/m], ki [N/(m s)], kd [N s/m], tau [s]
    (2e6, 0.0, 2000.0, 5e-5),
    (1.1e6, 8e8, 2300.0, 1e-4),
]


@pytest.mark.parametrize("kp, ki, kd, tau", GAINS)
def test_linear_regime_continuous_matches_python_control(kp, ki, kd, tau):
    system = linear_stage()
    r0 = 1e-6
    C = controllers.PID(kp=kp, ki=ki, kd=kd, tau=tau)
    res = controllers.simulate_loop(system, C, r0, 0.02)
    T = control.feedback(plant_tf() * pid_tf(kp, ki, kd, tau), 1)
    lin = control.forced_response(T, res.t, np.full(res.t.shape, r0)).outputs
    assert rel_err(res.x, lin) <= 1e-6
    U = control.feedback(pid_tf(kp, ki, kd, tau), plant_tf())  # r -> u
    assert rel_err(res.u, control.forced_response(U, res.t, np.full(res.t.shape, r0)).outputs) <= 1e-6
    assert res.Ts is None and len(res.t) == 2001


@pytest.mark.parametrize("kp, ki, kd, tau", GAINS)
def test_linear_regime_sampled_matches_exact_discretised_loop(kp, ki, kd, tau):
    system = linear_stage()
    r0 = 1e-6
    Cd = control.c2d(pid_tf(kp, ki, kd, tau), TS, "zoh")
    res = controllers.simulate_loop(system, Cd, r0, 0.02)
    Tz = control.feedback(control.c2d(plant_tf(), TS, "zoh") * Cd, 1)
    lin = control.forced_response(Tz, res.t, np.full(res.t.shape, r0)).outputs
    np.testing.assert_allclose(res.t, TS * np.arange(len(res.t)), rtol=0, atol=1e-15)
    assert rel_err(res.x, lin) <= 1e-6
    assert res.Ts == TS


def test_linear_regime_references_callable_and_samples():
    system = linear_stage()
    kp, kd, tau = 2e6, 2000.0, 5e-5
    # continuous loop: samples of 1e-6 (1 - exp(-t / 2 ms)) every 50 us, on the output grid (5 us), so
    # that forced_response (linear between its time points) sees the same piecewise-linear reference
    tr = np.linspace(0.0, 0.01, 201)
    ramp = (tr, 1e-6 * (1.0 - np.exp(-tr / 2e-3)))
    res = controllers.simulate_loop(system, controllers.pd(kp, kd, tau=tau), ramp, 0.01)
    T = control.feedback(plant_tf() * pid_tf(kp, 0.0, kd, tau), 1)
    lin = control.forced_response(T, res.t, np.interp(res.t, *ramp)).outputs
    assert rel_err(res.x, lin) <= 1e-6
    np.testing.assert_allclose(res.reference, np.interp(res.t, *ramp), rtol=1e-14)
    # sampled loop: samples (t, r), linear between them, read at the instants k Ts
    Cd = control.c2d(pid_tf(kp, 0.0, kd, tau), TS, "zoh")
    Tz = control.feedback(control.c2d(plant_tf(), TS, "zoh") * Cd, 1)
    samples = (np.array([0.0, 0.004, 0.01]), np.array([2e-7, 1e-6, 1e-6]))
    res_s = controllers.simulate_loop(system, Cd, samples, 0.01)
    lin_s = control.forced_response(Tz, res_s.t, np.interp(res_s.t, *samples)).outputs
    assert rel_err(res_s.x, lin_s) <= 1e-6
    # a plain Python callable (not CasADi-traceable) is fine in a sampled loop
    late = lambda t: 1e-6 if t >= 5e-4 else 2e-7  # noqa: E731
    res_c = controllers.simulate_loop(system, Cd, late, 0.01)
    r = np.where(res_c.t >= 5e-4, 1e-6, 2e-7)
    np.testing.assert_array_equal(res_c.reference, r)
    assert rel_err(res_c.x, control.forced_response(Tz, res_c.t, r).outputs) <= 1e-6


def _stable_sampled_loop(design, step, t_end):
    """The design sampled at TS on the Dahl stage; an UnstableLoopWarning fails the test.

    A loop that settles: well damped once sampled (a nearly unstable sampled loop, e.g.
    wn = 3 sqrt(sigma/m) with zeta = 1 at 10 kHz, 0.2 deg margin, rings for long).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error", controllers.UnstableLoopWarning)
        c = design(stage())
        assert controllers.margins(stage(), c.c2d(TS)).phase_margin > 25.0
        return c, controllers.simulate_loop(stage(), c.c2d(TS), step, t_end)


@settings(max_examples=4, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(wn_ratio=st.floats(1.3, 2.2), zeta=st.floats(0.5, 0.9), step=st.floats(2e-7, 3e-6))
def test_pd_settles_within_fc_over_kp(wn_ratio, zeta, step):
    pd, res = _stable_sampled_loop(lambda s: controllers.design_pd(s, wn=wn_ratio * np.sqrt(SIGMA / M), zeta=zeta),
                                   step, 0.04)
    bound = 1.0 / pd.kp  # Fc / kp
    tail = res.t >= 0.03
    assert np.all(np.abs(res.error[tail]) <= bound)
    assert abs(res.residual_error) <= bound * (1 - 1e-9)
    # at rest the friction balances the proportional force: F = kp e (static gain of the ZOH PD)
    assert abs(res.v[-1]) <= 1e-9 * step * np.sqrt(SIGMA / M)
    assert res.F[-1] == pytest.approx(pd.kp * res.residual_error, rel=1e-6)
    assert res.error_bound == pytest.approx(bound, rel=1e-12)


@settings(max_examples=3, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(wn_hz=st.floats(110.0, 200.0), zeta=st.floats(0.6, 0.9), step=st.floats(2e-7, 3e-6))
def test_pid_drives_error_to_zero(wn_hz, zeta, step):
    _, res = _stable_sampled_loop(lambda s: controllers.design_pid(s, wn=2 * np.pi * wn_hz, zeta=zeta), step, 0.08)
    assert abs(res.residual_error) <= 1e-6 * step
    assert res.kp is None and res.error_bound is None  # integrator: no finite static gain


def test_samples_lie_on_closed_form_dahl_branches():
    """gamma = 1: between reversals s F/Fc = 1 - (1 - s F_i/Fc) exp(-s (x - x_i) sigma/Fc), (3.4)."""
    system = stage()
    res = controllers.simulate_loop(system, controllers.design_pd(system, wn=3000.0).c2d(TS), 1e-6, 0.01)
    xs = np.concatenate(([0.0], res.reversals.x))
    Fs = np.concatenate(([0.0], res.reversals.F))
    ts = np.concatenate(([0.0], res.reversals.t))
    assert len(res.reversals) >= 2
    for k, (t, x, F) in enumerate(zip(res.t, res.x, res.F)):
        i = np.searchsorted(ts, t, side="right") - 1
        if i + 1 < len(ts):
            s = np.sign(xs[i + 1] - xs[i])
        else:
            s = np.sign(x - xs[i]) or 1.0
        f = 1.0 - (1.0 - s * Fs[i]) * np.exp(-s * (x - xs[i]) * SIGMA)
        assert s * F == pytest.approx(f, abs=1e-7), k
    lx, lF = res.friction_loop()
    assert lx[0] == 0.0 and lF[0] == 0.0 and lx[-1] == res.x[-1]
    np.testing.assert_allclose(lF[-1], res.F[-1], rtol=1e-6)


def test_summary_is_readable():
    system = stage()
    res = controllers.simulate_loop(system, controllers.design_pd(system, wn=3000.0), 1e-6, 0.01)
    text = res.summary()
    for key in ("residual error", "Fc/kp", "velocity reversals", "settling time"):
        assert key in text
    assert f"{len(res.reversals)}" in text


def test_argument_errors():
    system = stage()
    pd = controllers.pd(2e6, 2000.0)
    with pytest.raises(ValueError, match=r"reference samples must be a pair \(t, r\) of 1-D arrays of equal length >= 2, "
                                         r"got shapes \(3,\) and \(2,\)"):
        controllers.simulate_loop(system, pd, (np.array([0.0, 1.0, 2.0]), np.array([0.0, 1e-6])), 0.01)
    with pytest.raises(ValueError, match="strictly increasing"):
        controllers.simulate_loop(system, pd, (np.array([0.0, 0.0]), np.array([0.0, 1e-6])), 0.01)
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got 0.0"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, Ts=0.0)
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got -0.0001"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, Ts=-1e-4)
    with pytest.raises(ValueError, match=r"t_end must be finite and > 0, got nan"):
        controllers.simulate_loop(system, pd, 1e-6, float("nan"))
    with pytest.raises(ValueError, match="differs from the discrete controller's sample time"):
        controllers.simulate_loop(system, pd.c2d(1e-4), 1e-6, 0.01, Ts=2e-4)
    with pytest.raises(ValueError, match="t_out is not allowed with a sampled controller"):
        controllers.simulate_loop(system, pd.c2d(1e-4), 1e-6, 0.01, t_out=[0.0, 0.01])
    with pytest.raises(ValueError, match="reference must be finite"):
        controllers.simulate_loop(system, pd, float("inf"), 0.01)
    with pytest.raises(TypeError, match=r"pass \(t, r\) with the sample times"):
        controllers.simulate_loop(system, pd, [0.0, 1e-6], 0.01)
    with pytest.raises(TypeError, match="unexpected keyword argument 'ts'"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, ts=1e-4)
    with pytest.raises(ValueError, match=r"t_out must be strictly increasing, got t_out\[2\] = 0.001 <= t_out\[1\] = 0.002"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, t_out=[0.0, 0.002, 0.001])
    with pytest.raises(ValueError, match=r"t_out\[1\] must be finite and in \[0.0, 0.01\] \[s\], got 0.02"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, t_out=[0.0, 0.02])
    with pytest.raises(TypeError, match="reference samples t must be a real number or an array of finite real numbers"):
        controllers.simulate_loop(system, pd, ("ab", "cd"), 0.01)
    with pytest.raises(ValueError, match=r"xc0 must be a vector of length n = 1 \(the controller states of A\), got \[0.0, 0.0\]"):
        controllers.simulate_loop(system, pd, 1e-6, 0.01, xc0=[0.0, 0.0])
    with pytest.raises(TypeError, match="warn must be True or False, got 'yes'"):
        controllers.closed_loop(system, pd, warn="yes")
    with pytest.raises(ValueError, match="unspecified sample time"):
        controllers.simulate_loop(system, control.tf([1.0], [1.0, -0.5], True), 1e-6, 0.01)
    limited = controllers.design_pid(system, wn=2 * np.pi * 150, u_max=5.0)
    forced = prefriction.Oscillator(system.friction, mass=M, u=lambda t: 0.1 * np.sin(t))
    with pytest.raises(ValueError, match=r"u_max needs an oscillator without its own input force"):
        controllers.simulate_loop(forced, limited, 1e-6, 0.01, Ts=TS)


def test_unstable_loop_warns_and_still_runs():
    system = stage()
    bad = controllers.PID(kp=1e5, ki=1e12).c2d(TS)
    with pytest.warns(controllers.UnstableLoopWarning, match="poles"):
        res = controllers.simulate_loop(system, bad, 1e-7, 20 * TS)
    assert len(res.t) >= 19


def test_continuous_controller_with_ts_is_discretised():
    system = linear_stage()
    pd = controllers.pd(2e6, 2000.0, tau=5e-5)
    res = controllers.simulate_loop(system, pd, 1e-6, 0.005, Ts=TS, discretization="tustin")
    ref = control.c2d(pid_tf(2e6, 0.0, 2000.0, 5e-5), TS, "tustin")
    w = np.array([100.0, 5000.0])
    np.testing.assert_allclose(np.squeeze(control.frequency_response(res.controller, w).complex),
                               np.squeeze(control.frequency_response(ref, w).complex), rtol=1e-9)
    assert res.Ts == TS


def _saturated_reference(kp, ki, kd, tau, t_track, u_max, r0, n):
    """Independent sampled loop: exact ZOH plant 1/(m s^2 + sigma), PID with clip and back-calculation."""
    Pz = control.c2d(control.ss([[0.0, 1.0], [-SIGMA / M, 0.0]], [[0.0], [1.0 / M]], [[1.0, 0.0]], [[0.0]]), TS)
    Ad, Bd = np.asarray(Pz.A), np.asarray(Pz.B)[:, 0]
    a = np.exp(-TS / tau)
    z, I, xf, xs, us = np.zeros(2), 0.0, 0.0, [], []
    for _ in range(n):
        e = r0 - z[0]
        v = kp * e + ki * I + kd / tau * (e - xf)
        u = min(max(v, -u_max), u_max)
        xs.append(z[0])
        us.append(u)
        I += TS * e + TS / (ki * t_track) * (u - v)
        xf = a * xf + (1.0 - a) * e
        z = Ad @ z + Bd * u
    return np.array(xs), np.array(us)


def test_saturated_pid_linear_regime_matches_independent_loop():
    kp, ki, kd, tau, t_track, u_max, r0 = 1.1e6, 8e8, 2300.0, 1e-4, 2e-3, 2.0, 3e-6
    c = controllers.PID(kp=kp, ki=ki, kd=kd, tau=tau, u_max=u_max, t_track=t_track)
    res = controllers.simulate_loop(linear_stage(), c, r0, 0.01, Ts=TS)
    x_ref, u_ref = _saturated_reference(kp, ki, kd, tau, t_track, u_max, r0, len(res.t))
    assert np.max(np.abs(u_ref)) == u_max  # the force limit is active
    assert rel_err(res.x, x_ref) <= 1e-6
    assert rel_err(res.u, u_ref) <= 1e-6


def test_saturated_path_without_saturation_equals_linear_path():
    system = stage()
    c = controllers.design_pid(system, wn=2 * np.pi * 150)
    lin = controllers.simulate_loop(system, c, 2e-6, 0.02, Ts=TS)
    big = controllers.simulate_loop(system, controllers.PID(kp=c.kp, ki=c.ki, kd=c.kd, tau=c.tau, u_max=1e9),
                                    2e-6, 0.02, Ts=TS)
    n = min(len(lin.t), len(big.t))
    assert big.loop_stats is not None and lin.loop_stats is not None
    assert rel_err(big.x[:n], lin.x[:n]) <= 1e-8
    assert len(big.reversals) == len(lin.reversals) >= 2
    np.testing.assert_allclose(big.reversals.x, lin.reversals.x, rtol=1e-8)
    np.testing.assert_allclose(big.reversals.E_d, lin.reversals.E_d, rtol=1e-6)


def test_anti_windup_reduces_overshoot_with_dahl_friction():
    system = stage()
    c = controllers.design_pid(system, wn=2 * np.pi * 150, u_max=3.0)
    r0 = 5e-6  # five pre-sliding ranges: gross sliding, the force limit is hit
    aw = controllers.simulate_loop(system, c, r0, 0.03, Ts=TS)
    no_aw = controllers.simulate_loop(system, controllers.PID(kp=c.kp, ki=c.ki, kd=c.kd, tau=c.tau, u_max=3.0,
                                                              t_track=1e6), r0, 0.03, Ts=TS)
    assert np.max(np.abs(aw.u)) == 3.0 and np.max(np.abs(no_aw.u)) == 3.0
    assert np.max(aw.x) - r0 < 0.8 * (np.max(no_aw.x) - r0)


def _dahl_rhs(u, y):
    """m x'' = u - F, F' = sigma (v - |v| F/Fc): Dahl (3.2) with gamma = 1, Fc = 1 N, as one smooth-enough ODE."""
    return [y[1], (u - y[2]) / M, SIGMA * (y[1] - abs(y[1]) * y[2])]


def _lsoda_sampled(Cd, r_at, n):
    """Independent sampled loop: scipy LSODA over each hold interval, controller ``Cd`` stepped by hand."""
    Cd = control.ss(Cd)
    A, B, C, D = (np.asarray(X, dtype=float) for X in (Cd.A, Cd.B, Cd.C, Cd.D))
    xc, y, xs = np.zeros(A.shape[0]), np.zeros(3), []
    for k in range(n):
        xs.append(y[0])
        e = r_at(k * TS) - y[0]
        u = float(C[0] @ xc + D[0, 0] * e)
        xc = A @ xc + B[:, 0] * e
        y = solve_ivp(lambda t, z: _dahl_rhs(u, z), (0.0, TS), y, method="LSODA", rtol=1e-10, atol=1e-22).y[:, -1]
    return np.array(xs)


def test_sampled_delayed_step_from_rest():
    """The mass rests until the reference moves (r(0) = x0, no force), then follows the loop."""
    kp, ki, kd, tau = 1.1e6, 8e8, 2300.0, 1e-4
    Cd = control.c2d(pid_tf(kp, ki, kd, tau), TS, "zoh")
    samples = (np.array([0.0, 1.05e-3, 1.06e-3, 0.02]), np.array([0.0, 0.0, 1e-6, 1e-6]))  # first r > 0 at k = 11
    res = controllers.simulate_loop(linear_stage(), Cd, samples, 0.01)
    Tz = control.feedback(control.c2d(plant_tf(), TS, "zoh") * Cd, 1)
    r = np.interp(res.t, *samples)
    assert r[0] == 0.0 and r[-1] == 1e-6
    assert rel_err(res.x, control.forced_response(Tz, res.t, r).outputs) <= 1e-6
    np.testing.assert_allclose(res.t, TS * np.arange(len(res.t)), rtol=0, atol=1e-15)
    # Dahl stage (1 um step: beyond the linear pre-sliding range) against scipy LSODA
    late = controllers.simulate_loop(stage(), Cd, samples, 0.01)
    assert np.all(late.x[:11] == 0.0) and late.x[12] > 1e-8 and len(late.reversals) >= 1
    assert rel_err(late.x, _lsoda_sampled(Cd, lambda t: np.interp(t, *samples), len(late.t))) <= 1e-8


def test_sampled_loop_moves_a_resting_mass_again():
    """A PD loop comes to exact rest; a later reference change must move the mass again (scipy LSODA)."""
    Cd = controllers.design_pd(stage(), wn=2 * np.pi * 300, zeta=0.5).c2d(TS)
    ref = lambda t: 1e-6 if t < 0.04 - 1e-12 else 0.0  # noqa: E731
    res = controllers.simulate_loop(stage(), Cd, ref, 0.06)
    k = 400  # t = 40 ms
    # at rest (|v| at round-off of the mm/s peak speed)
    assert res.t[k] == pytest.approx(0.04) and abs(res.v[k]) <= 1e-15 and abs(res.v[k - 1]) <= 1e-15
    assert res.x[k] - res.x[k + 5] > 5e-7
    assert np.any(res.reversals.t > 0.04)
    assert rel_err(res.x, _lsoda_sampled(Cd, ref, len(res.t))) <= 1e-8


def _lsoda_continuous(C, ref, y0, t):
    """Independent continuous loop from state ``y0 = (x, v, F, xc)`` at ``t[0]``: scipy LSODA."""
    A, B, Cm, D = (np.asarray(X, dtype=float) for X in (C.A, C.B, C.C, C.D))

    def rhs(tt, y):
        e = ref(tt) - y[0]
        return np.concatenate((_dahl_rhs(float(Cm[0] @ y[3:] + D[0, 0] * e), y[:3]), A @ y[3:] + B[:, 0] * e))

    return solve_ivp(rhs, (t[0], t[-1]), y0, method="LSODA", rtol=1e-10, atol=1e-22, t_eval=t).y[0]


def test_continuous_loop_moves_a_resting_mass_with_a_smooth_reference():
    system = stage()
    pd = controllers.design_pd(system, wn=2 * np.pi * 300, zeta=0.5)
    # 1e-6 (1 - tanh((t - 40.5 ms) / 0.1 ms)) / 2 sampled every 10 us over its transition (1 ms
    # elsewhere): a smooth reference as samples, linear between them (LSODA reads the same samples)
    coarse = np.linspace(0.0, 0.046, 47)
    tr = np.concatenate((coarse[coarse < 0.0395], np.linspace(0.0395, 0.0415, 201), coarse[coarse > 0.0415]))
    samples = (tr, 1e-6 * (0.5 - 0.5 * np.tanh((tr - 0.0405) / 1e-4)))
    ref = lambda tt: np.interp(tt, *samples)  # noqa: E731
    t = np.linspace(0.0, 0.046, 461)
    res = controllers.simulate_loop(system, pd, samples, 0.046, t_out=t)
    k = 390  # 39 ms: creeping, |v| < 1e-11 m/s
    assert abs(res.v[k]) < 1e-11 and res.x[k] - res.x[-1] > 5e-7
    y0 = np.concatenate(([res.x[k], res.v[k], res.F[k]], res.xc[k]))
    assert rel_err(res.x[k:], _lsoda_continuous(res.controller, ref, y0, t[k:])) <= 1e-8


def test_continuous_loop_follows_a_reference_jump_from_rest():
    """A jump of a sampled reference while the mass rests: the LSODA trajectory from 39 ms on."""
    system = stage()
    pd = controllers.design_pd(system, wn=2 * np.pi * 300, zeta=0.5)
    samples = (np.array([0.0, 0.04, 0.04 + 1e-6, 1.0]), np.array([1e-6, 1e-6, 0.0, 0.0]))
    t = np.linspace(0.0, 0.046, 461)
    res = controllers.simulate_loop(system, pd, samples, 0.046, t_out=t)
    k = 390
    assert np.any(res.reversals.t > 0.04)
    y0 = np.concatenate(([res.x[k], res.v[k], res.F[k]], res.xc[k]))
    ref = lambda tt: np.interp(tt, *samples)  # noqa: E731
    assert rel_err(res.x[k:], _lsoda_continuous(res.controller, ref, y0, t[k:])) <= 1e-8


def test_saturated_loop_delayed_step_from_rest():
    """The per-sample (force-limited) path: rest until the step, then the LSODA trajectory; no step, no motion."""
    c = controllers.PID(kp=1.1e6, ki=8e8, kd=2300.0, tau=1e-4, u_max=1e9)
    samples = (np.array([0.0, 1.05e-3, 1.06e-3, 0.02]), np.array([0.0, 0.0, 1e-6, 1e-6]))
    res = controllers.simulate_loop(stage(), c, samples, 0.005, Ts=TS)
    assert np.all(res.x[:11] == 0.0) and res.x[12] > 1e-8 and len(res.reversals) >= 1
    assert rel_err(res.x, _lsoda_sampled(res.controller, lambda t: np.interp(t, *samples), len(res.t))) <= 1e-8
    still = controllers.simulate_loop(stage(), c, 0.0, 0.001, Ts=TS)  # r = x0, F0 = 0: no force, no motion
    assert np.all(still.x == 0.0) and np.all(still.u == 0.0) and len(still.reversals) == 0
    assert still.reversals.E_0 == 0.0
