"""The sampled stage both native-sampled-loop test files use: the 10 kHz PID around a 1 kg stage
tracking a 5 um sine, its models, and the agreement of a native run with CasADi's loop."""

from __future__ import annotations

import math

import numpy as np

import prefriction as pf
from prefriction import controllers
from prefriction.signals import Sine

TS, STROKE = 1e-4, 5e-6  # s, m
REF = Sine(0.5 * STROKE, 50.0, phase=-math.pi / 2, offset=0.5 * STROKE)
MODELS = {
    "dahl": pf.Dahl(sigma=1e6, Fc=1.0),
    "lugre": pf.LuGre(sigma0=1e6, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3),
    "maxwell_slip": pf.MaxwellSlip([4e5, 3e5, 3e5], [0.3, 0.3, 0.4]),
}


def feedback(stage: pf.Oscillator, reference=REF) -> tuple[pf.LinearFeedback, object]:
    """The 10 kHz discrete PID (ZOH of the 150 Hz design) as a sampled LinearFeedback, and ``c2d``'s system."""
    Cd = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7).c2d(TS)
    return pf.LinearFeedback(A=Cd.A, B=Cd.B, C=Cd.C, D=Cd.D, Ts=TS, reference=reference), Cd


def agree(a: pf.SimulationResult, b: pf.SimulationResult, t_end: float) -> None:
    """Native ``a`` and CasADi ``b`` (each at rtol 1e-8): the same samples, applied force,
    controller states and reversals to 1e-8 of the stroke and of the run's length ``t_end`` [s]."""
    assert a.stats.steps is not None and b.stats.steps is None  # the native loop counts its steps; CasADi does not
    assert a.status == b.status and len(a.t) == len(b.t) > 10
    np.testing.assert_allclose(a.t, b.t, rtol=1e-13, atol=0)  # (CasADi: the break times to round-off)
    assert np.max(np.abs(a.x - b.x)) <= 1e-8 * STROKE
    assert np.max(np.abs(a.u - b.u)) <= 1e-7 * np.max(np.abs(b.u))
    assert np.max(np.abs(a.xc - b.xc)) <= 1e-8 * np.max(np.abs(b.xc))
    assert len(a.reversals) == len(b.reversals) >= 2
    np.testing.assert_allclose(a.reversals.t, b.reversals.t, rtol=0, atol=1e-8 * t_end)
    np.testing.assert_allclose(a.reversals.x, b.reversals.x, rtol=0, atol=1e-8 * STROKE)
