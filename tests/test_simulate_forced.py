"""simulate() with an input force and in closed loop, against linear closed forms.

With ``Fc`` huge the Dahl force is the linear spring ``F = sigma x`` (to ``|F| / Fc``), so the
forced oscillator and the loops are linear systems with closed-form or python-control responses.
"""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pytest
import scipy.linalg as sla

import prefriction as pf
from prefriction.signals import Sine
from prefriction.simulation.feedback import LinearFeedback

K_SPRING, MASS, FC_HUGE = 1e4, 2.0, 1e12


def spring_system(u=None) -> pf.Oscillator:
    return pf.Oscillator(pf.Dahl(K_SPRING, FC_HUGE), mass=MASS, u=u)


def test_sinusoidal_input_matches_closed_form() -> None:
    """m x'' + k x = A sin(w t): homogeneous plus particular solution."""
    A, v0 = 3.0, 0.01
    f = 50.0 / (2.0 * math.pi)  # [Hz]
    w = 2.0 * math.pi * f  # the signal's angular frequency, bit for bit (Sine evaluates 2 pi f t)
    w0 = math.sqrt(K_SPRING / MASS)
    t = np.linspace(0.0, 0.5, 201)
    res = pf.simulate(spring_system(Sine(A, f)), v0, t_end=0.5, dense=t, rtol=1e-10)
    xp = A / (MASS * (w0**2 - w**2))
    x = (v0 - xp * w) / w0 * np.sin(w0 * t) + xp * np.sin(w * t)
    v = (v0 - xp * w) * np.cos(w0 * t) + xp * w * np.cos(w * t)
    scale = np.max(np.abs(x))
    assert np.max(np.abs(res.x - x)) <= 1e-8 * scale
    assert np.max(np.abs(res.v - v)) <= 1e-8 * np.max(np.abs(v))
    np.testing.assert_allclose(res.u, A * np.sin(w * t), rtol=0, atol=1e-12)
    # reversals are the zeros of v: check against the closed form between grid points
    for tr in res.reversals.t:
        vr = (v0 - xp * w) * np.cos(w0 * tr) + xp * w * np.cos(w * tr)
        assert abs(vr) <= 1e-8 * np.max(np.abs(v))


def test_sampled_input_matches_python_control() -> None:
    """Samples (t, u) are linear between samples, like python-control's forced_response."""
    ts = np.linspace(0.0, 0.3, 31)
    us = 2.0 * np.cos(37.0 * ts) + np.where(ts > 0.1, 1.5, 0.0)
    res = pf.simulate(spring_system((ts, us)), 0.0, t_end=0.3, dense=ts, rtol=1e-10)
    lin = ct.ss([[0, 1], [-K_SPRING / MASS, 0]], [[0], [1 / MASS]], [[1, 0]], [[0]])
    tf = np.linspace(0.0, 0.3, 30001)  # forced_response is exact for linear-in-time inputs
    ref = ct.forced_response(lin, T=tf, U=np.interp(tf, ts, us))
    x_ref = np.interp(ts, tf, ref.outputs)
    assert np.max(np.abs(res.x - x_ref)) <= 1e-6 * np.max(np.abs(x_ref))


def test_velocity_touching_zero_is_not_a_reversal() -> None:
    """x = t - sin t: v = 1 - cos t touches 0 at t = 2 pi without changing sign.

    m x'' + k x = u with x = X (t/T - sin(t/T)), T = sqrt(m/k): the inertial and the spring terms
    in sin(t/T) cancel, so u = k X t/T, a ramp from rest (x(0) = v(0) = 0): two samples, linear.
    """
    T = 1.0 / math.sqrt(K_SPRING / MASS)  # time unit; x(t) = X (t/T - sin(t/T))
    X = 1e-3
    t_end = 4.5 * math.pi * T
    u = (np.array([0.0, t_end]), np.array([0.0, K_SPRING * X * t_end / T]))
    res = pf.simulate(spring_system(u), X / T * 0.0, t_end=t_end, dense=np.linspace(0, t_end, 50),
                      rtol=1e-10)
    assert len(res.reversals) == 0
    s = res.t / T
    assert np.max(np.abs(res.x - X * (s - np.sin(s)))) <= 1e-8 * X * 4.5 * math.pi


def test_rest_is_recognised() -> None:
    """v0 = 0 with u = F0: the mass rests (no reversals, no motion) until the input changes."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0), u=(np.array([0.0, 1.0, 1.5, 3.0]), np.array([0.3, 0.3, 0.5, 0.5])))
    res = pf.simulate(sys_, 0.0, F0=0.3, t_end=3.0, dense=np.linspace(0, 3.0, 61), rtol=1e-9)
    before = res.t <= 1.0
    assert np.all(res.x[before] == 0.0) and np.all(res.v[before] == 0.0)
    assert np.max(res.x) > 0  # moves once u exceeds F
    assert np.all(np.diff(res.reversals.t) > 1e-3)  # no chattering pairs
    still = pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), u=0.3), 0.0, F0=0.3, t_end=10.0)
    assert len(still.reversals) == 0 and still.stats.calls < 10


def test_forced_energy_balance_uses_input_work() -> None:
    """E_d[k] = E_p[k-1] + W_u[k] - E_p[k]; W_u against the trapezoid of u v on dense samples."""
    sys_ = pf.Oscillator(pf.Dahl(1e3, 1.0), mass=1.0, u=Sine(0.4, 3.0 / (2.0 * math.pi)))
    t = np.linspace(0.0, 20.0, 200_001)
    res = pf.simulate(sys_, 0.05, t_end=20.0, dense=t, rtol=1e-10)
    tab = res.reversals
    assert len(tab) >= 3
    W = np.concatenate([[0.0], np.cumsum(0.5 * (res.u[1:] * res.v[1:] + res.u[:-1] * res.v[:-1]) * np.diff(t))])
    Wr = np.interp(tab.t, t, W)
    np.testing.assert_allclose(res.work_input[1:], np.diff(Wr), rtol=0, atol=1e-6 * np.max(np.abs(W)))
    np.testing.assert_allclose(tab.E_d[1:], tab.E_p[:-1] + res.work_input[1:] - tab.E_p[1:], rtol=1e-12)
    # energy balance of the whole run: input work = kinetic + friction work (integrated power)
    np.testing.assert_allclose(W[-1], res.E_k[-1] - res.E_k[0] + res.E_f[-1], rtol=1e-6)


def _ss_step(Acl: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """States of z' = Acl z + b, z(0) = 0, at times t (matrix exponential of the augmented system)."""
    n = len(b)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = Acl, b
    return np.array([sla.expm(M * ti)[:n, n] for ti in t])


def test_continuous_pi_loop_matches_matrix_exponential() -> None:
    kp, ki, r0 = 3e4, 2e5, 1e-3
    fb = LinearFeedback(A=[[0.0]], B=[[1.0]], C=[[ki]], D=kp, reference=r0)
    t = np.linspace(0.0, 0.2, 41)
    res = pf.simulate(spring_system(), 0.0, t_end=0.2, dense=t, feedback=fb, rtol=1e-10)
    Acl = np.array([[0, 1, 0], [-(kp + K_SPRING) / MASS, 0, ki / MASS], [-1, 0, 0]])
    Z = _ss_step(Acl, np.array([0.0, kp * r0 / MASS, r0]), t)
    assert np.max(np.abs(res.x - Z[:, 0])) <= 1e-8 * np.max(np.abs(Z[:, 0]))
    assert np.max(np.abs(res.xc[:, 0] - Z[:, 2])) <= 1e-8 * np.max(np.abs(Z[:, 2]))
    np.testing.assert_allclose(res.u, ki * Z[:, 2] + kp * (r0 - Z[:, 0]), rtol=0, atol=1e-7 * np.max(np.abs(res.u)))


def test_sampled_loop_matches_zero_order_hold_discretisation() -> None:
    """xc[k+1] = A xc + B e, u = C xc + D e held over Ts: python-control's c2d of the plant."""
    Ts, r0 = 1e-3, 1e-3
    fb = LinearFeedback(A=[[1.0]], B=[[Ts * 2e5]], C=[[1.0]], D=3e4, Ts=Ts, reference=r0)
    res = pf.simulate(spring_system(), 0.0, t_end=0.05, feedback=fb, rtol=1e-10)
    plant = ct.c2d(ct.ss([[0, 1], [-K_SPRING / MASS, 0]], [[0], [1 / MASS]], [[1, 0]], [[0]]), Ts, "zoh")
    z, xc, xs, us = np.zeros(2), 0.0, [], []
    for _ in range(len(res.t)):
        e = r0 - z[0]
        u = xc + 3e4 * e
        xs.append(z[0])
        us.append(u)
        z = np.asarray(plant.A) @ z + np.asarray(plant.B)[:, 0] * u
        xc = xc + Ts * 2e5 * e
    np.testing.assert_allclose(res.t, Ts * np.arange(len(res.t)), rtol=0, atol=1e-15)
    assert len(res.t) == 51
    assert np.max(np.abs(res.x - np.array(xs))) <= 1e-8 * np.max(np.abs(xs))
    assert np.max(np.abs(res.u - np.array(us))) <= 1e-8 * np.max(np.abs(us))


def test_untraceable_input_raises_type_error() -> None:
    with pytest.raises(TypeError, match="u does not trace"):
        spring_system(lambda s: math.sin(s))


def test_rest_ends_when_the_held_force_jumps() -> None:
    """A mass at rest under a sampled controller moves once the held force changes (no stiction)."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0))
    ref = (np.array([0.0, 0.0105, 0.0115, 1.0]), np.array([0.0, 0.0, 1e-4, 1e-4]))  # step at ~0.011 s
    fb = LinearFeedback(D=2e3, Ts=1e-3, reference=ref)
    res = pf.simulate(sys_, 0.0, t_end=0.05, feedback=fb, rtol=1e-9)
    assert np.all(res.x[res.t <= 0.0105] == 0.0)
    assert res.x[-1] > 1e-6  # the reference step moves the mass
    assert np.max(np.abs(res.x)) < 2e-4


def test_continuous_loop_with_sampled_reference_matches_python_control() -> None:
    """u = kp (r - x) with r piecewise linear (samples): python-control's forced_response of the loop."""
    kp = 5e4
    tr = np.linspace(0.0, 0.1, 11)
    rr = 1e-3 * np.minimum(tr / 0.03, 1.0) * (1.0 + 0.2 * np.sin(60.0 * tr))
    fb = LinearFeedback(D=kp, reference=(tr, rr))
    t = np.linspace(0.0, 0.1, 101)
    res = pf.simulate(spring_system(), 0.0, t_end=0.1, dense=t, feedback=fb, rtol=1e-10)
    loop = ct.ss([[0, 1], [-(K_SPRING + kp) / MASS, 0]], [[0], [kp / MASS]], [[1, 0]], [[0]])
    tf = np.linspace(0.0, 0.1, 100_001)
    ref = ct.forced_response(loop, T=tf, U=np.interp(tf, tr, rr))
    x_ref = np.interp(t, tf, ref.outputs)
    assert np.max(np.abs(res.x - x_ref)) <= 1e-6 * np.max(np.abs(x_ref))
    np.testing.assert_allclose(res.u, kp * (np.interp(t, tr, rr) - res.x), rtol=0, atol=1e-9 * kp * 1e-3)


def test_net_force_reversing_within_the_first_step_is_a_reversal() -> None:
    """Start at v = 0 pushed forward by 1 mN, then pulled back by 30 N within 1 us: the velocity turns
    negative before it has grown, so the branch must flip (scipy LSODA on the |v| form as reference)."""
    from scipy.integrate import solve_ivp

    ts, us = np.array([0.0, 1e-6, 1.0]), np.array([0.301, -30.0, -30.0])
    system = pf.Oscillator(pf.Dahl(1.0, 1.0), mass=1.0, u=(ts, us))
    times = np.array([1e-5, 5e-5, 1e-4])
    res = pf.simulate(system, 0.0, F0=0.3, t_end=1e-4, dense=times)

    def rhs(t, y):
        return [y[1], np.interp(t, ts, us) - y[2], y[1] - abs(y[1]) * y[2]]

    ref = solve_ivp(rhs, [0.0, 1e-4], [0.0, 0.0, 0.3], method="LSODA", rtol=1e-12, atol=1e-18,
                    t_eval=times, max_step=1e-7)
    assert len(res.reversals) == 1 and res.reversals.t[0] < 1e-6
    # F moves by about 2e-7 N: on the wrong branch (slope 1 - F instead of 1 + F) it is 46 % off
    np.testing.assert_allclose(0.3 - res.F, 0.3 - ref.y[2], rtol=1e-5)


def test_no_force_on_a_mass_at_rest_keeps_it_at_rest() -> None:
    """u = 0, v0 = 0, F0 = 0: the equilibrium; the mass stays at x = 0 (was: ZeroDivisionError).

    u = 0 as samples (t, 0): the same all-zero force, on the structure of the other sampled inputs."""
    res = pf.simulate(pf.Oscillator(pf.Dahl(1e6, 1.0), u=(np.array([0.0, 1e-3]), np.zeros(2))), 0.0, t_end=1e-3,
                      dense=True)
    assert res.status == 0 and len(res.reversals) == 0 and res.reversals.E_0 == 0.0
    assert np.all(res.x == 0.0) and np.all(res.v == 0.0) and np.all(res.F == 0.0)
