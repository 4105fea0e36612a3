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


# ------------------------------------------------------ parallel elements (Maxwell-slip, GMS)
def _phi(y, kappa, w):
    """The virgin curve sum_i min(kappa_i y, w_i), written here (mpmath)."""
    import mpmath

    return mpmath.fsum(min(mpmath.mpf(float(k)) * y, mpmath.mpf(float(c))) for k, c in zip(kappa, w))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_virgin_curve_energies_against_quadrature(seed):
    """VirginCurve.stored = Phi(phi^-1(f)) and complementary = Phi*(f) = f y - Phi(y) (Legendre,
    y = phi^-1(f)) against mpmath: the inverse by bisection on phi, Phi by quadrature split at
    the slip deflections."""
    import mpmath

    from prefriction.models.element_curves import VirginCurve

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 6))
    kappa = rng.uniform(0.1, 1.0, n)
    kappa /= kappa.sum()
    w = rng.uniform(0.1, 1.0, n)
    w /= w.sum()
    curve = VirginCurve(kappa, w)
    deltas = sorted(float(d) for d in w / kappa)
    for f in rng.uniform(0.0, 1.0, 6):
        y = mpmath.findroot(lambda yy: _phi(yy, kappa, w) - f, (0.0, deltas[-1]), solver="bisect", tol=1e-30)
        nodes = [0.0] + [d for d in deltas if d < y] + [y]
        Phi = mpmath.quad(lambda yy: _phi(yy, kappa, w), nodes)
        assert float(curve.inverse(np.array(f))) == pytest.approx(float(y), rel=1e-13)
        assert float(curve.stored(np.array(f))) == pytest.approx(float(Phi), rel=1e-12)
        assert float(curve.complementary(np.array(f))) == pytest.approx(float(f * y - Phi), rel=1e-12)


def _maxwell_slip():
    return pf.MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.3])


def _gms():
    return pf.GMS([6e4, 3e4, 1e4], [0.2, 0.3, 0.5], 1.0, 1.5, 1e-3, 2e3, damping=[1.0, 0.0, 2.0])


@pytest.mark.parametrize("make", [_maxwell_slip, _gms])
def test_parallel_elements_compare_hash_and_pickle_by_their_numbers(make):
    import pickle

    model = make()
    back = pickle.loads(pickle.dumps(model))
    assert back == model and hash(back) == hash(model) and type(back) is type(model)
    assert not back.stiffness.flags.writeable if isinstance(back, pf.MaxwellSlip) else not back.k.flags.writeable
    assert model != 3 and model != (_gms() if isinstance(model, pf.MaxwellSlip) else _maxwell_slip())
    assert model.structure_key() == (type(model).__name__, 3)
    assert (model.n_elements, model.n_states, model.n_flags, model.n_events, model.sigma) == (3, 4, 3, 3, 1e5)


@pytest.mark.parametrize("make", [_maxwell_slip, _gms])
def test_parallel_elements_reversal_map(make):
    """Floats: after a reversal every flag is clear and the guard zero; an element within snap of
    its limit (Maxwell-slip: w_j; GMS: alpha_j Fs/Fc, sticking ones only) is put on it."""
    model = make()
    q = model.runtime_params()
    n = model.n_elements
    limit = q[n:2 * n] * (model.Fs / model.Fc if isinstance(model, pf.GMS) else 1.0)
    z = [limit[0] * (1.0 - 1e-9), 0.5 * limit[1], limit[2] * (1.0 - 1e-9), 0.3]  # moving along +1
    m = [0.0, 0.0, 1.0]
    zn, mn = model.reverse(z, m, -1.0, q, 1e-6)
    assert mn == [0.0] * n and zn[n] == 0.0 and zn[1] == z[1] and zn[0] == limit[0]
    assert zn[2] == (z[2] if isinstance(model, pf.GMS) else limit[2])
