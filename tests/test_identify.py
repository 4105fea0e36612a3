"""prefriction.identify on force-displacement data: coverage of the 95 % intervals over 20 noise
seeds, the identifiability warning, a Maxwell-slip fit, and bad input.

References independent of the fitter: Dahl forces along the prescribed displacement from the
closed-form branches (prefriction.analysis.branch.force_after_distance, any gamma, via
prefriction.identify.synthetic), Maxwell-slip forces from the elementwise clip recursion of
elasto-plastic elements written out here.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.identify import ForceDisplacement, IdentifiabilityWarning, Motion
from prefriction.identify.synthetic import dahl_loop_force, dahl_loops

TRUE = pf.Dahl(sigma=2.0e4, Fc=1.5, gamma=1.5)
START = pf.Dahl(sigma=1.4e4, Fc=1.1, gamma=1.2)
T = np.linspace(0.0, 3.0, 241)


def loops(amplitude: float) -> np.ndarray:
    """Growing loops of peak ``amplitude`` in units Fc / sigma."""
    return amplitude * TRUE.Fc / TRUE.sigma * np.sin(2 * np.pi * T) * (0.3 + 0.7 * T / 3.0)


def test_dahl_intervals_cover_the_true_parameters_in_18_of_20_seeds():
    x = loops(3.0)
    names = ("sigma", "Fc", "gamma")
    truth = np.array([TRUE.sigma, TRUE.Fc, TRUE.gamma])
    inside = np.zeros(3, dtype=int)
    with warnings.catch_warnings():
        warnings.simplefilter("error", IdentifiabilityWarning)
        for seed in range(20):
            data = dahl_loops(TRUE, T, x, 0.01 * TRUE.Fc, np.random.default_rng(seed))
            res = identify.fit(START, data)
            assert res.names == names
            inside += (res.low <= truth) & (truth <= res.high)
    assert np.all(inside >= 18), dict(zip(names, inside))


def test_fit_recovers_dahl_and_reports():
    data = dahl_loops(TRUE, T, loops(3.0), 0.005 * TRUE.Fc, np.random.default_rng(1))
    res = identify.fit(START, data)
    assert isinstance(res.model, pf.Dahl)
    assert res.model.sigma == pytest.approx(TRUE.sigma, rel=0.02)
    assert res.model.Fc == pytest.approx(TRUE.Fc, rel=0.02)
    assert res.model.gamma == pytest.approx(TRUE.gamma, rel=0.05)
    # residual sd close to the noise; residuals are data minus fit
    assert res.statistics.sigma_hat == pytest.approx(0.005 * TRUE.Fc, rel=0.15)
    np.testing.assert_allclose(res.residuals, data.F - res.fitted, atol=1e-14)
    assert res.correlation.shape == (3, 3) and np.allclose(np.diag(res.correlation), 1.0)
    text = res.report()
    assert "95 % interval" in text and "identifiable" in text and "sigma" in text
    assert "Dahl" in repr(res) and len(repr(res)) < 200
    assert res.interval("Fc")[0] < res.estimate("Fc") < res.interval("Fc")[1]
    with pytest.raises(ValueError, match="name must be one of"):
        res.estimate("mass")


def test_fixed_parameter_stays_and_bounds_are_kept():
    data = dahl_loops(TRUE, T, loops(3.0), 0.005 * TRUE.Fc, np.random.default_rng(2))
    res = identify.fit(pf.Dahl(1.4e4, 1.1, 1.5), data, fixed=["gamma"], bounds={"sigma": (1e4, 1.9e4)})
    assert res.names == ("sigma", "Fc") and res.model.gamma == 1.5
    assert res.estimate("sigma") == pytest.approx(1.9e4)  # the bound below the true 2e4 holds


def test_pre_sliding_loops_warn_that_Fc_is_not_identifiable():
    data = dahl_loops(TRUE, T, loops(0.01), 0.02 * 0.01 * TRUE.Fc, np.random.default_rng(3))
    with pytest.warns(IdentifiabilityWarning, match="Fc") as rec:
        res = identify.fit(START, data, fixed=["gamma"])
    assert "Fc" in res.unidentifiable and "sigma" not in res.unidentifiable
    assert not any("identify sigma" in str(w.message) for w in rec)
    assert res.estimate("sigma") == pytest.approx(TRUE.sigma, rel=0.01)
    assert "NOT IDENTIFIABLE" in res.report()


def test_gross_sliding_loops_do_not_warn():
    data = dahl_loops(TRUE, T, loops(3.0), 0.01 * TRUE.Fc, np.random.default_rng(4))
    with warnings.catch_warnings():
        warnings.simplefilter("error", IdentifiabilityWarning)
        res = identify.fit(START, data, fixed=["gamma"])
    assert res.unidentifiable == ()


def maxwell_force(k: np.ndarray, W: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Elasto-plastic elements from rest along a piecewise-linear x: z_i <- clip(z_i + k_i dx, +-W_i)."""
    z = np.zeros(k.size)
    out = [0.0]
    for dx in np.diff(x):
        z = np.clip(z + k * dx, -W, W)
        out.append(z.sum())
    return np.array(out)


def test_maxwell_slip_two_elements():
    k, W = np.array([6e4, 2e4]), np.array([0.4, 0.6])
    t = np.linspace(0.0, 2.0, 201)
    x = 40e-6 * np.sin(2 * np.pi * t) * (0.25 + 0.75 * t / 2.0)
    F = maxwell_force(k, W, x) + 0.003 * np.random.default_rng(5).standard_normal(t.size)
    res = identify.fit(pf.MaxwellSlip([5e4, 2.5e4], [0.3, 0.7]), ForceDisplacement(t, x, F))
    assert isinstance(res.model, pf.MaxwellSlip)
    assert res.names == ("stiffness[0]", "stiffness[1]", "slip_force[0]", "slip_force[1]")
    truth = np.concatenate([k, W])
    assert np.all(np.abs(res.estimates - truth) <= 3.0 * res.stderr), res.report()
    np.testing.assert_allclose(res.estimates, truth, rtol=0.01)


# ----------------------------------------------------------------------------- bad input
GOOD_T = np.linspace(0.0, 1.0, 20)
GOOD_X = 1e-4 * np.sin(2 * np.pi * GOOD_T)
GOOD_F = dahl_loop_force(TRUE, GOOD_X)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"t": np.r_[GOOD_T[:5], np.nan, GOOD_T[6:]]}, r"t\[5\] must be finite"),
    ({"F": np.r_[GOOD_F[:3], np.inf, GOOD_F[4:]]}, r"F\[3\] must be finite"),
    ({"t": GOOD_T[::-1]}, "t must be strictly increasing, got decreasing"),
    ({"t": np.r_[GOOD_T[:4], GOOD_T[3], GOOD_T[5:]]}, "got repeated times"),
    ({"t": GOOD_T[:5], "x": GOOD_X[:5], "F": GOOD_F[:5]}, "t must hold 8 to"),
    ({"x": np.full(20, 2e-5)}, "x must vary, got a constant signal"),
    ({"F": np.zeros(20)}, "F must vary"),
    ({"F": GOOD_F[:-1]}, r"F must have one sample per time, got len\(F\) = 19"),
    ({"x": GOOD_X.reshape(4, 5)}, r"x must be a 1-D array"),
])
def test_bad_force_displacement_data_is_rejected(kwargs, match):
    args = {"t": GOOD_T, "x": GOOD_X, "F": GOOD_F, **kwargs}
    with pytest.raises(ValueError, match=match):
        ForceDisplacement(**args)


def test_bad_types_and_motion_data():
    with pytest.raises(TypeError, match="x must be a 1-D array of real numbers"):
        ForceDisplacement(GOOD_T, "abc", GOOD_F)
    with pytest.raises(TypeError, match="F must be"):
        ForceDisplacement(GOOD_T, GOOD_X, [True] * 20)
    with pytest.raises(ValueError, match="mass must be finite and > 0"):
        Motion(GOOD_T, GOOD_X, 0.0, mass=-1.0)
    with pytest.raises(ValueError, match=r"u must have one sample per time"):
        Motion(GOOD_T, GOOD_X, np.zeros(12))
    with pytest.raises(ValueError, match="u must be a finite number"):
        Motion(GOOD_T, GOOD_X, np.nan)
    with pytest.raises(ValueError, match="x must vary"):
        Motion(GOOD_T, np.zeros(20))
    assert Motion(GOOD_T, GOOD_X).free_decay and "free decay" in repr(Motion(GOOD_T, GOOD_X))


def test_bad_fit_arguments():
    data = ForceDisplacement(GOOD_T, GOOD_X, GOOD_F)
    with pytest.raises(TypeError, match="unexpected keyword"):
        identify.fit(START, data, solver="lm")
    with pytest.raises(TypeError, match="model must be a prefriction.FrictionModel"):
        identify.fit("Dahl", data)
    with pytest.raises(TypeError, match="data must be"):
        identify.fit(START, (GOOD_T, GOOD_X, GOOD_F))
    with pytest.raises(ValueError, match="free names an unknown parameter 'Fs'"):
        identify.fit(START, data, free=["Fs"])
    with pytest.raises(ValueError, match=r"free and fixed both name \['Fc'\]"):
        identify.fit(START, data, free=["Fc"], fixed=["Fc"])
    with pytest.raises(ValueError, match="no parameter left to fit"):
        identify.fit(START, data, fixed=["sigma", "Fc", "gamma"])
    with pytest.raises(ValueError, match=r"bounds\['gamma'\] = \(0.5, 2.0\) must satisfy 1.0 <= low"):
        identify.fit(START, data, bounds={"gamma": (0.5, 2.0)})  # gamma >= 1 keeps the structure
    with pytest.raises(ValueError, match="must contain the start value"):
        identify.fit(START, data, bounds={"sigma": (2e4, 3e4)})
    with pytest.raises(ValueError, match="mass0 .* force-displacement data involve no mass"):
        identify.fit(START, data, mass0=1.0)
    with pytest.raises(ValueError, match="substeps must be an integer in"):
        identify.fit(START, data, substeps=100)
    with pytest.raises(ValueError, match="mass0 must be given"):
        identify.fit(START, Motion(GOOD_T, GOOD_X), fixed=["gamma"])
