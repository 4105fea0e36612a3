"""A stiff forced run: GMS with a stiff slip law (``C = 1e7`` N/s) under a sine force. The forced
native driver detects the stiffness (the explicit step held by stability, 2.75 M steps for
0.2 s) and the run continues on Radau (``prefriction/simulation/stiff_forced.py``), saying so in
``result.message``. Reference: scipy's Radau on the GMS equations in SI (tests/_gms_radau.py) with
the force written here."""

from __future__ import annotations

import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.signals import Sine
from prefriction.simulation.compiled import jit_available

from _gms_radau import gms_reversals

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native driver needs a C compiler")

GMS_P = dict(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=1e7)
MASS, AMP, FREQ, T_END = 1.0, 2.0, 5.0, 0.5


def _reference() -> np.ndarray:
    """Reversals (t, x, F) of m x'' = u(t) - sum F_i, u = AMP sin(2 pi FREQ t), from rest with the
    first motion in +x (scipy's Radau on the GMS equations, tests/_gms_radau.py)."""
    return gms_reversals(GMS_P, MASS, np.zeros(len(GMS_P["k"]) + 2), lambda t: AMP * math.sin(2 * math.pi * FREQ * t),
                         t_end=T_END)


def test_stiff_forced_run_switches_to_radau_and_meets_the_tolerance() -> None:
    rtol = 1e-7
    res = pf.simulate(pf.Oscillator(pf.GMS(**GMS_P), MASS, Sine(AMP, FREQ)), 0.0, t_end=T_END, rtol=rtol)
    assert "implicit Radau" in res.message and "stiff" in res.message
    ref = _reference()
    tab = res.reversals
    assert len(tab) == len(ref) >= 3
    assert np.max(np.abs(tab.t - ref[:, 0])) <= 10 * rtol * T_END
    assert np.max(np.abs(tab.x - ref[:, 1])) <= 10 * rtol * np.max(np.abs(ref[:, 1]))
    assert np.max(np.abs(tab.F - ref[:, 2])) <= 10 * rtol * np.max(np.abs(ref[:, 2]))
    assert res.stats.steps < 100_000  # the explicit part stops at about 20,000 steps (2.75 M for 0.2 s before)


def test_soft_forced_run_stays_explicit() -> None:
    res = pf.simulate(pf.Oscillator(pf.GMS(**dict(GMS_P, C=2e3)), MASS, Sine(AMP, FREQ)), 0.0, t_end=0.2)
    assert "Radau" not in res.message
