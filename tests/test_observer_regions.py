"""The friction observer's eigenvalue regions (docs/compensation.md#friction-observer) against numpy."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction import controllers


@pytest.mark.parametrize("pole, fast", [(500.0, 5000.0), (1000.0, 1500.0)])
def test_real_below_and_above_the_band_complex_inside_and_always_hurwitz(pole, fast):
    sigma, Fc, m = 1e6, 1.0, 2.5
    obs = controllers.FrictionObserver(pf.Dahl(sigma=sigma, Fc=Fc), pole=pole, fast_pole=fast)
    l1, l2 = obs.gains(m)
    low = Fc * (math.sqrt(fast) - math.sqrt(pole)) ** 2 / sigma
    high = Fc * (math.sqrt(fast) + math.sqrt(pole)) ** 2 / sigma
    assert obs.max_velocity() == pytest.approx(low, rel=1e-14)
    for v in np.concatenate([np.linspace(0.0, 0.999 * low, 7), np.linspace(1.001 * low, 0.999 * high, 7),
                             np.linspace(1.001 * high, 10 * high, 7)]):
        beta = sigma * v / Fc
        eig = np.linalg.eigvals(np.array([[-l1, -1.0 / m], [sigma - l2, -beta]]))
        assert np.all(eig.real < 0.0)  # frozen M is Hurwitz at every speed
        real = bool(np.all(np.abs(eig.imag) <= 1e-9 * np.abs(eig.real)))
        assert real == (v < low or v > high), (v, eig)
