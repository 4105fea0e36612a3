"""The compiled sampled-data loop (prefriction.simulation.loops) behind controllers.simulate_loop.

References independent of the compiled loop: the Python per-sample loop of
``prefriction.simulate`` with a sampled ``LinearFeedback`` (the path sampled loops took before),
and ``controllers.zoh_reference`` (scipy DOP853 with restarts at every zero velocity, the
controller stepped by hand).
"""

from __future__ import annotations

import numpy as np
import pytest

from prefriction import controllers
import prefriction
from prefriction.controllers.zoh_reference import zoh_reference
from prefriction.simulation.feedback import MAX_SAMPLES, LinearFeedback
from prefriction.simulation.loops import BLOCK

TS = 1e-4
STEP = 1e-6


def stage(mass=1.0):
    return prefriction.Oscillator(prefriction.Dahl(sigma=1e6, Fc=1.0), mass=mass)


def pid():
    return controllers.design_pid(stage(), wn=2 * np.pi * 150.0, zeta=0.7).c2d(TS)


def python_loop(system, Cd, r, t_end, Ts, rtol=1e-8):
    """The per-sample Python loop of prefriction.simulate."""
    fb = LinearFeedback(A=Cd.A, B=Cd.B, C=Cd.C, D=Cd.D, Ts=Ts, reference=r)
    return prefriction.simulate(system, 0.0, t_end=t_end, rtol=rtol, feedback=fb)


def test_agrees_with_the_python_loop_over_several_blocks(monkeypatch):
    from prefriction.simulation.loops import runner

    monkeypatch.setattr(runner, "NATIVE_BLOCK", 128)  # the native loop's blocks: several here too
    res = controllers.simulate_loop(stage(), pid(), STEP, 0.03)
    assert len(res.t) > BLOCK and res.loop_stats.blocks >= 2
    old = python_loop(stage(), pid(), STEP, 0.03, TS)
    np.testing.assert_allclose(res.t, old.t, rtol=0, atol=1e-15)
    # two integrations at rtol 1e-8 (the native loop carries its step size over the periods)
    assert np.max(np.abs(res.x - old.x)) <= 1e-8 * STEP
    assert np.max(np.abs(res.u - old.u)) <= 1e-8 * np.max(np.abs(old.u))
    assert len(res.reversals) == len(old.reversals) >= 2
    np.testing.assert_allclose(res.reversals.t, old.reversals.t, rtol=1e-8)
    np.testing.assert_allclose(res.reversals.F, old.reversals.F, rtol=1e-8)


def test_tight_tolerance_against_independent_zoh_reference():
    res = controllers.simulate_loop(stage(), pid(), STEP, 0.02, rtol=1e-11)
    x_ref = zoh_reference(stage(), pid(), np.full(len(res.t), STEP), TS)
    assert np.max(np.abs(res.x - x_ref)) <= 1e-9 * STEP


def test_resting_periods_are_skipped():
    """The mass rests (r = x0 = 0, no force) until the reference steps at 10 ms: those periods
    are not integrated, and the result is that of the Python loop, which integrates every period."""
    r = (np.array([0.0, 0.00995, 0.01005, 1.0]), np.array([0.0, 0.0, STEP, STEP]))
    res = controllers.simulate_loop(stage(), pid(), r, 0.02)
    st = res.loop_stats
    assert st.integrated <= st.samples - 1 - 100
    assert np.all(res.x[:101] == 0.0) and res.x[-1] > 0.5 * STEP
    old = python_loop(stage(), pid(), r, 0.02, TS)
    assert np.max(np.abs(res.x - old.x)) <= 1e-8 * STEP  # two integrations at rtol 1e-8


def test_periods_with_many_reversals_are_finished_in_python():
    """A light stage (free oscillation period 63 us) under P control sampled at 1 kHz reverses
    about 30 times per period (the linear check warns: the pre-sliding linearisation has no
    damping; the Dahl hysteresis damps the motion)."""
    light = stage(mass=1e-4)
    Cd = controllers.PID(kp=1e4).c2d(1e-3)
    with pytest.warns(controllers.UnstableLoopWarning):
        res = controllers.simulate_loop(light, Cd, STEP, 0.01)
    if res.loop_stats.jit != "interpreted" and res.simulation.stats.steps is not None:
        assert res.loop_stats.finished_in_python == 0  # the native loop holds any number per period
    else:
        assert res.loop_stats.finished_in_python >= 5
    old = python_loop(light, Cd, STEP, 0.01, 1e-3)
    assert np.max(np.abs(res.x - old.x)) <= 1e-9 * STEP
    assert len(res.reversals) == len(old.reversals) > 100
    np.testing.assert_allclose(res.reversals.t, old.reversals.t, rtol=1e-9)


def test_gain_sweep_compiles_nothing_new():
    system = stage()
    controllers.simulate_loop(system, pid(), STEP, 0.002)
    for wn in (120.0, 180.0):
        Cd = controllers.design_pid(system, wn=2 * np.pi * wn, zeta=0.7).c2d(TS)
        st = controllers.simulate_loop(system, Cd, STEP, 0.002).loop_stats
        assert st.setup_time == 0.0 and st.jit in ("cached", "interpreted")


def test_sample_count_limit():
    with pytest.raises(ValueError, match=rf"at most {MAX_SAMPLES - 1} are allowed \(MAX_SAMPLES"):
        controllers.simulate_loop(stage(), controllers.pd(2e6, 2000.0), STEP, 0.01, Ts=1e-12)
    with pytest.raises(ValueError, match="MAX_SAMPLES"):
        controllers.simulate_loop(stage(), controllers.pd(2e6, 2000.0).c2d(1e-300), STEP, 0.01)


def test_loop_result_reads():
    res = controllers.simulate_loop(stage(), pid(), STEP, 0.02)
    assert res.settling_time == res.settling_time_within(0.02)
    assert res.settling_time_within(0.5) <= res.settling_time
    assert repr(res).startswith("LoopResult(sampled") and "reversals" in repr(res)
    assert "us per sample" in res.loop_stats.summary()
