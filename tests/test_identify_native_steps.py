"""The compiled shooting segments (``segment_functions(..., native=True)``: one Runge-Kutta
sub-step compiled to C and repeated over the sample split into sub-samples) against independent
references: the scipy integration of the model's equations with its events located anew
(:func:`prefriction.identify.synthetic_events.event_motion`) for the positions, central finite
differences of the segment for the sensitivities across reversals and in-branch events."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.identify.motion_step import segment_functions
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.synthetic_events import event_motion

from _segment_fd import segment_derivatives

MASS = 1.0
MODELS = {
    "dahl_gamma_2": (pf.Dahl(1e5, 1.0, 2.0), None),
    "dahl_gamma_0.6": (pf.Dahl(1e5, 1.0, 0.6), None),
    "maxwell_slip": (pf.MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.3]), None),
}
NAMES = ["dahl_gamma_2", "dahl_gamma_0.6",
         pytest.param("maxwell_slip", marks=pytest.mark.slow)]   # its compilation takes about 10 s


def _drive(model: pf.FrictionModel, n: int, step: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Sample times (``step`` time units ``sqrt(m / sigma)`` apart) and a two-tone force [N] that
    slides the mass both ways, with reversals (and slips or saturations where the model has them)."""
    T = math.sqrt(MASS / model.sigma)
    t = np.arange(n) * step * T
    return t, 0.05 + 1.6 * np.sin(2 * np.pi * t / (10 * T)) + 0.3 * np.sin(2 * np.pi * t / (3.3 * T))


def _native_segment(name: str, K: int, n_sub: int, s0: float):
    """The compiled segment of ``K`` samples and its inputs: the drive held over each sample, the
    model's virgin state in direction ``s0``, the force offset free at 0 N."""
    model, fixed = MODELS[name]
    space = ParameterSpace(model, None, fixed, None, mass=MASS, offset=1.0)   # offset free, from 0 N
    plain, sens = segment_functions(model, space, K, n_sub, True, True)
    t, u = _drive(model, K + 1)
    z0, m0 = model.initial_state(0.0, s0)
    X, V = model.Fc / model.sigma, model.Fc / math.sqrt(MASS * model.sigma)
    args = dict(m0=m0, s0=s0, s_to=1.0, scale=space.scale, fixed=space.fixed_values(), mass=MASS,
                U0=u[None, :K], U1=u[None, :K], DT=np.diff(t)[None, :], scl=[X, V])
    return model, space, plain, sens, t, u, z0, args


@pytest.mark.parametrize("name", NAMES)
def test_native_positions_match_the_scipy_integration(name):
    """Positions of a compiled 80-sample segment from rest (16 sub-steps per sample) against the
    scipy integration of the same held force with every reversal and event located (DOP853 at
    ``rtol = 1e-11``): within 1e-9 of the segment's travel (measured: 4e-12 to 3e-11)."""
    K, n_sub = 80, 16
    model, space, plain, _sens, t, u, z0, args = _native_segment(name, K, n_sub, 1.0)   # u[0] > 0: s = +1
    out = plain(node=np.r_[0.0, 0.0, z0], theta=space.theta0, **args)
    x = np.asarray(out["X"])[0]
    ref = event_motion(model, MASS, t, u).x
    assert np.any(np.diff(np.sign(np.asarray(out["X"])[1])) != 0)    # the segment reverses
    travel = float(np.ptp(ref))
    assert np.max(np.abs(x - ref)) <= 1e-9 * travel, (name, np.max(np.abs(x - ref)) / travel)


@pytest.mark.parametrize("name", NAMES)
def test_native_sensitivities_match_finite_differences(name):
    """dX/dw and dYe/dw of a compiled segment that moves through reversals (and events): the
    sub-step-by-sub-step chain rule against central differences of the compiled segment itself."""
    K, n_sub = 80, 3
    model, space, plain, sens, t, u, z0, args = _native_segment(name, K, n_sub, 1.0)
    node = np.r_[0.0, 0.3, z0]                       # moving: no kink of the start at v = 0
    o, ad, fd = segment_derivatives(plain, sens, node, space.theta0, args)
    assert np.any(np.diff(np.sign(np.asarray(o["X"])[1])) != 0)
    for j in range(ad.shape[1]):
        scale = max(np.max(np.abs(ad[:, j])), 1e-4 * np.max(np.abs(ad)))
        assert np.max(np.abs(fd[:, j] - ad[:, j])) <= 1e-5 * scale, (name, j)


def test_without_a_compiler_the_segments_are_the_interpreted_ones(monkeypatch):
    """``PREFRICTION_NO_JIT=1`` (as on a machine without a C compiler): ``native=True`` gives the
    segments of ``native=False`` (the unrolled interpreted step; repeating an interpreted sub-step
    would cost Dahl 1.6 times as much), whose positions match the scipy integration."""
    monkeypatch.setenv("PREFRICTION_NO_JIT", "1")
    model = pf.Dahl(1.3e5, 1.0, 1.7)                 # a structure no other test compiles
    space = ParameterSpace(model, None, None, None, mass=MASS, offset=1.0)
    native = segment_functions(model, space, 30, 5, True, True)
    interpreted = segment_functions(model, space, 30, 5, True, False)
    assert native[0] is interpreted[0] and native[1] is interpreted[1]
    t, u = _drive(model, 31)
    z0, m0 = model.initial_state(0.0, 1.0)
    X, V = model.Fc / model.sigma, model.Fc / math.sqrt(MASS * model.sigma)
    out = native[0](node=np.r_[0.0, 0.0, z0], theta=space.theta0, m0=m0, s0=1.0, s_to=1.0, scale=space.scale,
                    fixed=space.fixed_values(), mass=MASS, U0=u[None, :30], U1=u[None, :30],
                    DT=np.diff(t)[None, :], scl=[X, V])
    ref = event_motion(model, MASS, t, u).x
    assert np.max(np.abs(np.asarray(out["X"])[0] - ref)) <= 1e-8 * float(np.ptp(ref))
