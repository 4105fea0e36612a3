"""Static friction maps (Coulomb + viscous + Stribeck, direction-dependent) fitted to ForceVelocity data.

References: the linear map against numpy's least squares and the closed-form OLS covariance
``s^2 (X^T X)^-1``; the Stribeck map against its true parameters on synthetic data (coverage
over seeds); the map's force against equation (1) written out here.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.stats import t as student_t

import prefriction as pf
from prefriction import identify
from prefriction.identify import ForceVelocity, StaticFriction

V = np.r_[-np.logspace(-4, -0.7, 25), np.logspace(-4, -0.7, 25)]
TRUE = StaticFriction(Fc=20.0, b=200.0, Fs=30.0, vs=2e-3, delta=2.0, Fc_neg=17.0, Fs_neg=26.0)


def test_force_is_equation_1():
    v = np.array([-0.01, -1e-3, 1e-3, 0.01])
    e = np.exp(-np.abs(v / 2e-3) ** 2.0)
    want = np.where(v > 0, 20.0 + 10.0 * e, -(17.0 + 9.0 * e)) + 200.0 * v
    np.testing.assert_allclose(TRUE.force(v), want, rtol=1e-15)
    assert TRUE.force([0.0])[0] == 0.0


def test_jacobian_against_central_differences():
    v = np.linspace(-0.02, 0.02, 41)
    _F, J = TRUE.force_and_jacobian(v)
    for i, name in enumerate(TRUE.names):
        h = 1e-6 * getattr(TRUE, name)
        up = TRUE.replace({name: getattr(TRUE, name) + h}).force(v)
        dn = TRUE.replace({name: getattr(TRUE, name) - h}).force(v)
        np.testing.assert_allclose(J[:, i], (up - dn) / (2 * h), rtol=1e-6, atol=1e-6 * np.abs(J).max())


def test_linear_map_is_ordinary_least_squares():
    rng = np.random.default_rng(3)
    F = StaticFriction(Fc=20.0, b=200.0, Fc_neg=17.0).force(V) + 0.3 * rng.standard_normal(V.size)
    res = identify.fit(StaticFriction(Fc=5.0, b=50.0, Fc_neg=5.0), ForceVelocity(V, F))
    X = np.column_stack([(V > 0).astype(float), V, -(V < 0).astype(float)])   # Fc, b, Fc_neg
    coef, *_ = np.linalg.lstsq(X, F, rcond=None)
    np.testing.assert_allclose(res.estimates, coef, rtol=1e-9)
    r = F - X @ coef
    s2 = r @ r / (V.size - 3)
    se = np.sqrt(np.diag(s2 * np.linalg.inv(X.T @ X)))
    np.testing.assert_allclose(res.stderr, se, rtol=1e-6)
    tq = student_t.ppf(0.975, V.size - 3)
    np.testing.assert_allclose(res.low, coef - tq * se, rtol=1e-6)
    assert res.names == ("Fc", "b", "Fc_neg") and "N" in res.summary()


def test_stribeck_map_intervals_cover_the_truth_over_seeds():
    inside = np.zeros(len(TRUE.names), dtype=int)
    start = StaticFriction(Fc=15.0, b=100.0, Fs=20.0, vs=1e-3, Fc_neg=15.0, Fs_neg=20.0)
    truth = np.array([TRUE.values()[n] for n in TRUE.names])
    for seed in range(20):
        F = TRUE.force(V) + 0.3 * np.random.default_rng(seed).standard_normal(V.size)
        res = identify.fit(start, ForceVelocity(V, F))
        inside += (res.low <= truth) & (truth <= res.high)
    assert np.all(inside >= 17), dict(zip(TRUE.names, inside))


def test_offset_with_symmetric_levels_and_confounded_with_asymmetric_ones():
    F = StaticFriction(Fc=20.0, b=200.0).force(V) - 3.0 + 0.1 * np.random.default_rng(0).standard_normal(V.size)
    res = identify.fit(StaticFriction(Fc=10.0, b=100.0), ForceVelocity(V, F), offset=True)
    assert abs(res.estimate("offset") + 3.0) <= 3 * res.stderr[res.names.index("offset")]
    with pytest.warns(identify.IdentifiabilityWarning, match="offset"):
        identify.fit(StaticFriction(Fc=10.0, b=100.0, Fc_neg=10.0), ForceVelocity(V, F), offset=True)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="Fc"):
        StaticFriction(Fc=-1.0)
    with pytest.raises(ValueError, match="Fs_neg"):
        StaticFriction(Fc=1.0, Fs_neg=2.0)
    with pytest.raises(ValueError, match="F must have one sample per velocity"):
        ForceVelocity(V, np.ones(V.size - 1))
    with pytest.raises(TypeError, match="ForceVelocity"):
        identify.fit(StaticFriction(Fc=1.0), identify.ForceDisplacement(np.arange(10.0), np.sin(np.arange(10.0)),
                                                                        np.cos(np.arange(10.0))))
    with pytest.raises(TypeError, match="ForceVelocity"):
        identify.fit(pf.Dahl(1e4, 1.0), ForceVelocity(V, TRUE.force(V)))
    with pytest.raises(ValueError, match="unknown parameter 'vs'"):
        identify.fit(StaticFriction(Fc=1.0), ForceVelocity(V, TRUE.force(V)), fixed=["vs"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="no parameter left"):
            identify.fit(StaticFriction(Fc=1.0), ForceVelocity(V, TRUE.force(V)), fixed=["Fc", "b"])


def test_predict_plot_and_report_of_a_static_fit(tmp_path):
    F = TRUE.force(V) + 0.3 * np.random.default_rng(5).standard_normal(V.size)
    res = identify.fit(StaticFriction(Fc=15.0, b=100.0, Fs=20.0, vs=1e-3, Fc_neg=15.0, Fs_neg=20.0), ForceVelocity(V, F))
    np.testing.assert_allclose(res.predict(ForceVelocity(V, F)), F - res.residuals, rtol=1e-12, atol=1e-12)
    assert "residual sd" in res.report() and " N " in res.report()
    assert res.plot(tmp_path / "map.png").stat().st_size > 0
    with pytest.raises(TypeError, match="ForceVelocity data have none"):
        res.validate(ForceVelocity(V, F))
