"""A model written with only its mathematics (parameters, n_states, rate, force) gets every other
member from the base class, simulates, evaluates along a motion and passes check_model; a missing
piece is refused at construction, naming it. The model file is docs/models.md#add-a-model's."""

from __future__ import annotations

import importlib.util
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import prefriction as pf
from prefriction.testing import check_model

_FILE = Path(__file__).resolve().parent.parent / "examples" / "bouc_wen_model.py"
_spec = importlib.util.spec_from_file_location("bouc_wen_model", _FILE)
bouc_wen_model = importlib.util.module_from_spec(_spec)
sys.modules["bouc_wen_model"] = bouc_wen_model  # dataclasses look the module up
_spec.loader.exec_module(bouc_wen_model)
BoucWen = bouc_wen_model.BoucWen


def test_the_add_a_model_file_is_short_and_runs(capsys):
    assert len(_FILE.read_text().splitlines()) <= 60
    bouc_wen_model.main()
    out = capsys.readouterr().out
    assert "check_model: 6 reversals" in out


def test_defaults_derived_from_the_declared_parameters():
    model = BoucWen(k=2e5, Fy=0.5, c=2.0)
    assert (model.sigma, model.Fc) == (2e5, 0.5)
    V = 0.5 / math.sqrt(2e5)  # velocity unit of a unit mass
    np.testing.assert_allclose(model.runtime_params(), [1.0, 1.0, 2.0 * V / 0.5], rtol=1e-15)
    sc = pf.Scales.of(pf.Oscillator(model, mass=0.3))
    np.testing.assert_allclose(model.runtime_params_for(sc), [1.0, 1.0, 2.0 * sc.v / 0.5], rtol=1e-15)
    assert model.n_flags == model.n_events == 0 and not model.rate_independent
    assert model.initial_state(0.3, 1.0) == ([pytest.approx(0.3, rel=1e-15)], [])
    assert model.reverse([0.7], [], -1.0, model.runtime_params(), 1e-9) == ([0.7], [])


def test_friction_along_matches_an_independent_integration():
    """Rate-independent part along ``x = X sin``: ``dw/dx~ = 1 - s w^3`` by scipy per monotone leg."""
    from scipy.integrate import solve_ivp

    model = BoucWen(k=2e5, Fy=0.5)
    t = np.linspace(0.0, 1.0, 801)
    x = 6e-6 * np.sin(2 * np.pi * t) + 1e-6 * np.sin(6 * np.pi * t)
    got = pf.friction_along(model, t, x, substeps=16)
    xn = x * 2e5 / 0.5
    w, ref = 0.0, [0.0]
    for i in range(len(t) - 1):
        s = 1.0 if xn[i + 1] >= xn[i] else -1.0
        sol = solve_ivp(lambda _x, y, s=s: [s * (1.0 - s * y[0] ** 3)], (0.0, abs(xn[i + 1] - xn[i])), [w],
                        method="DOP853", rtol=1e-12, atol=1e-14)
        w = float(sol.y[0, -1])
        ref.append(w)
    np.testing.assert_allclose(got.F / 0.5, ref, rtol=0, atol=1e-9)


def test_user_model_fits_force_displacement_data():
    """The fit builds the model on CasADi symbols: the base's units and run-time numbers follow."""
    from prefriction import identify

    t = np.linspace(0.0, 1.0, 801)
    x = 6e-6 * np.sin(2 * np.pi * t) + 1e-6 * np.sin(6 * np.pi * t)
    truth = BoucWen(k=2e5, Fy=0.5)
    F = pf.friction_along(truth, t, x).F
    res = identify.fit(BoucWen(k=1.5e5, Fy=0.6), identify.ForceDisplacement(t, x, F), fixed=["c"])
    assert res.model.k == pytest.approx(2e5, rel=1e-6) and res.model.Fy == pytest.approx(0.5, rel=1e-6)


@dataclass(frozen=True)
class Cubic(pf.FrictionModel):
    """The element alone: rate-independent, so the energy analysis applies (branch energy by quadrature)."""

    k: float
    Fy: float
    parameters = (pf.Parameter("k", "N/m", 0.0, math.inf, low_open=True),
                  pf.Parameter("Fy", "N", 0.0, math.inf, low_open=True))
    n_states = 1

    def rate(self, z, m, v, s, q):
        return [v * (1.0 - s * z[0] ** 3)]

    def force(self, z, m, v, s, q):
        return z[0]


def test_rate_independent_user_model_gets_its_energy_by_quadrature():
    model = Cubic(1e4, 2.0)
    assert model.rate_independent
    F = -0.6  # at a reversal into s = +1: -int_F^0 w / (1 - w^3) dw ... area back to the zero crossing
    ref = float(mp.quad(lambda w: w / (1 - w ** 3), [F, 0]))
    assert model.branch_energy_of_force(np.array([F]), 1.0)[0] == pytest.approx(-ref, rel=1e-12)
    out = check_model(model, v0=1.2, reversals=8)  # energy balance, dissipation and bound included
    assert out.n_reversals == 8 and out.branch_energy_error < 1e-6


@pytest.mark.parametrize("v0", [0.5, 2.0])
def test_user_model_passes_check_model(v0):
    out = check_model(BoucWen(k=1e4, Fy=2.0, c=5.0), v0=v0, reversals=6, t_end=60.0)
    assert out.n_reversals >= 3


def test_missing_pieces_are_refused_naming_them():
    @dataclass(frozen=True)
    class NoForce(pf.FrictionModel):
        k: float
        Fy: float
        parameters = Cubic.parameters
        n_states = 1

        def rate(self, z, m, v, s, q):
            return [v]

    with pytest.raises(TypeError, match="does not define force"):
        NoForce(1.0, 1.0)

    @dataclass(frozen=True)
    class EventsOnly(Cubic):
        def events(self, z, m, v, s, q):
            return [1.0 - s * z[0]]

    with pytest.raises(TypeError, match=r"defines events\(\) but not on_event"):
        EventsOnly(1.0, 1.0)

    @dataclass(frozen=True)
    class NoUnits(Cubic):
        parameters = (pf.Parameter("k", "N/m", 0.0, math.inf, low_open=True),
                      pf.Parameter("Fy", "m", 0.0, math.inf, low_open=True))

    with pytest.raises(TypeError, match="has no Fc"):
        NoUnits(1.0, 1.0)


@dataclass(frozen=True)
class TwoElements(pf.FrictionModel):
    """Two Bouc-Wen elements of stiffness ratio 1:3 and a damper: several states, no initial_state."""

    k: float
    Fy: float
    c: float
    parameters = BoucWen.parameters
    n_states = 2

    def rate(self, z, m, v, s, q):
        return [0.25 * v * (1.0 - s * (2.0 * z[0]) ** 3), 0.75 * v * (1.0 - s * (2.0 * z[1]) ** 3)]

    def force(self, z, m, v, s, q):
        return z[0] + z[1] + q[2] * v


def test_several_states_without_initial_state():
    model = TwoElements(1e4, 2.0, 5.0)
    assert check_model(model, v0=1.0, reversals=5, t_end=60.0).n_reversals >= 3
    with pytest.raises(NotImplementedError, match="does not define initial_state"):
        pf.simulate(pf.Oscillator(model), 0.0, F0=0.5, reversals=2)
