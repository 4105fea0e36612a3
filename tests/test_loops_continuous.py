"""Continuous positioning loops with a force limit: clipped PID force and back-calculation anti-windup.

Reference: an independent closed-loop ODE of the Dahl stage (3.2) with gamma = 1 and the
saturated PID, written here from the controller's formula (not from its state-space form):

    x' = v,  m v' = u - F,  F' = sigma v (1 - s F / Fc),
    xi' = e + k_aw (u - w),  xf' = (e - xf) / tau,
    w = kp e + ki xi + kd (e - xf) / tau,  u = clip(w, -u_max, u_max),  e = r(t) - x,

integrated by scipy DOP853 at rtol 1e-12 with a restart at every zero velocity (reversal, touch or
rest, decided by the net force), at every switch of the clip and at every sample time of the
piecewise-linear reference. Nothing of ``prefriction.simulation`` is used in it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from prefriction import controllers
import prefriction
from prefriction.controllers.example_stage import stage
from prefriction.simulation.feedback import LinearFeedback

REST = 1e-12  # net force [N] below which a mass at zero velocity rests (far below the loop's forces)


def _design() -> controllers.PID:
    """The continuous PID of examples/stage_pid.py (150 Hz, zeta = 0.7) on the example stage."""
    return controllers.design_pid(stage(), wn=2 * np.pi * 150.0, zeta=0.7, alpha=1.0)


def _limited(u_max: "float | None") -> controllers.PID:
    d = _design()
    return controllers.PID(kp=d.kp, ki=d.ki, kd=d.kd, tau=d.tau, u_max=u_max)


def _reference_loop(pid: controllers.PID, u_max: float, k_aw: float, ref: tuple, t: np.ndarray,
                    rtol: float = 1e-12) -> tuple[np.ndarray, int]:
    """Positions [m] at ``t`` (from rest at x = 0, F = 0, zero controller states) and the number
    of reversals of the loop above, on the stage m = 1 kg, sigma = 1e6 N/m, Fc = 1 N."""
    m, sigma, Fc = 1.0, 1e6, 1.0
    kp, ki, kd, tau = pid.kp, pid.ki, pid.kd, pid.tau
    tr, rr = ref
    scale = np.array([Fc / sigma, Fc / math.sqrt(m * sigma), Fc, 1e-9, 1e-6])
    atol = rtol * 1e-3 * scale

    def w_of(tt, y):
        e = np.interp(tt, tr, rr) - y[0]
        return kp * e + ki * y[3] + kd * (e - y[4]) / tau, e

    def u_of(tt, y, mode):
        w, e = w_of(tt, y)
        return (w if mode == 0 else mode * u_max), w, e

    out = np.empty(len(t))
    y, tt, T = np.zeros(5), 0.0, float(t[-1])
    w0 = w_of(0.0, y)[0]
    mode = 0 if abs(w0) <= u_max else int(math.copysign(1.0, w0))  # clip: 0 inside, +-1 at the limit
    s, nrev, stuck = 0.0, 0, 0  # branch direction (0: at rest)
    while tt < T:
        if s == 0.0:
            a = u_of(tt, y, mode)[0] - y[2]
            if abs(a) > REST:
                s = math.copysign(1.0, a)
        moving = s != 0.0

        def rhs(t_, z, s=s, mode=mode, moving=moving):
            u, w, e = u_of(t_, z, mode)
            ctrl = [e + k_aw * (u - w), (e - z[4]) / tau]
            if not moving:
                return [0.0, 0.0, 0.0, *ctrl]
            return [z[1], (u - z[2]) / m, sigma * z[1] * (1.0 - s * z[2] / Fc), *ctrl]

        def zero_v(_t, z, s=s):
            return s * z[1]

        def rest_end(t_, z, mode=mode):
            return abs(u_of(t_, z, mode)[0] - z[2]) - REST

        def upper(t_, z):
            return w_of(t_, z)[0] - u_max

        def lower(t_, z):
            return w_of(t_, z)[0] + u_max

        zero_v.terminal = rest_end.terminal = upper.terminal = lower.terminal = True
        zero_v.direction, rest_end.direction = -1.0, 1.0
        upper.direction = 1.0 if mode == 0 else -1.0  # entering, or leaving the upper limit
        lower.direction = -1.0 if mode == 0 else 1.0
        events = [zero_v if moving else rest_end] + ([upper] if mode >= 0 else []) + ([lower] if mode <= 0 else [])
        t_stop = min([T] + [b for b in tr if b > tt * (1 + 1e-14)])
        sol = solve_ivp(rhs, (tt, t_stop), y, method="DOP853", rtol=rtol, atol=atol, events=events, dense_output=True)
        if sol.t[-1] <= tt and sol.t_events[0].size:  # at equilibrium, within round-off:
            # the speed decayed into it (the mass rests), or the rest ends at once (it moves)
            y[1], s, stuck = 0.0, (math.copysign(1.0, u_of(tt, y, mode)[0] - y[2]) if s == 0.0 else 0.0), stuck + 1
            assert stuck < 100, f"no progress at t = {tt} s"
            continue
        assert sol.success and sol.t[-1] > tt, sol.message
        sel = (t >= tt) & (t <= sol.t[-1])
        if sel.any():
            out[sel] = sol.sol(t[sel])[0]
        y, tt = sol.y[:, -1].copy(), float(sol.t[-1])
        for ev, te in zip(events, sol.t_events):
            if te.size and ev in (upper, lower):  # a switch of the clip
                mode = 0 if mode != 0 else (1 if ev is upper else -1)
        if moving and sol.t_events[0].size:  # zero velocity: reversal, touch or rest
            y[1] = 0.0
            sa = s * (u_of(tt, y, mode)[0] - y[2])
            if sa < -REST:
                s, nrev = -s, nrev + 1
            elif sa <= REST:
                s = 0.0
    return out, nrev


# 1 um, then -1 um from 8 ms on (a 1 us ramp): the clip binds at +u_max and at -u_max
JUMP = (np.array([0.0, 0.008, 0.008 + 1e-6, 1.0]), np.array([1e-6, 1e-6, -1e-6, -1e-6]))
STEP = 1e-6


@pytest.mark.parametrize("u_max, rtol", [(1.5, 1e-9), (2.0, 1e-7)])
def test_saturated_pid_matches_the_scipy_reference(u_max, rtol):
    pid = _limited(u_max)
    k_aw = float(pid.back_calculation_gain()[0])
    t = np.linspace(0.0, 0.02, 401)
    res = controllers.simulate_loop(stage(), pid, JUMP, 0.02, t_out=t, rtol=rtol)
    x_ref, n_ref = _reference_loop(pid, u_max, k_aw, JUMP, t)
    assert np.max(np.abs(res.x - x_ref)) <= 10 * rtol * STEP
    assert len(res.reversals) == n_ref >= 2
    # the limit binds on both sides, and the applied force is the clipped PID law of the states
    assert res.u.max() == pytest.approx(u_max, rel=1e-14) and res.u.min() == pytest.approx(-u_max, rel=1e-14)
    xi, xf = res.xc[:, 0], res.xc[:, 1]
    w = pid.kp * res.error + pid.ki * xi + pid.kd * (res.error - xf) / pid.tau
    np.testing.assert_allclose(res.u, np.clip(w, -u_max, u_max), rtol=0, atol=1e-9 * u_max)
    # the anti-windup term is seen: without it the reference moves by far more than the tolerance
    x_wind, _ = _reference_loop(pid, u_max, 0.0, JUMP, t, rtol=1e-9)
    assert np.max(np.abs(x_wind - x_ref)) > 1e-3 * STEP


def test_limit_that_never_binds_gives_the_linear_loop():
    t = np.linspace(0.0, 0.02, 201)
    linear = controllers.simulate_loop(stage(), _limited(None), JUMP, 0.02, t_out=t, rtol=1e-9)
    peak = np.max(np.abs(linear.u))
    loose = controllers.simulate_loop(stage(), _limited(2.0 * peak), JUMP, 0.02, t_out=t, rtol=1e-9)
    for name in ("x", "v", "F", "u", "xc"):
        np.testing.assert_array_equal(getattr(loose, name), getattr(linear, name))
    np.testing.assert_array_equal(loose.reversals.t, linear.reversals.t)
    # and the linear loop is the reference without a limit
    x_ref, _ = _reference_loop(_design(), math.inf, 0.0, JUMP, t)
    assert np.max(np.abs(linear.x - x_ref)) <= 10 * 1e-9 * STEP


def test_linear_feedback_with_a_limit_in_simulate():
    """simulate with a LinearFeedback(u_max, k_aw): the same run as simulate_loop's."""
    pid = _limited(1.5)
    C = pid.ss()
    fb = LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, reference=JUMP, u_max=1.5, k_aw=pid.back_calculation_gain())
    t = np.linspace(0.0, 0.01, 101)
    sim = prefriction.simulate(stage(), 0.0, t_end=0.01, dense=t, feedback=fb, rtol=1e-9)
    loop = controllers.simulate_loop(stage(), pid, JUMP, 0.01, t_out=t, rtol=1e-9)
    np.testing.assert_array_equal(sim.x, loop.x)
    np.testing.assert_array_equal(sim.u, loop.u)
    assert np.max(np.abs(sim.u)) == pytest.approx(1.5, rel=1e-14)


def test_bad_force_limits_are_refused():
    C = _design().ss()
    mats = dict(A=C.A, B=C.B, C=C.C, D=C.D)
    for bad in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(ValueError, match=r"u_max must be finite and > 0, got .*0 < u_max < inf"):
            controllers.PID(kp=1e6, ki=1e8, u_max=bad)
        with pytest.raises(ValueError, match=r"u_max must be finite and > 0"):
            LinearFeedback(**mats, u_max=bad)
    with pytest.raises(TypeError, match="u_max must be a real number, got '2'"):
        LinearFeedback(**mats, u_max="2")
    with pytest.raises(ValueError, match=r"k_aw must be a vector of length n = 2 \(the controller states of A\), got \[1.0\]"):
        LinearFeedback(**mats, u_max=2.0, k_aw=[1.0])
    with pytest.raises(ValueError, match=r"k_aw\[1\] must be finite .* \[1/\(N s\)\], got nan"):
        LinearFeedback(**mats, u_max=2.0, k_aw=[1.0, math.nan])
    with pytest.raises(TypeError, match=r"k_aw must be a real number or an array of finite real numbers"):
        LinearFeedback(**mats, u_max=2.0, k_aw="fast")
    with pytest.raises(ValueError, match=r"k_aw=\[1.0, 0.0\] needs a force limit u_max"):
        LinearFeedback(**mats, k_aw=[1.0, 0.0])
    Cd = _design().c2d(1e-4)
    with pytest.raises(ValueError, match=r"u_max and k_aw are for continuous controllers \(Ts=None\), got Ts=0.0001"):
        LinearFeedback(A=Cd.A, B=Cd.B, C=Cd.C, D=Cd.D, Ts=1e-4, u_max=2.0)


def test_settling_loop_comes_to_rest_at_equilibrium():
    """A continuous PID settles; its speed decays into the integration error near t = 0.07 s
    (this run failed there with "a reversal pair inside one step"): the mass rests at r."""
    t = np.linspace(0.0, 0.1, 1001)
    res = controllers.simulate_loop(stage(), _design(), STEP, 0.1, t_out=t, rtol=1e-10)
    window = t <= 0.05
    x_ref, n_ref = _reference_loop(_design(), math.inf, 0.0, (np.array([0.0, 1.0]), np.array([STEP, STEP])), t[window])
    assert np.max(np.abs(res.x[window] - x_ref)) <= 10 * 1e-10 * STEP
    assert len(res.reversals) == n_ref
    assert abs(res.x[-1] - STEP) <= 1e-9 * STEP and abs(res.v[-1]) <= 1e-12
