"""Fits that hold on a measured record: offset, both Dahl structures, bounds, convergence,
prediction and validation on held-out data (prefriction.identify, docs/identify.md).

References independent of the fitter: Dahl forces from the closed-form branches
(prefriction.analysis.branch.force_after_distance via prefriction.identify.synthetic), the
offset of the tribometer record from the midpoint of its two gross-sliding plateaus, the fit %
of a hand-made case, and the measured record itself (held-out cycles never seen by the fit).
The real-record fits use every 4th (Dahl) or 8th (GMS, Maxwell-slip) sample of 12-60 s to stay
fast; the held-out score uses every 4th sample of 150-198 s.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.data import tribometer
from prefriction.identify import BoundWarning, ConvergenceWarning, ForceDisplacement, Validation
from prefriction.identify.synthetic import dahl_loop_force
from prefriction.identify.validation import predict_force

HELD_OUT_RMS = 0.12
"""Held-out rms [N] the best fit must reach on 150-198 s (issue 17 target; 0.149 N before offsets)."""


@pytest.fixture(scope="module")
def record():
    rec = tribometer()
    return rec.window(12.0, 60.0, step=4), rec.window(150.0, 198.0, step=4)


@pytest.fixture(scope="module")
def dahl_fit(record):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BoundWarning)
        return identify.fit(pf.Dahl(sigma=4e4, Fc=2.4, gamma=1.5), record[0], offset=True, structures="both")


def test_real_record_dahl_with_offset_holds_on_held_out_cycles(dahl_fit, record):
    res = dahl_fit
    assert res.model.gamma < 1.0                      # both structures tried, gamma < 1 kept
    assert "compared both Dahl structures" in res.notes[-1] and "kept gamma < 1" in res.notes[-1]
    val = res.validate(record[1], skip=2.0)
    assert val.rms <= HELD_OUT_RMS, val
    assert res.validate(record[1]).rms <= HELD_OUT_RMS          # initial state from the first force
    # the offset against the midpoint of the gross-sliding plateaus of the fitted part
    F = record[0].F
    mid = 0.5 * (np.median(F[F > 2.0]) + np.median(F[F < -2.0]))
    lo, hi = res.interval("offset")
    assert lo > 0.0 and abs(res.estimate("offset") - mid) < 0.03, (res.interval("offset"), mid)
    assert res.success and "offset" in res.report()


GMS_FIXED = ["alpha[0]", "alpha[1]", "alpha[2]", "vs", "delta", "sigma2", "damping[0]", "damping[1]", "damping[2]"]


@pytest.mark.parametrize(("start", "kwargs"), [
    (pf.GMS(k=[2e5, 4e4, 1e4], alpha=[0.4, 0.33, 0.27], Fc=2.35, Fs=2.5, vs=1e-4, C=20.0, sigma2=1.0,
            damping=[1e-3] * 3), dict(fixed=GMS_FIXED)),
    (pf.MaxwellSlip(stiffness=[1e5, 4e4, 5e3], slip_force=[0.3, 1.8, 0.2]), dict(max_iter=1000)),
], ids=["GMS3", "MaxwellSlip3"])
def test_real_record_element_models_with_offset_hold_on_held_out_cycles(record, start, kwargs):
    """Fitted on every 8th sample (25 Hz) of 12-60 s to stay fast (the example uses 200 Hz)."""
    data = tribometer().window(12.0, 60.0, step=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", identify.IdentifiabilityWarning)   # C, or a vanishing element
        warnings.simplefilter("ignore", BoundWarning)
        res = identify.fit(start, data, offset=True, **kwargs)
    assert res.success
    assert res.validate(record[1], skip=2.0).rms <= HELD_OUT_RMS
    F = data.F
    mid = 0.5 * (np.median(F[F > 2.0]) + np.median(F[F < -2.0]))
    assert abs(res.estimate("offset") - mid) < 0.03


def test_dahl_started_at_gamma_above_one_warns_on_the_structure_bound(record):
    with pytest.warns(BoundWarning, match="gamma = 1 ends on its lower bound 1 .*structure boundary"):
        res = identify.fit(pf.Dahl(sigma=4e4, Fc=2.4, gamma=1.5), record[0], offset=True, structures="given")
    i = res.names.index("gamma")
    assert res.low[i] == 1.0 and res.high[i] > 1.0     # one-sided: never below the boundary
    assert "structure boundary" in res.flags[i] and "structure boundary" in res.report()


# ----------------------------------------------------------------- synthetic, record-like
TRUE = pf.Dahl(sigma=4.0e4, Fc=2.35, gamma=0.06)
OFFSET, NOISE = 0.1, 0.11
T = np.arange(0.0, 12.0, 0.02)                       # 50 Hz, about 6.5 cycles


def triangle(t: np.ndarray) -> np.ndarray:
    """0.23 mm triangular stroke at 0.26 mm/s, starting mid-stroke (as a held-out window does)."""
    period = 2 * 0.23e-3 / 0.26e-3
    phase = (t / period + 0.25) % 1.0
    return 0.23e-3 * np.where(phase < 0.5, 2 * phase, 2 - 2 * phase)


CLEAN = dahl_loop_force(TRUE, triangle(T)) + OFFSET


@pytest.mark.slow  # 20 fits (coverage over seeds, 4 s of CPU)
def test_offset_and_dahl_intervals_cover_on_record_like_data():
    truth = np.array([TRUE.sigma, TRUE.Fc, TRUE.gamma, OFFSET])
    inside = np.zeros(4, dtype=int)
    start = pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error", BoundWarning)
        warnings.simplefilter("error", ConvergenceWarning)
        for seed in range(20):
            F = CLEAN + NOISE * np.random.default_rng(seed).standard_normal(T.size)
            res = identify.fit(start, ForceDisplacement(T, triangle(T), F), offset=True, structures="given",
                               tol=1e-9)   # at 1e-10 seed 19 needs > 1000 evaluations (the events kink the cost)
            assert res.names == ("sigma", "Fc", "gamma", "offset") and res.success
            inside += (res.low <= truth) & (truth <= res.high)
    assert np.all(inside >= 17), dict(zip(("sigma", "Fc", "gamma", "offset"), inside))


def test_prediction_from_mid_cycle_matches_the_closed_form():
    x = triangle(T)
    for model, tol in ((TRUE, 1e-9), (pf.Dahl(sigma=4.0e4, Fc=2.35, gamma=1.5), 1e-5)):
        F = dahl_loop_force(model, x) + OFFSET
        k = 137                                        # a held-out record starting mid-stroke
        held = ForceDisplacement(T[k:], x[k:], F[k:])
        pred = predict_force(model, held, offset=OFFSET)
        assert np.max(np.abs(pred - F[k:])) <= tol * model.Fc
        warm = predict_force(model, held, offset=OFFSET, warmup=1.0)   # state from the first second
        assert np.max(np.abs(warm - F[k:])) <= max(tol, 1e-7) * model.Fc


def test_fit_result_predict_and_validate_on_held_out_noise_free_data():
    x = triangle(T)
    res = identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5), ForceDisplacement(T[:300], x[:300], CLEAN[:300]),
                       offset=True, structures="given")
    held = ForceDisplacement(T[300:], x[300:], CLEAN[300:])
    np.testing.assert_allclose(res.predict(held), CLEAN[300:], atol=1e-6)
    val = res.validate(held)
    assert val.rms < 1e-6 and val.fit_percent > 99.999
    with pytest.raises(TypeError, match="data must be ForceDisplacement"):
        res.predict(identify.Motion(T, x))


def test_validation_measures_by_hand(tmp_path):
    val = Validation(np.arange(4.0), np.array([1.0, 2.0, 3.0, 4.0]), np.array([1.0, 2.0, 3.0, 5.0]), "N", "Dahl")
    assert val.rms == pytest.approx(0.5)                          # sqrt(1/4)
    assert val.nrmse == pytest.approx(1.0 / np.sqrt(5.0))          # ||e|| / ||y - 2.5||
    assert val.fit_percent == pytest.approx(100.0 * (1.0 - 1.0 / np.sqrt(5.0)))
    assert "fit 55.28 %" in repr(val) and "rms error" in val.summary()
    assert val.plot(tmp_path / "v.png").stat().st_size > 10_000


def test_dahl_plus_viscous_recovers_the_viscous_coefficient():
    t = np.linspace(0.0, 4.0, 801)
    w = 2 * np.pi * 1.0
    x = 2e-4 * np.sin(w * t) * (0.5 + 0.5 * t / 4.0)
    v = 2e-4 * (w * np.cos(w * t) * (0.5 + 0.5 * t / 4.0) + np.sin(w * t) * 0.5 / 4.0)
    F = dahl_loop_force(TRUE, x) + 200.0 * v + 0.004 * np.random.default_rng(3).standard_normal(t.size)
    res = identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5) + pf.Viscous(100.0), ForceDisplacement(t, x, F),
                       structures="given")
    assert res.names == ("sigma", "Fc", "gamma", "b")
    b, se = res.estimate("b"), res.stderr[res.names.index("b")]
    assert abs(b - 200.0) < 3 * se + 2.0, (b, se)   # + 2: the fit's central-difference velocity
    assert res.model.models[0].Fc == pytest.approx(TRUE.Fc, rel=0.01)


# ----------------------------------------------------------------- bad input, convergence
@pytest.fixture(scope="module")
def small():
    return ForceDisplacement(T[:200], triangle(T[:200]), CLEAN[:200])


@pytest.mark.parametrize(("kwargs", "exc", "match"), [
    (dict(tol=10.0), ValueError, r"tol must be in \[1e-14, 1e-06\], got 10.0"),
    (dict(tol=1e-20), ValueError, "tol must be in"),
    (dict(bounds=[(1e4, 1e5)]), TypeError, "bounds must be a dict .* got .* of type list"),
    (dict(max_iter=0), ValueError, "max_iter must be an integer >= 1"),
    (dict(max_iter=10**6), ValueError, "max_iter must be an integer <= 100_000"),
    (dict(offset="yes"), TypeError, "offset must be True or False"),
    (dict(structures="all"), ValueError, "structures must be 'both' or 'given'"),
])
def test_argument_checks(small, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5), small, **kwargs)


def test_offset_is_refused_for_a_free_decay():
    t = np.linspace(0.0, 1.0, 50)
    with pytest.raises(ValueError, match="offset=True"):   # no force to tell an offset from
        identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=1.5), identify.Motion(t, 1e-5 * np.sin(t)), offset=True,
                     mass0=1.0)


def test_a_fit_stopped_at_max_iter_says_so(small):
    with pytest.warns(ConvergenceWarning, match="did not converge"):
        res = identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5), small, offset=True, structures="given", max_iter=2)
    assert not res.success and "max_iter = 2" in res.message
    assert "NOT CONVERGED" in repr(res) and "NOT CONVERGED" in res.report() and "NOT CONVERGED" in res.summary()


def test_user_bound_interval_stays_inside(small):
    with pytest.warns(BoundWarning, match="sigma = 35000 ends on its upper bound 35000 .*user bound"):
        res = identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5), small, offset=True, structures="given",
                           bounds={"sigma": (1e4, 3.5e4)})
    lo, hi = res.interval("sigma")
    assert hi == 3.5e4 and lo < hi


def test_plots_refuse_a_missing_directory(small, tmp_path):
    res = identify.fit(pf.Dahl(sigma=3e4, Fc=2.0, gamma=0.5), small, offset=True, structures="given")
    missing = tmp_path / "nowhere" / "x.png"
    with pytest.raises(ValueError, match="path must be in an existing directory"):
        res.plot(missing)
    with pytest.raises(ValueError, match="path must be in an existing directory"):
        res.validate(small).plot(missing)
    assert "residual sd" in res.summary() and res.summary().count("\n") < 12
