"""controllers: PID objects, pole-placement designs, margins, warnings and argument errors.

References are independent of the code under test: the textbook PID formula evaluated with
numpy, polynomial roots (numpy.roots), and a bisection for the gain crossover.
"""

from __future__ import annotations

import re
import warnings

import control
import numpy as np
import pytest
from scipy.optimize import brentq

from prefriction import controllers
import prefriction

M, SIGMA, FC = 1.0, 1e6, 1.0


@pytest.fixture(scope="module")
def stage():
    return prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)


def pid_formula(s, kp, ki, kd, tau):
    return kp + ki / s + kd * s / (tau * s + 1)


def test_pid_lti_is_the_textbook_formula():
    c = controllers.PID(kp=2e6, ki=3e8, kd=1500.0, tau=4e-5)
    w = np.array([1.0, 30.0, 1e3, 2e4, 1e6])
    resp = np.squeeze(control.frequency_response(c.tf(), w).complex)
    np.testing.assert_allclose(resp, pid_formula(1j * w, 2e6, 3e8, 1500.0, 4e-5), rtol=1e-10)
    ss = c.ss()
    assert ss.nstates == 2 and ss.input_labels == ["e"] and ss.output_labels == ["u"]


def test_pd_has_one_state_and_default_filter():
    c = controllers.pd(1e6, 2000.0)
    assert c.ss().nstates == 1
    assert c.tau == pytest.approx(2000.0 / (10.0 * 1e6))  # Td / N with N = 10
    assert controllers.PID(kp=5.0).ss().nstates == 0


def test_discrete_pid_matches_c2d_zoh_of_formula():
    c = controllers.pid(2e6, 3e8, 1500.0, tau=4e-5)
    Ts = 1e-4
    ref = control.c2d(control.tf([1500.0 + 2e6 * 4e-5, 2e6 + 3e8 * 4e-5, 3e8], [4e-5, 1.0, 0.0]), Ts, "zoh")
    w = np.array([10.0, 1e3, 1e4])
    np.testing.assert_allclose(
        np.squeeze(control.frequency_response(c.c2d(Ts), w).complex),
        np.squeeze(control.frequency_response(ref, w).complex), rtol=1e-8)


@pytest.mark.parametrize("name, value", [("kp", -1.0), ("ki", -2.0), ("kd", -0.5), ("kp", np.nan),
                                         ("kd", np.inf), ("ki", -np.inf)])
def test_bad_gains_raise_value_error_naming_argument(name, value):
    kwargs = {"kp": 1.0, "ki": 1.0, "kd": 1.0, name: value}
    with pytest.raises(ValueError, match=rf"{name} must be finite and >= 0, got {re.escape(repr(float(value)))}"):
        controllers.PID(**kwargs)


def test_other_bad_arguments():
    with pytest.raises(ValueError, match=r"tau must be finite and > 0, got 0.0"):
        controllers.PID(kp=1.0, kd=1.0, tau=0.0)
    with pytest.raises(ValueError, match=r"tau must be given when kd > 0 and kp = 0"):
        controllers.PID(kp=0.0, kd=1.0)
    with pytest.raises(ValueError, match=r"u_max must be finite and > 0, got -1.0"):
        controllers.PID(kp=1.0, u_max=-1.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'kii'"):
        controllers.PID(kp=1.0, kii=2.0)
    with pytest.raises(TypeError, match="kp must be a real number"):
        controllers.PID(kp="1")
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got -0.001"):
        controllers.PID(kp=1.0).c2d(-1e-3)
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got 0.0"):
        controllers.linear_plant(prefriction.Oscillator(prefriction.Dahl(1.0, 1.0)), Ts=0.0)


def test_controller_checks(stage):
    with pytest.raises(ValueError, match="proper"):
        controllers.closed_loop(stage, control.tf([1.0, 0.0, 0.0], [1.0, 1.0]))
    with pytest.raises(ValueError, match="SISO"):
        controllers.closed_loop(stage, control.ss(np.eye(2) * -1, np.eye(2), np.eye(2), np.zeros((2, 2))))
    with pytest.raises(TypeError, match="controller must be"):
        controllers.closed_loop(stage, 3.0)
    with pytest.raises(ValueError, match="regime must be one of"):
        controllers.closed_loop(stage, controllers.PID(kp=1.0), regime="stuck")


@pytest.mark.parametrize("regime, k", [("presliding", SIGMA), ("sliding", 0.0)])
def test_design_pd_places_poles(stage, regime, k):
    wn, zeta = 2500.0, 0.6
    c = controllers.design_pd(stage, wn=wn, zeta=zeta, regime=regime, N=1e5)
    # characteristic polynomial of the unfiltered loop m s^2 + kd s + (k + kp)
    roots = np.roots([M, c.kd, k + c.kp])
    np.testing.assert_allclose(np.sort_complex(roots),
                               np.sort_complex(np.roots([1.0, 2 * zeta * wn, wn * wn])), rtol=1e-12)
    # with the (fast) filter the python-control loop keeps the pair within about 1/N
    poles = control.poles(controllers.closed_loop(stage, c, regime=regime))
    pair = poles[np.argsort(np.abs(poles))][:2]
    np.testing.assert_allclose(np.abs(pair), wn, rtol=1e-3)
    np.testing.assert_allclose(-pair.real / np.abs(pair), zeta, rtol=1e-3)


@pytest.mark.parametrize("regime, k", [("presliding", SIGMA), ("sliding", 0.0)])
def test_design_pid_places_poles(stage, regime, k):
    wn, zeta, alpha = 1500.0, 0.7, 1.5
    c = controllers.design_pid(stage, wn=wn, zeta=zeta, alpha=alpha, regime=regime, N=1e5)
    roots = np.roots([M, c.kd, k + c.kp, c.ki])
    want = np.roots(np.polymul([1.0, 2 * zeta * wn, wn * wn], [1.0, alpha * wn]))
    np.testing.assert_allclose(np.sort_complex(roots), np.sort_complex(want), rtol=1e-9)
    poles = control.poles(controllers.closed_loop(stage, c, regime=regime))
    slow = np.sort_complex(poles[np.argsort(np.abs(poles))][:3])
    np.testing.assert_allclose(slow, np.sort_complex(want), rtol=2e-3)


def test_design_rejects_unreachable_bandwidth(stage):
    with pytest.raises(ValueError, match=r"wn must be >= sqrt\(sigma/m\) = 1000 rad/s .* got wn=500.0"):
        controllers.design_pd(stage, wn=500.0)
    with pytest.raises(ValueError, match=r"wn must be finite and > 0, got -1.0"):
        controllers.design_pid(stage, wn=-1.0)
    with pytest.raises(ValueError, match=r"zeta must lie in \[0.0, 10.0\], got -0.1"):
        controllers.design_pd(stage, wn=2000.0, zeta=-0.1)
    with pytest.raises(TypeError):
        controllers.design_pd(stage, wn=2000.0, bandwidth=3.0)


def test_phase_margin_against_bisection(stage):
    c = controllers.pd(3e6, 2500.0, tau=5e-5)
    Lf = lambda w: pid_formula(1j * w, 3e6, 0.0, 2500.0, 5e-5) / (M * (1j * w) ** 2 + SIGMA)  # noqa: E731
    wgc = brentq(lambda w: abs(Lf(w)) - 1.0, 2e3, 1e5)
    pm = 180.0 + np.degrees(np.angle(Lf(wgc)))
    mg = controllers.margins(stage, c)
    assert mg.w_gain_crossover == pytest.approx(wgc, rel=1e-6)
    assert mg.phase_margin == pytest.approx(pm, rel=1e-6)
    assert "phase margin" in str(mg)


def _poles_in_message(msg: str) -> np.ndarray:
    body = msg[msg.index("[") + 1: msg.index("]")]
    return np.array([complex(z) for z in body.split(", ")])


def test_unstable_design_warns_with_its_poles(stage):
    c = controllers.PID(kp=1e5, ki=1e12)  # loop: m s^3 + (sigma + kp) s + ki, unstable
    with pytest.warns(controllers.UnstableLoopWarning, match="poles") as rec:
        controllers.closed_loop(stage, c)
    got = _poles_in_message(str(rec[0].message))
    want = np.roots([M, 0.0, SIGMA + 1e5, 1e12])
    assert np.max(want.real) > 0
    np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(want), rtol=1e-5)
    with pytest.warns(controllers.UnstableLoopWarning, match=r"\|z\| < 1"):
        controllers.closed_loop(stage, c.c2d(1e-4))


def test_stable_design_does_not_warn(stage):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        controllers.design_pd(stage, wn=2 * np.pi * 300)
        controllers.design_pid(stage, wn=2 * np.pi * 150)
        controllers.closed_loop(stage, controllers.design_pid(stage, wn=2 * np.pi * 150).c2d(1e-4))


def _crossover(f, lo, hi):
    return brentq(f, lo, hi, xtol=1e-12)


def test_margins_pd_by_hand(stage):
    """PD on 1/(m s^2 + sigma): Im C(jw) = kd w/(1 + tau^2 w^2) > 0 for every w > 0, so L is
    never real and negative: no phase crossover, an infinite gain margin (python-control reports
    a number at the resonance or at 1e11 rad/s). The gain crossover solves |C(jw)| = |sigma - m w^2|."""
    kp, kd, tau = 2.55e6, 2640.0, 5.3e-5
    mg = controllers.margins(stage, controllers.pd(kp, kd, tau=tau))
    C = lambda w: kp + kd * 1j * w / (tau * 1j * w + 1)  # noqa: E731
    wgc = _crossover(lambda w: abs(C(w)) - abs(SIGMA - M * w * w), 1.5e3, 1e5)
    pm = 180.0 + np.degrees(np.angle(C(wgc) / (SIGMA - M * wgc ** 2)))
    assert mg.gain_margin == np.inf and np.isnan(mg.w_phase_crossover) and mg.phase_crossovers == ()
    assert mg.w_gain_crossover == pytest.approx(wgc, rel=1e-9)
    assert mg.phase_margin == pytest.approx(pm, rel=1e-9)
    assert "gain margin inf" in str(mg)


def test_margins_pid_by_hand(stage):
    """PID: Im C(jw) = kd w/(1 + tau^2 w^2) - ki/w vanishes at w1 = sqrt(ki/(kd - ki tau^2)), where
    C = kp + kd tau w1^2/(1 + tau^2 w1^2) is real and positive. Pre-sliding (w1 < sqrt(sigma/m)) L is
    positive there: no phase crossover. Sliding, L = -C/(m w1^2) < 0 with |L| > 1: a lower gain
    margin m w1^2 / C (the loop is conditionally stable) and still no upper one."""
    kp, ki, kd, tau = 1.13e6, 8.37e8, 2262.0, 1.06e-4
    c = controllers.PID(kp=kp, ki=ki, kd=kd, tau=tau)
    w1 = np.sqrt(ki / (kd - ki * tau * tau))
    C1 = kp + kd * tau * w1 ** 2 / (1 + (tau * w1) ** 2)
    pre = controllers.margins(stage, c)
    assert w1 < np.sqrt(SIGMA / M) and pre.gain_margin == np.inf and pre.phase_crossovers == ()
    C = lambda w: kp + ki / (1j * w) + kd * 1j * w / (tau * 1j * w + 1)  # noqa: E731
    wgc = _crossover(lambda w: abs(C(w)) - abs(SIGMA - M * w * w), 1.5e3, 1e5)
    assert pre.w_gain_crossover == pytest.approx(wgc, rel=1e-9)
    assert pre.phase_margin == pytest.approx(180.0 + np.degrees(np.angle(C(wgc) / (SIGMA - M * wgc ** 2))), rel=1e-9)
    sl = controllers.margins(stage, c, regime="sliding")
    assert sl.gain_margin == np.inf
    assert sl.phase_crossovers == pytest.approx((w1,), rel=1e-9)
    assert sl.lower_gain_margin == pytest.approx(M * w1 ** 2 / C1, rel=1e-9)
    wgs = _crossover(lambda w: abs(C(w)) - M * w * w, 1e3, 1e5)
    assert sl.phase_margin == pytest.approx(180.0 + np.degrees(np.angle(-C(wgs) / (M * wgs ** 2))), rel=1e-9)


def test_margins_sampled_pd_against_python_control(stage):
    """A sampled PD (ZOH plant) has a finite gain margin below the Nyquist frequency; there
    python-control's grid search is reliable and serves as the reference."""
    Cd = controllers.design_pd(stage, wn=2 * np.pi * 300).c2d(1e-4)
    gm, pm, _, wpc, wgc, _ = control.stability_margins(controllers.linear_plant(stage, Ts=1e-4) * Cd)
    mg = controllers.margins(stage, Cd)
    assert mg.gain_margin == pytest.approx(gm, rel=1e-6) and mg.w_phase_crossover == pytest.approx(wpc, rel=1e-6)
    assert mg.phase_margin == pytest.approx(pm, rel=1e-6) and mg.w_gain_crossover == pytest.approx(wgc, rel=1e-6)
    assert 1.0 < mg.gain_margin < 10.0
