"""prefriction.identify on motion data: Dahl from a free decay (the paper's situation).

Reference independent of the fitter: reversal times, positions and forces from
prefriction.exact_reversals, samples in between from scipy DOP853 at rtol 1e-12
(prefriction.identify.synthetic.dahl_free_decay), computed once without noise; each seed adds
its own Gaussian position noise. One nonlinear program serves the located-reversal fit and every
seed of the coverage study: the segment layout (the sample interval of each reversal) is that of
the exact reversal times, so it does not change with the noise. The mass-free fit, a second
program, uses the first half of the record.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.identify import IdentifiabilityWarning
from prefriction.identify.synthetic import dahl_free_decay

TRUE = pf.Dahl(sigma=1.0e4, Fc=1.0, gamma=1.0)
MASS = 1.0
TU = np.sqrt(MASS / TRUE.sigma)                     # time unit [s]
T = np.linspace(0.0, 16.0 * TU, 81)                 # 5 reversals, 0.2 time units per sample
V0 = 1.2 * TRUE.Fc / np.sqrt(MASS * TRUE.sigma)     # first excursion into gross sliding
NOISE = 0.003 * TRUE.Fc / TRUE.sigma                 # [m]
START = pf.Dahl(sigma=1.3e4, Fc=0.8, gamma=1.0)
TRUTH = np.array([TRUE.sigma, TRUE.Fc])


@pytest.fixture(scope="module")
def clean() -> np.ndarray:
    """Noise-free positions [m] at T (exact reversals + DOP853)."""
    return dahl_free_decay(TRUE, MASS, V0, T, 0.0, np.random.default_rng(0)).x


@pytest.fixture(scope="module")
def exact_times() -> np.ndarray:
    table = pf.exact_reversals(pf.Oscillator(TRUE, mass=MASS), V0, 20)
    return table.t[table.t < T[-1] - 2 * (T[1] - T[0])]


def noisy(clean: np.ndarray, seed: int, n: int | None = None, mass: float | None = MASS) -> identify.Motion:
    x = clean + NOISE * np.random.default_rng(seed).standard_normal(clean.size)
    return identify.Motion(T[:n], x[:n], 0.0, mass)


def test_free_decay_reversals_located_and_parameters_recovered(clean, exact_times):
    res = identify.fit(START, noisy(clean, 11), fixed=["gamma"], tol=1e-8)
    tau = res.nuisance["reversal times [s]"]
    assert tau.size == exact_times.size == 5
    np.testing.assert_allclose(tau, exact_times, atol=0.5 * (T[1] - T[0]))
    assert np.all(np.abs(res.estimates - TRUTH) <= 3.0 * res.stderr), res.report()
    assert res.statistics.sigma_hat == pytest.approx(NOISE, rel=0.3)
    assert res.mass == MASS and res.unidentifiable == ()


@pytest.mark.slow  # 20 fits (coverage over seeds, 6 s of CPU)
def test_free_decay_intervals_cover_the_true_parameters_in_18_of_20_seeds(clean, exact_times):
    inside = np.zeros(2, dtype=int)
    for seed in range(20):
        res = identify.fit(START, noisy(clean, seed), fixed=["gamma"], reversals=exact_times, tol=1e-8)
        inside += (res.low <= TRUTH) & (TRUTH <= res.high)
    assert np.all(inside >= 18), inside


def test_free_decay_cannot_separate_mass_sigma_and_Fc(clean, exact_times):
    """m x'' + F = 0 with m, sigma, Fc scaled together is the same motion."""
    half = T.size // 2 + 1
    data = noisy(clean, 12, half, mass=None)
    with pytest.warns(IdentifiabilityWarning) as rec:
        res = identify.fit(START, data, fixed=["gamma"], mass0=0.8, reversals=exact_times[exact_times < T[half - 3]],
                           tol=1e-8)
    assert set(res.unidentifiable) == {"sigma", "Fc", "mass"}, res.report()
    assert all("combination" in str(w.message) for w in rec)
    # what the data do determine: sigma / m and Fc / m
    assert res.estimate("sigma") / res.estimate("mass") == pytest.approx(TRUE.sigma / MASS, rel=0.01)
    assert res.estimate("Fc") / res.estimate("mass") == pytest.approx(TRUE.Fc / MASS, rel=0.02)


def test_motion_rejects_invalid_reversal_times(clean):
    data = noisy(clean, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="reversals must be finite times inside the record"):
            identify.fit(START, data, fixed=["gamma"], reversals=[-1.0])
