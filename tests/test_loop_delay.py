"""The stability check of a sampled loop counts its measurement delay (issue 26, item 9).

``simulate_loop(..., delay=d)`` feeds the controller ``x(t_{k-d})``. The linear loop is then
``1 + P(z) C(z) z^-d = 0``; before, the check ignored ``z^-d`` and a loop that ends at 33 km
ran without a word. The reference is the characteristic polynomial written by hand from the
closed-form ZOH discretisation of ``1 / (m s^2 + sigma)``.
"""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest

import controllers
from controllers._linear import as_lti
import prefriction as pf
from prefriction.signals import Sine

STAGE = pf.Oscillator(pf.Dahl(sigma=1e6, Fc=1.0), mass=1.0)
TS = 1e-4


def _largest_pole_by_hand(C: control.TransferFunction, d: int) -> float:
    """Largest |z| of den_P den_C z^d + num_P num_C = 0, with the exact ZOH plant
    P(z) = (1 - c)/k (z + 1) / (z^2 - 2 c z + 1), c = cos(w0 Ts), w0 = sqrt(k/m)."""
    k, m = STAGE.friction.sigma, STAGE.mass
    c = math.cos(math.sqrt(k / m) * TS)
    numP, denP = (1.0 - c) / k * np.array([1.0, 1.0]), np.array([1.0, -2.0 * c, 1.0])
    numC, denC = np.ravel(C.num[0][0]), np.ravel(C.den[0][0])
    poly = np.polyadd(np.polymul(np.polymul(denP, denC), np.r_[1.0, np.zeros(d)]), np.polymul(numP, numC))
    return float(np.max(np.abs(np.roots(poly))))


def _pid():
    return controllers.design_pid(STAGE, wn=2 * math.pi * 150)


@pytest.mark.parametrize("d", [0, 2, 3, 8])
def test_closed_loop_poles_include_the_delay(d: int) -> None:
    Cd = control.tf(control.c2d(as_lti(_pid()), TS, method="zoh"))
    T = controllers.closed_loop(STAGE, Cd, warn=False, delay=d)
    got = float(np.max(np.abs(control.poles(T))))
    assert got == pytest.approx(_largest_pole_by_hand(Cd, d), rel=1e-9)


def _run(d: int):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = controllers.simulate_loop(STAGE, _pid(), Sine(5e-6, 1.0, -math.pi / 2, 5e-6), Ts=TS, t_end=0.05, delay=d)
    return res, [w for w in caught if issubclass(w.category, controllers.UnstableLoopWarning)]


def test_delayed_loop_that_diverges_warns_with_the_delay() -> None:
    res, caught = _run(8)
    assert np.max(np.abs(res.x)) > 1.0  # it does diverge (33 km at 50 ms) ...
    assert len(caught) == 1  # ... and says so, naming the delay
    msg = str(caught[0].message)
    assert "delay of 8 samples" in msg and "not asymptotically stable" in msg


def test_delayed_loop_that_is_stable_runs_quietly() -> None:
    res, caught = _run(2)
    assert not caught
    assert np.max(np.abs(res.x)) < 3e-7  # the 5 um-peak-to-peak reference tracked within the pre-sliding range


def test_delay_with_a_continuous_controller_is_refused() -> None:
    with pytest.raises(ValueError, match="delay=2"):
        controllers.closed_loop(STAGE, _pid(), delay=2)
