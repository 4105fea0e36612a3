"""The elasto-plastic model (Dupont et al. 2002) against an independent scipy integration of the
paper's equations (``tests/_elasto_plastic_reference.py``, restarted at every reversal, breakaway
and saturation crossing)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.testing import check_model

from _elasto_plastic_reference import along, oscillator

EP = dict(sigma0=1e5, sigma1=100.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3, z_ba=0.5e-5)
MASS = 0.5


def _rel(got: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(got - ref)) / np.max(np.abs(ref)))


def test_unforced_reversals_match_the_2002_equations():
    ep = pf.ElastoPlastic(**EP)
    res = pf.simulate(pf.Oscillator(ep, mass=MASS), 0.05, reversals=8, rtol=1e-10)
    tab = res.reversals
    ref = oscillator(ep, MASS, 0.05, t_end=tab.t[-1] * (1.0 + 1e-7))
    assert ref["breakaways"] >= 1 and ref["saturations"] >= 1  # both events on the way
    rows = ref["reversals"]
    assert len(rows) == len(tab.t) == 8
    assert np.max(np.abs(tab.t - rows[:, 0]) / rows[:, 0]) < 1e-9
    assert _rel(tab.x, rows[:, 1]) < 1e-9
    assert _rel(tab.F, rows[:, 2]) < 1e-9


def test_forced_run_matches_the_2002_equations():
    ep = pf.ElastoPlastic(**EP)
    u = pf.signals.Constant(0.3) + pf.signals.Sine(amplitude=1.4, frequency=20.0)
    T = np.linspace(0.01, 0.2, 40)
    res = pf.simulate(pf.Oscillator(ep, mass=MASS, u=u), 0.0, t_end=0.2, rtol=1e-10, dense=T)
    ref = oscillator(ep, MASS, 1e-300, u=lambda t: 0.3 + 1.4 * math.sin(40.0 * math.pi * t), t_end=0.2, times=T)
    assert ref["breakaways"] >= 4 and ref["saturations"] >= 1
    rows = ref["reversals"]
    assert len(rows) == len(res.reversals.t)
    assert np.max(np.abs(res.reversals.t - rows[:, 0]) / rows[:, 0]) < 1e-9
    assert _rel(res.reversals.F, rows[:, 2]) < 1e-9
    d = ref["dense"]
    assert _rel(res.x, d[:, 0]) < 1e-9 and _rel(res.v, d[:, 1]) < 1e-9 and _rel(res.F, d[:, 2]) < 1e-9


def test_friction_along_matches_the_2002_equations():
    ep = pf.ElastoPlastic(**EP)
    t = np.linspace(0.0, 0.1, 2001)
    x = 2e-5 * np.sin(40.0 * math.pi * t) + 0.6e-5 * np.sin(94.0 * math.pi * t)
    got = pf.friction_along(ep, t, x)
    assert got.step == "exact"
    ref = along(ep, t, x)
    assert _rel(got.F, ref) < 1e-10
    inside = pf.friction_along(pf.ElastoPlastic(**EP, crossings=False), t, x)  # no flags: the same step
    assert _rel(inside.F, ref) < 1e-10 and inside.flags.shape == (t.size, 0)
    # sample by sample: the same forces
    stream = pf.FrictionStream(ep, x0=x[0], t0=t[0])
    F = np.array([stream.step(xi, ti) for ti, xi in zip(t[1:], x[1:])])
    np.testing.assert_allclose(F, got.F[1:], rtol=0, atol=1e-12)


@pytest.mark.parametrize("v0", [0.3, 3.0])  # normalised: stays elastic / breaks away
def test_elasto_plastic_meets_the_invariants(v0):
    out = check_model(pf.ElastoPlastic(**EP), v0=v0, reversals=4, t_end=40.0)
    assert out.n_reversals >= 1


def test_below_breakaway_the_model_is_a_spring():
    """Below ``z_ba`` (normalised ``b``) the unforced motion is the undamped-free elastic
    oscillation of LuGre's bristle with damping ``sigma1``: closed form of a linear oscillator."""
    ep = pf.ElastoPlastic(**{**EP, "sigma1": 0.0, "sigma2": 0.0})
    sc = pf.Scales.of(pf.Oscillator(ep, mass=MASS))
    res = pf.simulate(pf.Oscillator(ep, mass=MASS), 0.4 * sc.v, reversals=5, rtol=1e-10)
    np.testing.assert_allclose(res.reversals.t / sc.t, math.pi / 2 + math.pi * np.arange(5), rtol=1e-9)
    np.testing.assert_allclose(np.abs(res.reversals.F) / sc.F, 0.4, rtol=1e-9)


@pytest.mark.parametrize("bad, name", [(dict(z_ba=1e-5), "z_ba"), (dict(z_ba=0.0), "z_ba"), (dict(Fs=0.5), "Fs"),
                                       (dict(sigma0=-1.0), "sigma0")])
def test_bad_parameters_are_refused_by_name(bad, name):
    with pytest.raises(ValueError, match=name):
        pf.ElastoPlastic(**{**EP, **bad})


def test_sweep_over_the_breakaway_displacement_equals_single_runs():
    """One compiled plant for every ``z_ba``; each sweep member as its own run (and the reference)."""
    models = [pf.ElastoPlastic(**{**EP, "z_ba": z}) for z in (0.2e-5, 0.5e-5, 0.8e-5)]
    systems = [pf.Oscillator(m, mass=MASS) for m in models]
    swept = pf.sweep(systems, 0.05, reversals=4, rtol=1e-10)
    assert swept.success
    for system, res in zip(systems, swept):
        ref = oscillator(system.friction, MASS, 0.05, t_end=res.reversals.t[-1] * (1.0 + 1e-7))["reversals"]
        assert np.max(np.abs(res.reversals.F - ref[:, 2])) < 1e-9 * np.max(np.abs(ref[:, 2]))


def test_sum_with_a_damper_is_the_viscous_term():
    """``ElastoPlastic(sigma2=0) + Viscous(b)`` and ``ElastoPlastic(sigma2=b)``: the same equations."""
    summed = pf.ElastoPlastic(**{**EP, "sigma2": 0.0}) + pf.Viscous(b=EP["sigma2"])
    one = pf.simulate(pf.Oscillator(pf.ElastoPlastic(**EP), mass=MASS), 0.05, reversals=6, rtol=1e-10).reversals
    two = pf.simulate(pf.Oscillator(summed, mass=MASS), 0.05, reversals=6, rtol=1e-10).reversals
    np.testing.assert_allclose(two.t, one.t, rtol=1e-9)
    np.testing.assert_allclose(two.F, one.F, rtol=0, atol=1e-9 * np.max(np.abs(one.F)))
