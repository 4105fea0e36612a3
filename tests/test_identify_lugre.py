"""prefriction.identify with LuGre on motion data: multiple shooting for a rate-dependent model.

Reference independent of the fitter: the free decay of the LuGre oscillator from scipy's Radau,
restarted at every velocity reversal (a terminal event), in
prefriction.identify.synthetic.lugre_free_decay. Both fits share one nonlinear program: the
reversals located in the noise-free record fall in the sample intervals of the Radau events,
which the noisy fit is given.
"""

from __future__ import annotations

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.identify import motion_step
from prefriction.identify.synthetic import lugre_free_decay

TRUE = pf.LuGre(sigma0=1.0e4, sigma1=20.0, sigma2=0.4, Fc=1.0, Fs=1.3, vs=3.0e-3)
START = pf.LuGre(sigma0=1.2e4, sigma1=15.0, sigma2=0.4, Fc=0.8, Fs=1.3, vs=3.0e-3)
MASS = 1.0
TU = np.sqrt(MASS / TRUE.sigma0)                    # time unit [s]
T = np.linspace(0.0, 10.0 * TU, 51)
V0 = 1.2 * TRUE.Fc / np.sqrt(MASS * TRUE.sigma0)    # into gross sliding, then decaying pre-sliding swings
NOISE = 0.003 * TRUE.Fc / TRUE.sigma0               # [m]
FREE = ["sigma0", "sigma1", "Fc"]
TRUTH = np.array([TRUE.sigma0, TRUE.sigma1, TRUE.Fc])


def test_lugre_free_decay_recovered_by_multiple_shooting():
    clean, radau = lugre_free_decay(TRUE, MASS, V0, T, 0.0, np.random.default_rng(0))
    assert radau.size == 3
    exact = identify.fit(START, clean, free=FREE, tol=1e-9)
    built = len(motion_step._CACHE)
    tau = exact.nuisance["reversal times [s]"]
    np.testing.assert_allclose(tau, radau, atol=0.01 * (T[1] - T[0]))
    np.testing.assert_allclose(exact.estimates, TRUTH, rtol=1e-5)
    assert isinstance(exact.model, pf.LuGre) and exact.model.Fs == TRUE.Fs and exact.model.vs == TRUE.vs

    x = clean.x + NOISE * np.random.default_rng(1).standard_normal(T.size)
    res = identify.fit(START, identify.Motion(T, x, 0.0, MASS), free=FREE, reversals=radau, tol=1e-9)
    assert np.all(np.abs(res.estimates - TRUTH) <= 3.0 * res.stderr), res.report()
    assert res.statistics.sigma_hat == pytest.approx(NOISE, rel=0.25)
    assert res.unidentifiable == ()
    assert len(motion_step._CACHE) == built  # the noisy fit reuses the clean fit's programs
