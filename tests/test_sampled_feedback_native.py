"""``simulate(..., feedback=LinearFeedback(..., Ts=))`` on the native sampled loop.

A sampled controller around an oscillator without input force runs in C (the loop driver of
``controllers.simulate_loop``, ``native/loop.c``). References: the CasADi path
(``method="erk"``, one CasADi call per period) to the tolerance on Dahl, LuGre and Maxwell-slip;
and an independent closed loop (tests/_sampled_loop.py): python-control's discrete-time controller
(``StateSpace.dynamics`` / ``output`` of ``PID.c2d``) around ``solve_ivp`` (DOP853, rtol 1e-12)
of the Dahl equations ``x' = v, v' = (u - F) / m, F' = sigma (v - |v| F / Fc)``, the force held
over each sample period.
"""

from __future__ import annotations

import numpy as np
import pytest

import prefriction as pf
from prefriction.signals import Samples, Step, ZeroOrderHold
from prefriction.simulation.compiled import jit_available

from _sampled_loop import MODELS, STROKE, TS, agree, assert_dahl_loop_matches_reference, feedback

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native loop needs a C compiler")

T_END = 0.04  # s


def _agree(a: pf.SimulationResult, b: pf.SimulationResult) -> None:
    """Native ``a`` and CasADi ``b``: same samples, reversals and events to the tolerance (rtol 1e-8)."""
    agree(a, b, T_END)
    np.testing.assert_array_equal(a.events, b.events)
    assert a.stats.events == b.stats.events


@pytest.mark.parametrize("name", sorted(MODELS))
def test_native_and_erk_agree(name: str) -> None:
    """10 kHz PID loop tracking a 5 um sine on each model: native loop and CasADi agree to 1e-8."""
    stage = pf.Oscillator(MODELS[name], 1.0)
    fb, _ = feedback(stage)
    a = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb)
    b = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, method="erk")
    _agree(a, b)
    if name == "maxwell_slip":
        assert a.stats.events > 0  # the elements' stick/slip switches are counted across periods


def test_reversal_stop_keeps_the_samples_up_to_it() -> None:
    """``reversals=2``: both paths stop at the second reversal with the samples up to it."""
    stage = pf.Oscillator(MODELS["lugre"], 1.0)
    fb, _ = feedback(stage)
    a = pf.simulate(stage, 0.0, t_end=T_END, reversals=2, feedback=fb)
    b = pf.simulate(stage, 0.0, t_end=T_END, reversals=2, feedback=fb, method="erk")
    _agree(a, b)
    assert a.status == 1 and len(a.reversals) == 2 and a.t[-1] <= a.reversals.t[-1] < a.t[-1] + TS


def test_start_from_rest_with_a_step_reference_agrees() -> None:
    """The mass at rest, a 2 um step of the reference at 5 ms: it leaves rest at a sample instant."""
    stage = pf.Oscillator(MODELS["dahl"], 1.0)
    fb, _ = feedback(stage, Step(5e-3, 0.0, 2e-6))
    a = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb)
    b = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, method="erk")
    assert np.all(a.x[a.t < 5e-3] == 0.0)
    assert np.max(np.abs(a.x - b.x)) <= 1e-8 * STROKE
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-7 * np.max(np.abs(b.u)))
    assert len(a.reversals) == len(b.reversals)
    np.testing.assert_allclose(a.reversals.t, b.reversals.t, rtol=0, atol=1e-8 * T_END)


@pytest.mark.parametrize("kind", ["zero_order_hold", "samples_and_step"])
def test_input_force_linear_over_each_period_runs_native(kind: str) -> None:
    """A disturbance force whose breaks are sample instants (a zero-order hold of one value per
    2 periods; samples every 4 periods plus a step) joins the held force in C: native and erk
    agree, including the work of the forces per half-cycle."""
    rng = np.random.default_rng(3)
    tu = np.arange(0.0, T_END + 1e-9, 2 * TS)
    if kind == "zero_order_hold":
        u = ZeroOrderHold(tu, 0.2 * rng.standard_normal(tu.size))
    else:
        u = Samples(tu[::2], 0.2 * rng.standard_normal(tu[::2].size)) + Step(150 * TS, 0.0, 0.3)
    stage = pf.Oscillator(MODELS["dahl"], 1.0, u)
    fb, _ = feedback(pf.Oscillator(MODELS["dahl"], 1.0))
    a = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb)
    b = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, method="erk")
    _agree(a, b)
    np.testing.assert_allclose(a.work_input, b.work_input, rtol=0, atol=1e-7 * np.max(np.abs(b.work_input)))


def test_input_force_with_a_break_inside_a_period_runs_native() -> None:
    """A step half-way between two sample instants: the native loop breaks the period at it and
    agrees with CasADi's loop."""
    stage = pf.Oscillator(MODELS["dahl"], 1.0, Step(100.5 * TS, 0.0, 0.3))
    fb, _ = feedback(pf.Oscillator(MODELS["dahl"], 1.0))
    _agree(pf.simulate(stage, 0.0, t_end=T_END, feedback=fb), pf.simulate(stage, 0.0, t_end=T_END, feedback=fb,
                                                                          method="erk"))


def test_dahl_loop_against_python_control_and_solve_ivp() -> None:
    """The native loop against python-control's discrete PID around ``solve_ivp`` of the Dahl
    equations (gamma = 1), the force held over each period: positions, forces and reversal times."""
    sigma, Fc, m = 1e6, 1.0, 1.0
    stage = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc), m)
    fb, Cd = feedback(stage)
    res = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, rtol=1e-10)
    assert_dahl_loop_matches_reference(res, Cd, sigma, Fc, m, T_END)
