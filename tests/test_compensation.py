"""Friction compensators in the sampled loop, the motion profiles and the measurement options.

References are independent of the code under test: closed forms (the Dahl branch, the S-curve
duration, the SPR boundary of a PD loop), scipy integrations written from the papers'
equations, python-control's own discrete responses, and a scipy replay of the recorded force.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import controllers
from prefriction.signals import PointToPoint, Sine

M, SIGMA, FC, TS = 1.0, 1e6, 1.0, 1e-4
SINE = Sine(5e-6, 1.0, phase=-math.pi / 2, offset=5e-6)


def stage(model=None):
    return pf.Oscillator(model or pf.Dahl(sigma=SIGMA, Fc=FC), mass=M)


@pytest.fixture(scope="module")
def pid():
    return controllers.design_pid(stage(), wn=2 * math.pi * 150.0)


# --- motion profiles -------------------------------------------------------------------------

@pytest.mark.parametrize("j_max", [None, 0.5])
def test_point_to_point_reaches_the_target_within_its_limits(j_max):
    d, v, a = 1e-5, 2e-4, 5e-3
    move = PointToPoint(d, v_max=v, a_max=a, j_max=j_max, start=0.01, position=2e-6)
    # closed-form durations when every limit is reached: d/v + v/a (+ a/j for the S-curve)
    assert move.duration == pytest.approx(d / v + v / a + (0.0 if j_max is None else a / j_max), rel=1e-12)
    t = np.linspace(0.0, 0.2, 200_001)
    x, vel, acc = move(t), move.velocity(t), move.acceleration(t)
    assert x[0] == 2e-6 and x[-1] == pytest.approx(1.2e-5, rel=1e-12)
    assert np.max(np.abs(vel)) <= v * (1 + 1e-12) and np.max(np.abs(acc)) <= a * (1 + 1e-12)
    np.testing.assert_allclose(np.gradient(x, t)[1:-1], vel[1:-1], atol=1e-3 * v)
    back = PointToPoint(-d, v_max=v, a_max=a, j_max=j_max)
    np.testing.assert_allclose(back(t), -PointToPoint(d, v_max=v, a_max=a, j_max=j_max)(t), rtol=0, atol=1e-20)


def test_short_s_curve_lowers_its_peak_speed():
    move = PointToPoint(1e-7, v_max=2e-4, a_max=5e-3, j_max=0.5)
    t = np.linspace(0.0, move.duration, 20_001)
    assert move(move.duration) == pytest.approx(1e-7, rel=1e-9)
    assert np.max(move.velocity(t)) < 2e-4 and abs(move.velocity(move.duration)) < 1e-12


def test_point_to_point_compiles_once_per_kind():
    import casadi as ca

    a = PointToPoint(1e-5, v_max=2e-4, a_max=5e-3, j_max=0.5)
    b = PointToPoint(-3e-6, v_max=1e-4, a_max=2e-3, j_max=0.1, start=0.2)
    assert a.key == b.key != PointToPoint(1e-5, v_max=2e-4, a_max=5e-3).key
    t, th = ca.SX.sym("t"), ca.SX.sym("th", a.n_params)
    f = ca.Function("f", [t, th], [a.expr(t, th)])
    for sig in (a, b):
        for ti in (0.03, 0.25, 1.0):
            assert float(f(ti, sig.params())) == pytest.approx(sig(ti), rel=1e-12, abs=1e-22)


@pytest.mark.parametrize("kwargs, match", [({"distance": 0.0}, "distance"), ({"v_max": -1.0}, "v_max"),
                                           ({"j_max": 0.0}, "j_max"), ({"start": -1.0}, "start")])
def test_point_to_point_bad_input(kwargs, match):
    args = {"distance": 1e-5, "v_max": 1e-4, "a_max": 1e-3, **kwargs}
    with pytest.raises(ValueError, match=match):
        PointToPoint(**args)


# --- the loop: replay, measurement options -----------------------------------------------------

def _replay(system, u, Ts, n):
    """Dahl stage (3.2) driven by the held forces ``u``: scipy DOP853, restarted at every zero velocity."""
    sigma, Fc, m = system.friction.sigma, system.friction.Fc, system.mass
    y, s, out = np.zeros(3), 0.0, np.empty(n)
    for k in range(n):
        out[k] = y[0]
        t = 0.0
        while t < Ts:
            if y[1] == 0.0:
                acc = u[k] - y[2]
                if abs(acc) <= 1e-13 * Fc:
                    break
                s = math.copysign(1.0, acc)

            def rhs(_t, z, s=s, uk=u[k]):
                return [z[1], (uk - z[2]) / m, sigma * z[1] * max(1.0 - s * z[2] / Fc, 0.0)]

            def stop(_t, z, s=s):
                return s * z[1]

            stop.terminal, stop.direction = True, -1.0
            sol = solve_ivp(rhs, (t, Ts), y, method="DOP853", rtol=1e-12, atol=[1e-22, 1e-18, 1e-15], events=stop)
            y, t = sol.y[:, -1].copy(), sol.t[-1]
            if sol.status == 1:
                y[1] = 0.0
    return out


def test_plant_trajectory_matches_a_replay_of_the_recorded_force(pid):
    comp = controllers.LuGreObserver(pf.LuGre(sigma0=SIGMA, sigma1=0.0, sigma2=0.0, Fc=FC, Fs=FC, vs=1.0), gain=2e3)
    res = controllers.simulate_loop(stage(), pid, SINE, 0.03, Ts=TS, compensator=comp, rtol=1e-11,
                                    quantization=1e-9, noise_rms=1e-9)
    x = _replay(stage(), res.u, TS, len(res.t))
    assert np.max(np.abs(res.x - x)) <= 1e-9 * np.max(np.abs(res.x))


def test_measurement_options(pid):
    q = 5e-9
    res = controllers.simulate_loop(stage(), pid, SINE, 0.02, Ts=TS, quantization=q)
    k = res.measured / q
    np.testing.assert_allclose(k, np.round(k), rtol=0, atol=1e-6)
    assert np.max(np.abs(res.measured - res.x)) <= 0.5 * q * (1 + 1e-9)
    res = controllers.simulate_loop(stage(), pid, SINE, 0.02, Ts=TS, delay=3)
    np.testing.assert_array_equal(res.measured[3:], res.x[:-3])
    res = controllers.simulate_loop(stage(), pid, SINE, 0.2, Ts=TS, noise_rms=2e-9, seed=4)
    noise = res.measured - res.x
    assert 1.9e-9 < np.std(noise) < 2.1e-9
    again = controllers.simulate_loop(stage(), pid, SINE, 0.2, Ts=TS, noise_rms=2e-9, seed=4)
    np.testing.assert_array_equal(again.x, res.x)


def test_bad_options(pid):
    comp = controllers.DisturbanceObserver(bandwidth=1e3)
    for kwargs, exc, match in (({"delay": 9}, ValueError, "delay"), ({"quantization": -1.0}, ValueError, "quantization"),
                               ({"compensator": "ff"}, TypeError, "compensator"),
                               ({"mismatch": (1.2, 0.8)}, ValueError, "mismatch")):
        with pytest.raises(exc, match=match):
            controllers.simulate_loop(stage(), pid, SINE, 0.01, Ts=TS, **kwargs)
    with pytest.raises(ValueError, match="sampled controller"):
        controllers.simulate_loop(stage(), pid, SINE, 0.01, compensator=comp)
    with pytest.raises(ValueError, match="gain"):
        controllers.LuGreObserver(pf.LuGre(sigma0=SIGMA, sigma1=0.0, sigma2=0.0, Fc=FC, Fs=FC, vs=1.0), gain=0.0)
    with pytest.raises(TypeError, match="LuGre"):
        controllers.LuGreObserver(pf.Dahl(sigma=SIGMA, Fc=FC), gain=1.0)
    with pytest.raises(ValueError, match="fast_pole"):
        controllers.FrictionObserver(pf.Dahl(sigma=SIGMA, Fc=FC), pole=100.0, fast_pole=50.0)
    with pytest.raises(ValueError, match="Nyquist"):
        controllers.simulate_loop(stage(), pid, SINE, 0.01, Ts=TS, compensator=controllers.DisturbanceObserver(1e5))


# --- each compensator against an independent implementation -----------------------------------

def test_feedforward_is_the_dahl_branch_along_the_reference(pid):
    """Dahl (3.2) with gamma = 1 along the sampled reference: F = s Fc - (s Fc - F_r) exp(-sigma s (x - x_r) / Fc)
    from the last reversal (x_r, F_r); the force held over [t_k, t_k+1] is m dv/Ts + (F_k + F_k+1) / 2."""
    model = pf.Dahl(sigma=SIGMA, Fc=FC)
    res = controllers.simulate_loop(stage(), pid, SINE, 0.7, Ts=TS, compensator=controllers.Feedforward(model))
    t = res.t
    r = SINE(t)
    w = 2 * math.pi
    vr = 5e-6 * w * np.cos(w * t - math.pi / 2)
    F, s, xr, Fr = np.zeros(len(t)), 0.0, 0.0, 0.0
    for k in range(1, len(t)):
        dx = r[k] - r[k - 1]
        sk = s if dx == 0.0 else math.copysign(1.0, dx)
        if sk != s and s != 0.0:
            xr, Fr = r[k - 1], F[k - 1]
        s = sk
        F[k] = s * FC - (s * FC - Fr) * math.exp(-SIGMA * s * (r[k] - xr) / FC) if s else 0.0
    ff = M * (vr[1:] - vr[:-1]) / TS + 0.5 * (F[:-1] + F[1:])
    np.testing.assert_allclose(res.compensation[:-1], ff, rtol=0, atol=1e-9 * FC)
    assert np.max(np.abs(res.error)) < 1e-12  # the exact model leaves (almost) nothing to the PID


def _interp(t_s, values):
    return lambda t: np.interp(t, t_s, values)


def test_lugre_observer_follows_the_papers_equations(pid):
    """Section V of Canudas de Wit et al. (1995): z^' = v - sigma0 |v| z^ / g(v) - k e, F^ = sigma0 z^ +
    sigma1 z^' + sigma2 v; integrated by scipy with v the encoder velocity of each period and e linear."""
    lg = pf.LuGre(sigma0=SIGMA, sigma1=200.0, sigma2=0.5, Fc=FC, Fs=1.3, vs=1e-4)
    k = 2e3
    res = controllers.simulate_loop(stage(lg), pid, SINE, 0.1, Ts=TS, compensator=controllers.LuGreObserver(lg, k))
    t, y, r = res.t, res.measured, res.reference
    e = _interp(t, y - r)
    z, est = 0.0, [0.0]
    for i in range(1, len(t)):
        v = (y[i] - y[i - 1]) / TS
        g = lg.Fc + (lg.Fs - lg.Fc) * math.exp(-(v / lg.vs) ** 2)
        sol = solve_ivp(lambda tt, zz: [v - lg.sigma0 * abs(v) * zz[0] / g - k * e(tt)], (t[i - 1], t[i]), [z],
                        rtol=1e-12, atol=1e-20)
        z = sol.y[0, -1]
        dz = v - lg.sigma0 * abs(v) * z / g - k * (y[i] - r[i])
        est.append(lg.sigma0 * z + lg.sigma1 * dz + lg.sigma2 * v)
    np.testing.assert_allclose(res.compensation[1:], est[1:], rtol=0, atol=1e-6 * np.max(np.abs(res.F)))


def test_friction_observer_follows_its_equations(pid):
    """xi' = M(t) xi + M(t) L y + B2 u, M = [[-l1, -1/m], [sigma - l2, -sigma |x2^| / Fc]], x3^ = xi2 + l2 y:
    scipy with y linear between the samples and u held; the loop's trapezoidal rule agrees to O((Ts p)^2)."""
    obs = controllers.FrictionObserver(pf.Dahl(sigma=SIGMA, Fc=FC), pole=300.0)
    res = controllers.simulate_loop(stage(), pid, SINE, 0.1, Ts=TS, compensator=obs)
    l1, l2 = obs.gains(M)
    t, y, u = res.t, res.measured, res.u
    ys = _interp(t, y)

    def rhs(tt, xi, uk):
        yy = ys(tt)
        x2 = xi[0] + l1 * yy
        Mt = np.array([[-l1, -1.0 / M], [SIGMA - l2, -SIGMA * abs(x2) / FC]])
        return Mt @ xi + Mt @ np.array([l1, l2]) * yy + np.array([uk / M, 0.0])

    xi, est = np.zeros(2), [0.0]
    for i in range(1, len(t)):
        xi = solve_ivp(rhs, (t[i - 1], t[i]), xi, args=(u[i - 1],), rtol=1e-11, atol=1e-14).y[:, -1]
        est.append(xi[1] + l2 * y[i])
    scale = np.max(np.abs(res.F))
    assert np.max(np.abs(res.compensation - est)) <= 3e-3 * scale


def test_disturbance_observer_is_pythons_control_discretisation(pid):
    """F^ = Q (u - m s^2 y), Q = w^2 / (s + w)^2: python-control's ZOH discretisation of each channel
    (``control.c2d``), simulated with ``control.forced_response`` on the recorded u and y."""
    w = 2 * math.pi * 300
    res = controllers.simulate_loop(stage(), pid, SINE, 0.05, Ts=TS, compensator=controllers.DisturbanceObserver(w))
    t, y, u = res.t, res.measured, res.u
    Qu = control.c2d(control.tf([w * w], [1, 2 * w, w * w]), TS, "zoh")
    Qy = control.c2d(control.tf([-M * w * w, 0, 0], [1, 2 * w, w * w]), TS, "zoh")
    est = control.forced_response(Qu, t, u).outputs + control.forced_response(Qy, t, y).outputs
    np.testing.assert_allclose(res.compensation, est, rtol=0, atol=1e-9 * np.max(np.abs(res.F)))


# --- convergence and the gain condition --------------------------------------------------------

def test_lugre_observer_estimation_error_goes_to_zero(pid):
    """Nominal LuGre stage starting with a bristle force the observer does not know (0.5 N): the
    error z~ decays at the rate sigma0 |v| / g(v) while the stage moves (section V)."""
    lg = pf.LuGre(sigma0=SIGMA, sigma1=200.0, sigma2=0.0, Fc=FC, Fs=1.3, vs=1e-4)
    res = controllers.simulate_loop(stage(lg), pid, SINE, 1.0, Ts=TS, compensator=controllers.LuGreObserver(lg, 2e3),
                                    F0=0.5)
    err = np.abs(res.compensation - res.F)
    windows = [np.max(err[(res.t > a) & (res.t <= a + 0.2)]) for a in (0.0, 0.2, 0.4, 0.6, 0.8)]
    assert windows[0] > 0.45 and all(b < a for a, b in zip(windows, windows[1:])) and windows[-1] < 1e-2 * windows[0]


def test_friction_observer_estimation_error_goes_to_zero(pid):
    """Nominal Dahl stage starting with 0.5 N of friction: the error decays to a floor that is the
    sampling's (it halves with Ts): e' = M(t) e goes to zero in continuous time."""
    obs = controllers.FrictionObserver(pf.Dahl(sigma=SIGMA, Fc=FC), pole=300.0)
    floors = []
    for Ts in (TS, TS / 2):
        res = controllers.simulate_loop(stage(), pid, SINE, 0.5, Ts=Ts, compensator=obs, F0=0.5)
        err = np.abs(res.compensation - res.F)
        assert err[1] > 0.45
        floors.append(np.max(err[res.t > 0.2]))
    assert floors[0] < 2e-2 * 0.5 and 0.4 < floors[1] / floors[0] < 0.6


def test_lugre_gain_condition_matches_the_spr_boundary_of_a_pd_loop():
    """H = (sigma1 s + sigma0) / (m s^2 + kd s + kp): Re H(jw) has the sign of sigma0 kp + (sigma1 kd - m sigma0) w^2,
    so H is SPR iff sigma1 kd >= m sigma0 (kp > 0)."""
    lg = pf.LuGre(sigma0=SIGMA, sigma1=200.0, sigma2=0.0, Fc=FC, Fs=1.3, vs=1e-4)
    obs = controllers.LuGreObserver(lg, gain=1e3)
    boundary = M * SIGMA / lg.sigma1
    ok, low = obs.gain_condition(control.tf([1.2 * boundary, 2e6], [1]), mass=M)
    assert ok and low > 0.0
    ok, low = obs.gain_condition(control.tf([0.8 * boundary, 2e6], [1]), mass=M)
    assert not ok and low < 0.0
    no_damping = controllers.LuGreObserver(pf.LuGre(sigma0=SIGMA, sigma1=0.0, sigma2=0.0, Fc=FC, Fs=FC, vs=1.0), 1e3)
    assert not no_damping.gain_condition(control.tf([1e5, 2e6], [1]), mass=M)[0]


def test_ruderman_eigenvalues_stay_real_and_negative_up_to_max_velocity():
    obs = controllers.FrictionObserver(pf.Dahl(sigma=SIGMA, Fc=FC), pole=300.0, fast_pole=5e3)
    l1, l2 = obs.gains(M)
    vmax = obs.max_velocity()
    for v in np.linspace(0.0, vmax, 50):
        lam = np.linalg.eigvals(np.array([[-l1, -1 / M], [SIGMA - l2, -SIGMA * v / FC]]))
        assert np.all(np.abs(lam.imag) <= 1e-6 * np.abs(lam.real)) and np.all(lam.real < 0)
    lam = np.linalg.eigvals(np.array([[-l1, -1 / M], [SIGMA - l2, -SIGMA * 1.5 * vmax / FC]]))
    assert np.any(np.abs(lam.imag) > 0)
    np.testing.assert_allclose(sorted(-np.linalg.eigvals(np.array([[-l1, -1 / M], [SIGMA - l2, 0.0]])).real), [300.0, 5e3])


def test_mismatch_scales_the_compensators_model(pid):
    res = controllers.simulate_loop(stage(), pid, SINE, 0.01, Ts=TS, mismatch=(1.2, 0.8),
                                    compensator=controllers.Feedforward(pf.Dahl(sigma=SIGMA, Fc=FC)))
    assert res.compensator.model.sigma == pytest.approx(1.2 * SIGMA) and res.compensator.model.Fc == pytest.approx(0.8)


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_example_script(tmp_path):
    """examples/compensation.py (quick): the figure exists; the exact-model feedforward leaves under
    1e-3 of PID alone's reversal spike, and a 20 % wrong model still cuts it (the bench's targets)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "compensation.py"
    spec = importlib.util.spec_from_file_location("compensation_example", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = mod.main(tmp_path, quick=True)
    assert out["path"].exists()
    e = out["errors"]
    pid_spike = e[("nominal", "PID alone")]["spike"]
    assert 1e-9 < pid_spike < 1e-7
    assert e[("nominal", "feedforward")]["spike"] < 1e-3 * pid_spike
    assert e[("mismatch", "feedforward")]["spike"] < pid_spike / 3


def test_force_limit_applies_to_the_total_force(pid):
    """A PID with u_max clips controller plus compensation; the replayed plant sees the clipped force."""
    limited = controllers.PID(kp=pid.kp, ki=pid.ki, kd=pid.kd, tau=pid.tau, u_max=0.9)
    res = controllers.simulate_loop(stage(), limited, SINE, 0.4, Ts=TS,
                                    compensator=controllers.Feedforward(pf.Dahl(sigma=SIGMA, Fc=FC)))
    assert np.max(np.abs(res.u)) <= 0.9 * (1 + 1e-15) and np.any(np.abs(res.u) >= 0.9 * (1 - 1e-12))


def test_callable_reference_with_a_compensator(pid):
    """A plain Python callable: its velocity from central differences of the samples (second order)."""
    res = controllers.simulate_loop(stage(), pid, lambda t: float(SINE(t)), 0.05, Ts=TS,
                                    compensator=controllers.Feedforward(pf.Dahl(sigma=SIGMA, Fc=FC)))
    same = controllers.simulate_loop(stage(), pid, SINE, 0.05, Ts=TS,
                                     compensator=controllers.Feedforward(pf.Dahl(sigma=SIGMA, Fc=FC)))
    np.testing.assert_allclose(res.x, same.x, rtol=0, atol=1e-6 * 5e-6)
