"""Motion fits of models with in-branch events: Dahl with gamma < 1, Maxwell-slip, GMS.

Reference independent of the fitter: the records come from scipy's DOP853 integration of the
models' published equations with every reversal, saturation and slip located as a terminal event
and the integration restarted there (prefriction.identify.synthetic_events, which reads only the
models' numbers). The derivatives of the shooting segments are checked against central finite
differences of the segment itself (exactness of the Jacobian where the motion is piecewise
smooth) and against central differences of the scipy reference (the saltation term: how the
event time moves with a parameter).
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.identify.motion_step import segment_functions
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.synthetic_events import event_motion, event_record

from _segment_fd import segment_derivatives

MASS = 1.0
GMS_FIXED = ["alpha[0]", "alpha[1]", "vs", "delta", "sigma2", "damping[0]", "damping[1]"]
MODELS = {
    "dahl": (pf.Dahl(1e5, 1.0, 0.6), None),
    "maxwell_slip": (pf.MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.3]), None),
    "gms": (pf.GMS(k=[6e4, 4e4], alpha=[0.4, 0.6], Fc=1.0, Fs=1.3, vs=1e-3, C=50.0), GMS_FIXED),
}


def _drive(model: pf.FrictionModel, n: int, step: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Sample times (``step`` time units apart) and a two-tone force that slides the mass both
    ways with several reversals and slips [s, N]."""
    T = math.sqrt(MASS / model.sigma)
    t = np.arange(n) * step * T
    return t, 0.05 + 1.6 * np.sin(2 * np.pi * t / (10 * T)) + 0.3 * np.sin(2 * np.pi * t / (3.3 * T))


def _segment(model, fixed, K, n_sub):
    space = ParameterSpace(model, None, fixed, None, mass=MASS, offset=1.0)
    plain, sens = segment_functions(model, space, K, n_sub, True)
    X, V = model.Fc / model.sigma, model.Fc / math.sqrt(MASS * model.sigma)
    return space, plain, sens, X, V


@pytest.mark.parametrize("name", list(MODELS))
def test_segment_jacobian_matches_finite_differences_across_events(name):
    """dX/dw and dYe/dw of a segment in which the model has events (a saturation or slips) and a
    reversal: exact where the motion is piecewise smooth."""
    model, fixed = MODELS[name]
    K, n_sub = 80, 2
    space, plain, sens, X, V = _segment(model, fixed, K, n_sub)
    t, u = _drive(model, K + 1)
    z0, m0 = model.initial_state(0.0, 1.0)
    node = np.r_[0.0, 0.3, z0]                       # moving: no kink of the start at v = 0
    args = dict(m0=m0, s0=1.0, s_to=1.0, scale=space.scale, fixed=space.fixed_values(), mass=MASS,
                U0=u[None, :K], U1=u[None, :K], DT=np.diff(t)[None, :], scl=[X, V])
    o, ad, fd = segment_derivatives(plain, sens, node, space.theta0, args)
    vel = np.asarray(o["X"])[1]
    assert np.any(np.diff(np.sign(vel)) != 0)                  # a reversal inside
    run = event_motion(model, MASS, t, u)
    assert run.events.size >= 1                                # and events
    for j in range(ad.shape[1]):
        scale = max(np.max(np.abs(ad[:, j])), 1e-4 * np.max(np.abs(ad)))   # the guard's column is ~0
        assert np.max(np.abs(fd[:, j] - ad[:, j])) <= 1e-5 * scale, (name, j)


@pytest.mark.parametrize("name, par", [("dahl", "Fc"), ("maxwell_slip", "slip_force[0]"), ("gms", "k[0]")])
def test_saltation_derivative_matches_the_reference(name, par):
    """d x / d parameter at the samples after the first event: the segment's sensitivity against
    a central difference of the scipy reference (which locates the event anew at each value)."""
    model, fixed = MODELS[name]
    K, n_sub = 40, 8
    space, plain, sens, X, V = _segment(model, fixed, K, n_sub)
    t, u = _drive(model, K + 1)
    z0, m0 = model.initial_state(0.0, 1.0)
    args = dict(m0=m0, s0=1.0, s_to=1.0, scale=space.scale, fixed=space.fixed_values(), mass=MASS,
                U0=u[None, :K], U1=u[None, :K], DT=np.diff(t)[None, :], scl=[X, V])
    o = sens(node=np.r_[0.0, 0.0, z0], theta=space.theta0, **args)
    j = space.free.index(par)
    dx = np.asarray(o["dX"])[j] / space.scale[j]               # d x / d par at each sample [m / unit]
    value = space.start[par]
    h = 1e-5 * value

    def moved(delta: float) -> np.ndarray:
        vals = dict(space.start)
        vals[par] = value + delta
        return event_motion(space.build(vals), MASS, t, u).x

    fd = (moved(h) - moved(-h)) / (2.0 * h)
    run = event_motion(model, MASS, t, u)
    first = int(np.searchsorted(t, run.events[0]))
    assert first < K - 3
    after = slice(first, K + 1)
    assert np.max(np.abs(dx[after] - fd[after])) <= 2e-3 * np.max(np.abs(fd[after])), (name, dx[after], fd[after])


def _fit(name: str, factor: float, n: int, noise: float, seed: int = 0):
    model, fixed = MODELS[name]
    t, u = _drive(model, n)
    off = 0.1 if name == "dahl" else 0.0
    rng = np.random.default_rng(seed)
    data = event_record(model, MASS, t, u, offset=off, noise=noise * model.Fc / model.sigma, rng=rng)
    start = _start(name, factor)
    kw = dict(offset=True) if name == "dahl" else dict(fixed=fixed)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(start, data, **kw)
    truth = dict(_truth(model), offset=off)
    return res, np.array([truth[n] for n in res.names]), time.perf_counter() - t0


def _truth(model: pf.FrictionModel) -> dict[str, float]:
    space = ParameterSpace(model, None, None, None)
    return dict(space.start)


def _start(name: str, f: float) -> pf.FrictionModel:
    """A start ``f`` off in every free parameter (up or down, keeping the elements distinct)."""
    if name == "dahl":
        return pf.Dahl(1e5 * f, 1.0 / f, 0.6 * f if 0.6 * f < 1.0 else 0.6 / f)
    if name == "maxwell_slip":
        return pf.MaxwellSlip([6e4 * f, 3e4 * f, 1e4 / f], [0.3 / f, 0.4 * f, 0.3 * f])
    return pf.GMS(k=[6e4 * f, 4e4 / f], alpha=[0.4, 0.6], Fc=1.0 / f, Fs=1.3, vs=1e-3, C=50.0 * f)


@pytest.mark.parametrize("factor", [1.5, 2.0])
def test_dahl_gamma_below_one_with_offset_fits_from_far_starts(factor):
    """Dahl gamma = 0.6 (saturation events) + offset, every parameter ``factor`` off (gamma
    0.9 and 0.3): within 1 % of the truth on a clean record."""
    res, truth, _sec = _fit("dahl", factor, 300, 0.0)
    assert res.success, res.message
    np.testing.assert_allclose(res.estimates, truth, rtol=0.01)


def test_dahl_gamma_below_one_intervals_hold_the_truth():
    """The same fit from 1.5x on a record with position noise (1 % of Fc / sigma): the 95 %
    intervals hold every true value."""
    res, truth, _sec = _fit("dahl", 1.5, 300, 0.01, seed=15)
    assert res.success, res.message
    assert np.all((res.low <= truth) & (truth <= res.high)), (res.names, res.estimates, res.low, res.high)


@pytest.mark.slow
def test_maxwell_slip_three_elements_fits_from_a_far_start():
    """Maxwell-slip(3), every stiffness and slip force 1.5x off (slip events of three elements),
    clean record: within 2 % of the truth (about 20 s on a loaded machine: slow)."""
    res, truth, _sec = _fit("maxwell_slip", 1.5, 300, 0.0)
    assert res.success, res.message
    np.testing.assert_allclose(res.estimates, truth, rtol=0.02)
