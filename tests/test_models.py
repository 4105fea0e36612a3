"""Models, validation and normalised units."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction import Dahl, FrictionModel, Oscillator, Scales


def test_dahl_stores_floats_and_is_immutable():
    d = Dahl(sigma=1e4, Fc=2, gamma=0)
    assert (d.sigma, d.Fc, d.gamma) == (1e4, 2.0, 0.0)
    with pytest.raises(AttributeError):
        d.sigma = 1.0  # type: ignore[misc]


@pytest.mark.parametrize("name", ["sigma", "Fc"])
@pytest.mark.parametrize("bad", [0.0, -1.0, math.inf, math.nan])
def test_dahl_rejects_nonpositive_or_nonfinite(name, bad):
    kwargs = {"sigma": 1.0, "Fc": 1.0, name: bad}
    with pytest.raises(ValueError, match=rf"{name} must be finite and > 0, got {bad!r}"):
        Dahl(**kwargs)


@pytest.mark.parametrize("bad", [-0.5, math.inf])
def test_dahl_rejects_bad_gamma(bad):
    with pytest.raises(ValueError, match=r"gamma must be finite and >= 0"):
        Dahl(1.0, 1.0, gamma=bad)


def test_dahl_rejects_non_numbers_and_unknown_keywords():
    with pytest.raises(TypeError, match="sigma must be a real number"):
        Dahl("1", 1.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="Fc must be a real number"):
        Dahl(1.0, True)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        Dahl(1.0, 1.0, shape=2)  # type: ignore[call-arg]


@pytest.mark.parametrize("gamma", [0.0, 0.5, 1.0, 2.0])
def test_dahl_slope_is_rest_stiffness_at_zero_force(gamma):
    d = Dahl(1.0, 1.0, gamma)
    assert d.slope(0.0) == pytest.approx(1.0)
    f = np.array([-1.0, -0.5, 0.5])
    np.testing.assert_allclose(d.slope(f), (1.0 - f) ** gamma)


def test_oscillator_validation():
    d = Dahl(1e4, 1.0)
    assert Oscillator(d).mass == 1.0 and not Oscillator(d).forced
    assert Oscillator(d, u=2).u(0.7) == 2.0 and Oscillator(d, u=2).forced
    with pytest.raises(ValueError, match=r"mass must be finite and > 0, got -1.0"):
        Oscillator(d, mass=-1.0)
    with pytest.raises(TypeError, match="friction must be a FrictionModel"):
        Oscillator(1.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"u must be None, a Signal \(prefriction.signals\), a finite real number \[N\]"):
        Oscillator(d, u="3")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="strictly increasing"):
        Oscillator(d, u=([0.0, 0.0], [1.0, 2.0]))
    with pytest.raises(ValueError, match="same length as u sample times"):
        Oscillator(d, u=([0.0, 1.0], [1.0]))
    with pytest.raises(ValueError, match="finite"):
        Oscillator(d, u=([0.0, 1.0], [1.0, math.nan]))
    forced = Oscillator(d, u=([0.0, 1.0], [1.0, 2.0]))
    assert forced.forced
    with pytest.raises(ValueError):
        forced.u.u[0] = 5.0  # samples are read-only


@pytest.mark.parametrize("sigma,Fc,m", [(1e4, 1.0, 1.0), (1e10, 3e-3, 1e-6), (1e-2, 50.0, 1e3)])
def test_scales_are_consistent_units(sigma, Fc, m):
    s = Scales.of(Oscillator(Dahl(sigma, Fc), mass=m))
    assert s.x == pytest.approx(Fc / sigma)
    assert s.v == pytest.approx(s.x / s.t)  # velocity unit = length / time
    assert s.E == pytest.approx(s.F * s.x)  # energy unit = force x length
    assert m * s.v**2 == pytest.approx(s.E)  # kinetic energy m v^2 in energy units
    assert sigma * s.t**2 / m == pytest.approx(1.0)  # natural period of the rest-stiffness spring


class _Viscous(FrictionModel):
    """A rate-dependent model (viscous friction ``F = v``): not for the Dahl-only or the
    energy functions (for the type checks)."""

    sigma, Fc = 1.0, 1.0
    rate_independent = False
    n_states = 0

    def runtime_params(self):
        return np.zeros(0)

    def initial_state(self, f0, s):
        return [], []

    def rate(self, z, m, v, s, q):
        return []

    def force(self, z, m, v, s, q):
        return v

    def reverse(self, z, m, s_new, q, snap):
        return [], []


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda s: pf.exact_reversals(s, 0.1, 3), "exact_reversals has an exact reference for Dahl and MaxwellSlip only"),
        (lambda s: pf.energy.total_energy([0.0, 1.0], [0.1, 0.1], [0.0, 0.0], system=s),
         "the energy analysis needs a rate-independent friction model"),
    ],
)
def test_dahl_only_functions_name_what_they_need(call, message):
    with pytest.raises(TypeError, match=message):
        call(Oscillator(_Viscous()))
    with pytest.raises(TypeError, match="system must be a prefriction.Oscillator, got 3"):
        call(3)
