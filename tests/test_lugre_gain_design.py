"""design_pid(..., observer=LuGreObserver) says when the designed PID fails the observer's gain condition.

Reference: H(s) = (sigma1 s + sigma0) / (m s^2 + C(s)) assembled by python-control from the PID's
transfer function and evaluated at j w (Canudas de Wit et al. 1995, section V: the observer-based
loop is covered by the stability proof only if H is strictly positive real)."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

import prefriction as pf
from prefriction import controllers

M = 2.5                                                               # kg
LUGRE = pf.LuGre(sigma0=2e6, sigma1=200.0, sigma2=0.0, Fc=3.0, Fs=3.5, vs=1e-4)
STAGE = pf.Oscillator(LUGRE, mass=M)
OBS = controllers.LuGreObserver(LUGRE, gain=1e3)


def _min_re_h(pid: controllers.PID) -> float:
    H = control.tf([LUGRE.sigma1, LUGRE.sigma0], [1.0]) / (control.tf([M, 0.0, 0.0], [1.0]) + pid.tf())
    w = math.sqrt(LUGRE.sigma0 / M) * np.logspace(-3, 3, 4000)
    return float(np.min(np.real(H(1j * w))))


@pytest.mark.parametrize("hz", [200.0, 2000.0])
def test_designed_pid_that_fails_the_condition_is_refused_with_the_alternatives(hz):
    pid = controllers.design_pid(STAGE, wn=2 * math.pi * hz)               # without the observer: designed
    assert _min_re_h(pid) < 0.0                                              # python-control: H is not SPR
    with pytest.raises(ValueError) as err:
        controllers.design_pid(STAGE, wn=2 * math.pi * hz, observer=OBS)
    text = str(err.value)
    assert "gain condition" in text and "controllers.FrictionObserver" in text and "controllers.Feedforward" in text
    assert "derivative filter" in text
    assert ("kd = " in text) == (pid.kd < M * LUGRE.sigma0 / LUGRE.sigma1)    # 7540 < 25000 at 200 Hz only


def test_a_pid_that_meets_the_condition_passes_and_other_observers_are_refused():
    ok = controllers.PID(kp=2e6, ki=1e8, kd=3e4, tau=1e-7)                  # sigma1 kd > m sigma0, sigma0 kp > sigma1 ki
    assert _min_re_h(ok) > 0.0
    OBS.require_gain_condition(ok, mass=M)
    with pytest.raises(ValueError, match=r"kd = 2e\+04 N s/m < m sigma0 / sigma1 = 2.5e\+04"):
        OBS.require_gain_condition(controllers.PID(kp=2e6, ki=1e8, kd=2e4, tau=1e-7), mass=M)
    with pytest.raises(TypeError, match="observer must be a controllers.LuGreObserver"):
        controllers.design_pid(STAGE, wn=2 * math.pi * 200.0,
                               observer=controllers.FrictionObserver(pf.Dahl(2e6, 3.0), pole=1e3))
