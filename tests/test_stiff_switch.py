"""Stiff and extreme unforced runs (issue 26, item 14), against references from the equations.

- GMS with a stiff slip law (``C = 1e7`` N/s): the explicit Runge-Kutta step is held by
  stability (0.66 M steps for 6 reversals); the native driver detects it and the run continues
  on Radau, saying so in ``result.message``. Reference: scipy's Radau on the GMS equations in SI.
- Dahl with gamma >= 1 in deep gross sliding (normalised speed 1e7 to 1e10): the first reversal
  lands on the energy balance ``m v0^2 / 2 = Fc x - (hysteretic potential)``; before, runs above
  about 1.5e7 stopped with "more than 1e6 steps without a reversal ... try a looser rtol".
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf

from _gms_radau import gms_reversals

GMS_P = dict(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=1e7)
MASS, V0, N_REV = 1.0, 0.05, 6


def _gms_reference():
    """Reversals (t, x, F) of m x'' = -sum F_i from x = 0, v = V0, unloaded elements (scipy's Radau on
    the GMS equations, tests/_gms_radau.py)."""
    return gms_reversals(GMS_P, MASS, np.r_[0.0, V0, np.zeros(len(GMS_P["k"]))], n_rev=N_REV)


@pytest.fixture(scope="module")
def gms_rows():
    return _gms_reference()


def test_stiff_slip_law_switches_to_radau_and_meets_the_tolerance(gms_rows) -> None:
    rtol = 1e-7  # measured: 0.01 rtol at 1e-8
    res = pf.simulate(pf.Oscillator(pf.GMS(**GMS_P), mass=MASS), V0, reversals=N_REV, rtol=rtol)
    assert "implicit Radau" in res.message and "stiff" in res.message
    tab = res.reversals
    assert np.max(np.abs(tab.t / gms_rows[:, 0] - 1.0)) <= 10 * rtol
    assert np.max(np.abs(tab.x - gms_rows[:, 1])) <= 10 * rtol * np.max(np.abs(gms_rows[:, 1]))
    assert np.max(np.abs(tab.F - gms_rows[:, 2])) <= 10 * rtol * np.max(np.abs(gms_rows[:, 2]))
    assert res.stats.steps < 60_000  # the explicit part stops at about 20,000 steps (was 0.66 M)


def test_soft_slip_law_stays_explicit() -> None:
    res = pf.simulate(pf.Oscillator(pf.GMS(**dict(GMS_P, C=2e3)), mass=MASS), V0, reversals=N_REV)
    assert "Radau" not in res.message


@pytest.mark.parametrize("gamma, tail", [(1.0, 1.0), (1.5, 2.0)])
@pytest.mark.parametrize("speed", [1e7, 3e7, 1e10])
def test_deep_gross_sliding_lands_on_the_energy_balance(gamma: float, tail: float, speed: float) -> None:
    """Normalised: v0^2/2 = x - int_0^x (1 - F) dx, and int_0^inf (1 - F) dp = 1/(2 - gamma) for
    F = 1 - (1 + (gamma - 1) p)^(-1/(gamma - 1)) (exp(-p) for gamma = 1), so the first reversal
    is at x = v0^2/2 + 1/(2 - gamma) with F = Fc (the tail beyond x is below round-off)."""
    sigma, Fc, m, rtol = 1e4, 1.0, 1.0, 1e-8
    V, X = Fc / math.sqrt(m * sigma), Fc / sigma  # velocity and length units [m/s, m]
    res = pf.simulate(pf.Oscillator(pf.Dahl(sigma, Fc, gamma), mass=m), speed * V, reversals=1, rtol=rtol)
    x_ref = (0.5 * speed**2 + tail) * X
    assert abs(res.reversals.x[0] / x_ref - 1.0) <= 10 * rtol
    assert res.reversals.F[0] == pytest.approx(Fc, rel=1e-15)
    assert res.stats.steps < 5_000


def test_deep_gross_sliding_without_a_compiler_too() -> None:
    """The interpreted compact model (``jit=False``) holds the log-gap the same way."""
    sigma, Fc, rtol, speed = 1e4, 1.0, 1e-8, 1e10
    res = pf.simulate(pf.Oscillator(pf.Dahl(sigma, Fc, 1.0), mass=1.0), speed * Fc / math.sqrt(sigma),
                      reversals=1, rtol=rtol, jit=False)
    assert abs(res.reversals.x[0] / ((0.5 * speed**2 + 1.0) * Fc / sigma) - 1.0) <= 10 * rtol
