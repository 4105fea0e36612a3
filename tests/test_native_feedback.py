"""Closed linear feedback (``simulate(..., feedback=LinearFeedback(...))``, continuous controller)
on the native driver against CasADi's integrator (``method="erk"``), a closed form and an
independent scipy integration written from the equations.

The controller's states are integrated with the plant in C (``prefriction/simulation/native/
closed.py``, ``forced.c``), and on while the mass rests; the rest's end and the force limit's
switches are events. Both paths must agree to the run's tolerance: reversal times (to the run's
length), positions (to the largest |x|), controller forces (to Fc) and the dense samples.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.signals import Sine, Step
from prefriction.simulation.compiled import jit_available

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native driver needs a C compiler")

RTOL = 1e-8
BOUND = 20 * RTOL  # two integrations at rtol, each within about rtol of the solution
T_END = 0.4
TD = np.linspace(0.0, T_END, 201)

MODELS = {
    "dahl": pf.Dahl(1e4, 1.0),
    "lugre": pf.LuGre(1e5, 300.0, 0.4, 1.0, 1.5, 1e-3),
    "maxwell_slip": pf.MaxwellSlip([1e4, 2e4, 3e4], [0.3, 0.5, 0.7]),
}


def _pid(kp: float, ki: float, kd: float, tau: float, **kw) -> pf.LinearFeedback:
    """PID with a filtered derivative: states (integral of e, filter of e)."""
    return pf.LinearFeedback([[0.0, 0.0], [0.0, -1.0 / tau]], [[1.0], [1.0 / tau]], [[ki, -kd / tau]],
                             [[kp + kd / tau]], **kw)


LOOPS = {
    "pid_sine": _pid(300.0, 3000.0, 5.0, 1e-3, reference=Sine(2e-3, 5.0)),
    # starts at rest, the reference steps at 0.05 s: the mass leaves the rest at the break
    "pid_step": _pid(300.0, 3000.0, 5.0, 1e-3, reference=Step(0.05, 0.0, 1e-3)),
    # a force limit that binds, with back-calculation anti-windup
    "pd_clip": pf.LinearFeedback([[-1e3]], [[1e3]], [[-5e3]], [[5.4e3]], reference=Sine(5e-3, 4.0), u_max=1.3),
    "pi_aw": pf.LinearFeedback([[0.0]], [[1.0]], [[2000.0]], [[300.0]], reference=Step(0.02, 0.0, 4e-3),
                               u_max=1.25, k_aw=[0.5]),
}


def _compare(model: pf.FrictionModel, fb: pf.LinearFeedback) -> pf.SimulationResult:
    system = pf.Oscillator(model, 1.0)
    kw = dict(t_end=T_END, rtol=RTOL, dense=TD, feedback=fb)
    a = pf.simulate(system, 0.0, method="native", **kw)
    b = pf.simulate(system, 0.0, method="erk", **kw)
    assert a.stats.steps is not None and a.stats.calls == 1  # the native driver ran, in one call
    ta, tb = a.reversals, b.reversals
    assert len(ta) == len(tb)
    if len(tb):
        assert np.max(np.abs(ta.t - tb.t)) <= BOUND * T_END
        assert np.max(np.abs(ta.x - tb.x)) <= BOUND * np.max(np.abs(tb.x))
        assert np.max(np.abs(ta.F - tb.F)) <= BOUND * model.Fc
    assert np.max(np.abs(a.x - b.x)) <= BOUND * np.max(np.abs(b.x))
    assert np.max(np.abs(a.v - b.v)) <= BOUND * np.max(np.abs(b.v))
    assert np.max(np.abs(a.u - b.u)) <= BOUND * model.Fc * 100  # the controller force: D e amplifies x
    assert a.xc.shape == b.xc.shape == (TD.size, fb.n_states)
    np.testing.assert_array_equal(a.v == 0.0, b.v == 0.0)  # the same rests
    return a


@pytest.mark.parametrize("loop", sorted(LOOPS))
def test_native_and_erk_agree_on_feedback_dahl(loop: str) -> None:
    res = _compare(MODELS["dahl"], LOOPS[loop])
    fb = LOOPS[loop]
    if fb.u_max is not None and loop == "pd_clip":  # the limit binds for a while
        assert np.sum(np.abs(res.u) >= fb.u_max * (1 - 1e-12)) >= 5


@pytest.mark.slow
@pytest.mark.parametrize("loop", sorted(LOOPS))
@pytest.mark.parametrize("name", ["lugre", "maxwell_slip"])
def test_native_and_erk_agree_on_feedback(name: str, loop: str) -> None:
    _compare(MODELS[name], LOOPS[loop])


def test_controller_integrates_while_the_mass_rests() -> None:
    """A mass at rest held by the controller's force (``F0 = D r = 0.5 N``), a slow integral
    action ``u = D e + ki xc``, ``xc' = e = r - x``: while the mass rests ``xc = r t`` (closed
    form, the controller integrating with the plant frozen) until ``ki r t`` passes the rest
    threshold (the error level of the net force); the rest, its end and the motion after it as
    CasADi's integrator has them."""
    ki, r, D = 1e-5, 1e-3, 500.0
    fb = pf.LinearFeedback([[0.0]], [[1.0]], [[ki]], [[D]], reference=r)
    system = pf.Oscillator(MODELS["dahl"], 1.0)
    kw = dict(F0=0.5, t_end=T_END, rtol=RTOL, dense=TD, feedback=fb)
    res = pf.simulate(system, 0.0, **kw)
    ref = pf.simulate(system, 0.0, method="erk", **kw)
    assert res.stats.steps is not None and res.stats.calls == 1  # the native driver ran
    resting = res.v == 0.0
    n = int(np.sum(resting))
    assert 10 <= n < TD.size - 10 and np.all(resting[:n])  # a rest at the start, then motion
    np.testing.assert_array_equal(res.x[:n], 0.0)
    np.testing.assert_allclose(res.xc[:n, 0], r * TD[:n], rtol=1e-12, atol=1e-18)  # xc = r t, integrated at rest
    assert np.max(np.abs(res.x)) > 0.0
    np.testing.assert_array_equal(resting, ref.v == 0.0)
    # the motion after the exit starts at the error level: positions to the loop's stroke r
    assert np.max(np.abs(res.x - ref.x)) <= BOUND * r
    assert np.max(np.abs(res.xc - ref.xc)) <= BOUND * np.max(np.abs(ref.xc))


def test_pid_loop_around_dahl_against_scipy() -> None:
    """Dahl (gamma = 1) in a PID loop tracking a sine: reversal times and dense positions against
    ``solve_ivp`` (DOP853, rtol 1e-12) of the equations written here,
    ``x' = v, v' = (u - F) / m, F' = sigma (v - |v| F / Fc)``, ``u = ki xi + kd/tau (e - xf) + kp e``,
    ``xi' = e, xf' = (e - xf) / tau``, ``e = r - x`` (the zeros of v as events)."""
    sigma, Fc, m = 1e4, 1.0, 1.0
    kp, ki, kd, tau = 300.0, 3000.0, 5.0, 1e-3
    ref_sig = Sine(2e-3, 5.0)
    res = pf.simulate(pf.Oscillator(pf.Dahl(sigma, Fc), m), 0.0, t_end=T_END, rtol=RTOL, dense=TD,
                      feedback=_pid(kp, ki, kd, tau, reference=ref_sig))

    def rhs(t, y):
        x, v, F, xi, xf = y
        e = 2e-3 * np.sin(2 * np.pi * 5.0 * t) - x
        u = ki * xi + kd / tau * (e - xf) + kp * e
        return [v, (u - F) / m, sigma * (v - abs(v) * F / Fc), e, (e - xf) / tau]

    def vzero(t, y):
        return y[1]

    sol = solve_ivp(rhs, (0.0, T_END), [0.0] * 5, method="DOP853", rtol=1e-12, atol=1e-16, events=vzero,
                    dense_output=True)
    times = np.array([t for t in sol.t_events[0] if t > 1e-9])
    tab = res.reversals
    assert len(tab) == len(times) >= 3
    assert np.max(np.abs(tab.t - times)) <= 10 * RTOL * T_END
    xs = sol.sol(TD)
    assert np.max(np.abs(res.x - xs[0])) <= 10 * RTOL * np.max(np.abs(xs[0]))
    assert np.max(np.abs(res.xc[:, 0] - xs[3])) <= 10 * RTOL * np.max(np.abs(xs[3]))
