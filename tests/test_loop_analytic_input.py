"""Sampled loops of :func:`prefriction.simulate` under an input force that is not linear over the
sample periods: an analytic disturbance (``Sine``) and a ``Step`` between two sample instants.

The native sampled loop (``native/loop.c``) evaluates the input with the forced driver's generated
C (``pf_input``), the integration broken at the input's breaks inside a period. It is held to
CasADi's loop (``method="erk"``, one integrator call per period) and to an independent reference:
python-control's discrete PID around ``solve_ivp`` of the Dahl equations (tests/_sampled_loop.py), the
controller's output held over each period and the sine force added.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.signals import Chirp, PointToPoint, Ramp, Samples, Sine, Step, Traced, ZeroOrderHold
from prefriction.simulation.compiled import jit_available

from _sampled_loop import MODELS, TS, agree, assert_dahl_loop_matches_reference, feedback

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native loop needs a C compiler")

T_END = 0.03  # s
INPUTS = {
    "sine": Sine(0.3, 70.0),
    "step_between_samples": Step(100.37 * TS, 0.0, 0.3),
}


def _feedback() -> tuple[pf.LinearFeedback, object]:
    """The 10 kHz discrete PID (python-control's ZOH of the 150 Hz design) as a sampled feedback."""
    return feedback(pf.Oscillator(MODELS["dahl"], 1.0))


@pytest.mark.parametrize("kind", sorted(INPUTS))
@pytest.mark.parametrize("name", ["dahl", "lugre"])
def test_native_and_erk_agree(name: str, kind: str) -> None:
    """Native loop and CasADi's loop, each at rtol 1e-8: samples, applied force, controller states
    and reversals agree to 1e-8 of the stroke and of the run's length."""
    stage = pf.Oscillator(MODELS[name], 1.0, INPUTS[kind])
    fb, _ = _feedback()
    a = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, rtol=1e-8)
    b = pf.simulate(stage, 0.0, t_end=T_END, feedback=fb, rtol=1e-8, method="erk")
    agree(a, b, T_END)
    assert a.stats.calls <= 2 < b.stats.calls  # one C call per block of periods, one CasADi call per period
    assert len(a.t) == round(T_END / TS) + 1
    np.testing.assert_allclose(a.work_input, b.work_input, rtol=0, atol=1e-7 * np.max(np.abs(b.work_input)))


_TU = np.linspace(0.0, 0.02, 57)  # sample times off the loop's grid


def _traced(t):
    import casadi as ca

    return 0.5 * (ca.cos(180.0 * t) if isinstance(t, (ca.SX, ca.MX)) else np.cos(180.0 * t))


EVERY_KIND = {
    "chirp": Chirp(0.4, 30.0, 250.0, 0.02),
    "ramp": Ramp(0.00517, 0.00733, -0.3),
    "samples": Samples(_TU, 0.3 * np.sin(2 * np.pi * 90 * _TU)),
    "zoh": ZeroOrderHold(_TU[::3], 0.3 * np.sin(2 * np.pi * 70 * _TU[::3])),
    "point_to_point": PointToPoint(0.6, 6.0, 20000.0) + Sine(0.2, 120.0) + (-0.1),
    "traced": Traced(_traced),
    "sum": Sine(0.2, 100.0) + Samples(_TU, 0.1 * np.sin(2 * np.pi * 230 * _TU)),
}


@pytest.mark.parametrize("kind", sorted(EVERY_KIND))
def test_every_input_kind_runs_native_and_agrees(kind: str) -> None:
    """Every other signal kind as the disturbance of the Dahl loop (breaks off the sample grid):
    native and CasADi's loop agree to 1e-8 of the largest |x| and of the run's length."""
    stage = pf.Oscillator(MODELS["dahl"], 1.0, EVERY_KIND[kind])
    fb, _ = _feedback()
    a = pf.simulate(stage, 0.0, t_end=0.02, feedback=fb, rtol=1e-8)
    b = pf.simulate(stage, 0.0, t_end=0.02, feedback=fb, rtol=1e-8, method="erk")
    assert a.stats.steps is not None and b.stats.steps is None
    assert np.max(np.abs(a.x - b.x)) <= 1e-8 * np.max(np.abs(b.x))
    assert np.max(np.abs(a.u - b.u)) <= 1e-7 * np.max(np.abs(b.u))
    assert len(a.reversals) == len(b.reversals) >= 1
    np.testing.assert_allclose(a.reversals.t, b.reversals.t, rtol=0, atol=1e-8 * 0.02)


def test_dahl_under_a_sine_disturbance_against_python_control_and_solve_ivp() -> None:
    """The native loop against python-control's discrete PID around ``solve_ivp`` of
    ``m x'' = u_k + d(t) - F``, ``F' = sigma (v - |v| F / Fc)`` (Dahl, gamma = 1), ``u_k`` held
    over each period, ``d`` the sine: positions, applied forces and reversal times."""
    sigma, Fc, m = 1e6, 1.0, 1.0
    d = INPUTS["sine"]
    amp, w = 0.3, 2 * np.pi * 70.0
    assert float(d(0.01)) == pytest.approx(amp * math.sin(w * 0.01), abs=1e-15)  # the force written below
    fb, Cd = _feedback()
    res = pf.simulate(pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc), m, d), 0.0, t_end=T_END, feedback=fb, rtol=1e-10)
    assert_dahl_loop_matches_reference(res, Cd, sigma, Fc, m, T_END, lambda t: amp * math.sin(w * t))
