"""Describing functions: Dahl closed form against mpmath quadrature, the settled-cycle DF against
the closed form, python-control's own numerical DF, and predicted against simulated limit cycles."""

from __future__ import annotations

import dataclasses
import math
import warnings

import control
import mpmath
import numpy as np
import pytest

from prefriction import controllers
import prefriction as pf
from prefriction.describing import (
    DahlDescribingFunction,
    FrictionDescribingFunction,
    VelocityDescribingFunction,
    dahl_cycle,
    dahl_describing_function,
    friction_describing_function,
    friction_loop,
    measure_limit_cycle,
    plant_describing_function,
    predict_limit_cycle,
    trace_unstable_cycle,
    velocity_loop,
)

SIGMA, FC = 1e4, 2.0


def _mp_df(A: float) -> complex:
    """Fourier coefficients of the settled cycle by mpmath quadrature of the branch (3.5)."""
    mpmath.mp.dps = 30
    A, s, F = mpmath.mpf(A), mpmath.mpf(SIGMA), mpmath.mpf(FC)
    Fr = F * mpmath.tanh(s * A / F)  # fixed point of the half-cycle map: checked below

    def up(th):  # loading branch from (-A, -Fr)
        return F - (F + Fr) * mpmath.exp(-s * (A * mpmath.sin(th) + A) / F)

    assert abs(up(mpmath.pi / 2) - Fr) < mpmath.mpf(10) ** -25 * F
    b1 = 2 / mpmath.pi * mpmath.quad(lambda th: up(th) * mpmath.sin(th), [-mpmath.pi / 2, mpmath.pi / 2])
    a1 = 2 / mpmath.pi * mpmath.quad(lambda th: up(th) * mpmath.cos(th), [-mpmath.pi / 2, mpmath.pi / 2])
    return complex(b1 / A, a1 / A)


@pytest.mark.parametrize("A", [1e-9, 3e-5, 2e-4, 1e-3, 0.05])
def test_dahl_closed_form_matches_mpmath_quadrature(A):
    N = complex(dahl_describing_function(A, SIGMA, FC))
    ref = _mp_df(A)
    assert abs(N.real - ref.real) <= 1e-13 * abs(ref)
    assert abs(N.imag - ref.imag) <= 1e-13 * abs(ref) + 1e-300


def test_dahl_area_is_the_dissipation_and_limits():
    A = np.array([1e-8, 1e-4, 1e-2])
    Fr, area = dahl_cycle(A, SIGMA, FC)
    N = dahl_describing_function(A, SIGMA, FC)
    np.testing.assert_allclose(np.pi * A * A * N.imag, area, rtol=1e-14)  # energy per cycle
    assert abs(N[0].real - SIGMA) < 1e-6 * SIGMA  # rest stiffness for small A
    assert abs(N[0].imag - 4.0 * SIGMA ** 2 * A[0] / (3.0 * math.pi * FC)) < 1e-6 * N[0].imag  # k^2/3 leading term
    k = SIGMA * 1.0 / FC  # large A: the Coulomb relay 4 i Fc / (pi A)
    Nl = complex(dahl_describing_function(1.0, SIGMA, FC))
    assert abs(Nl - 4j * FC / math.pi) < 2.0 * FC * (math.sqrt(2.0 / (math.pi * k)) + 2.0 / (math.pi * k))
    assert dahl_describing_function(0.0, SIGMA, FC) == SIGMA
    with pytest.raises(ValueError, match="A must lie"):
        dahl_describing_function(-1.0, SIGMA, FC)


@pytest.mark.parametrize("A", [1e-5, 2e-4, 1e-3])
def test_settled_cycle_of_the_model_matches_the_closed_form(A):
    system = pf.Oscillator(pf.Dahl(SIGMA, FC), mass=0.5)
    N = friction_describing_function(system, A, omega=7.0)
    ref = complex(dahl_describing_function(A, SIGMA, FC))
    assert abs(N - ref) <= 1e-8 * abs(ref)


def test_python_control_numerical_df_of_the_stepped_hysteresis():
    nl = DahlDescribingFunction(SIGMA, FC)
    A = 2e-4
    for x in A * np.sin(np.linspace(0.0, 40 * np.pi, 4001)):  # settle the memory first
        nl(x)
    num = control.describing_function(nl, [A], try_method=False, num_points=4000)[0]
    assert abs(num - nl.describing_function(A)) < 2e-3 * abs(num)  # rectangle rule across the kinks
    assert control.describing_function(nl, [A])[0] == nl.describing_function(A)


def test_rate_independent_model_has_one_df_for_all_frequencies():
    system = pf.Oscillator(pf.Dahl(SIGMA, FC, gamma=2.0), mass=1.0)
    N1 = friction_describing_function(system, 3e-4, omega=1.0)
    N2 = friction_describing_function(system, 3e-4, omega=500.0)
    assert abs(N1 - N2) < 1e-8 * abs(N1)
    # the cycle encloses the energy dissipated per cycle: pi A^2 Im N > 0, below the relay's 4 Fc A
    assert 0.0 < math.pi * 3e-4 ** 2 * N1.imag < 4.0 * FC * 3e-4


def test_bad_arguments_name_themselves():
    system = pf.Oscillator(pf.Dahl(SIGMA, FC), mass=1.0)
    with pytest.raises(ValueError, match="A must be finite and > 0"):
        friction_describing_function(system, 0.0)
    with pytest.raises(ValueError, match="max_cycles must be <= 400"):
        friction_describing_function(system, 1e-4, max_cycles=10 ** 6)
    with pytest.raises(ValueError, match="omega must be finite and > 0"):
        plant_describing_function(system, 1.0, -1.0)
    with pytest.raises(ValueError, match="amplitudes must be"):
        predict_limit_cycle(control.tf([1], [1, 1]), FrictionDescribingFunction(system), [1.0])
    with pytest.raises(ValueError, match="needs a frequency"):
        FrictionDescribingFunction(pf.Oscillator(pf.LuGre(1e5, 300.0, 0.4, 1.0, 1.5, 1e-3))).describing_function(1e-3)


PID = controllers.PID(kp=100.0, ki=300.0, kd=5.0)  # hunts with LuGre, Fs > Fc (the linear loops are stable)


def test_dahl_under_pid_no_intersection_and_the_loop_converges():
    system = pf.Oscillator(pf.Dahl(1e5, 1.0), mass=1.0)
    H = friction_loop(system, PID)
    # python-control's own describing_function_response: -1/N never meets H(i omega)
    resp = control.describing_function_response(H, FrictionDescribingFunction(system), np.logspace(-8, 0, 81),
                                                omega=np.logspace(-2, 4, 600), warn_nyquist=False)
    assert len(resp.intersections) == 0
    assert predict_limit_cycle(H, FrictionDescribingFunction(system), np.logspace(-8, 0, 81)) is None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = controllers.simulate_loop(system, PID, 0.01, 12.0, t_out=np.linspace(0.0, 12.0, 6001))
    # no reversal in the second half: the error creeps monotonically to zero (integral action
    # through the pre-sliding branch), no limit cycle
    assert len(res.reversals) > 10 and res.reversals.t[-1] < 6.0
    e = np.abs(res.error[res.t > 6.0])
    assert np.all(np.diff(e) <= 1e-15) and e[-1] < 0.9 * e[0] and e[-1] < 1e-3 * 0.01


def _harmonic(t, y, a, b):
    """First-harmonic phasor (relative to sin) of samples ``y`` over one period ``[a, b]``."""
    sel = (t >= a) & (t <= b)
    w = 2.0 * math.pi / (b - a)
    ts, ys = t[sel], y[sel]
    return 2.0 / (b - a) * complex(np.trapezoid(ys * np.sin(w * ts), ts), np.trapezoid(ys * np.cos(w * ts), ts))


def test_lugre_under_pid_hunts_and_the_friction_df_misses_it():
    lugre = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = controllers.simulate_loop(lugre, PID, 0.01, 24.0, t_out=np.linspace(0.0, 24.0, 24001))
    cyc = measure_limit_cycle(res.t, res.x, t_start=6.0)
    assert cyc.periods >= 3 and 3.0 < cyc.period < 6.0  # stick-slip hunting around the set point
    assert 2e-3 < cyc.half_range < 6e-3 and abs(cyc.mean - 0.01) < 1e-3
    # the friction block alone has no intersection (H = 1/(m s^2 + C) never enters the second
    # quadrant where -1/N lies): the describing function misses hunting, docs/describing.md#hunting
    H = friction_loop(lugre, PID)
    Hw = np.array([complex(H(1j * w)) for w in np.logspace(-2, 4, 400)])
    assert not np.any((Hw.real < 0) & (Hw.imag > 0))
    w = 2.0 * math.pi / cyc.period
    assert predict_limit_cycle(H, FrictionDescribingFunction(lugre, w, method="LSODA"), [1e-3, 4e-3],
                               iterations=1) is None
    # why: the harmonics of the simulated cycle obey the linear part exactly, F1 / V1 = -1/G(i w),
    # whose equivalent stiffness k = -w Im(F1/V1) = m w^2 - kp is negative (sticking); the friction
    # under a sinusoidal velocity has k > 0 and damping Re N_v >= sigma2
    up = np.nonzero((res.x[:-1] < cyc.mean) & (res.x[1:] >= cyc.mean) & (res.t[1:] > 6.0))[0]
    a, b = res.t[up[-2]], res.t[up[-1]]  # the last full period
    Neff = _harmonic(res.t, res.F, a, b) / _harmonic(res.t, res.v, a, b)
    G = velocity_loop(lugre, PID)
    we = 2.0 * math.pi / (b - a)
    assert abs(Neff + 1.0 / complex(G(1j * we))) < 2e-2 * abs(Neff)
    assert -we * Neff.imag < -50.0  # m w^2 - kp = -98 N/m
    for Av in (1e-3, 1e-2):
        Nv = VelocityDescribingFunction(lugre, w, method="LSODA").describing_function(Av)
        assert Nv.real >= 0.4 and -w * Nv.imag > 0.0
    # the plant block jumps at breakaway: stuck just below, sliding just above the force amplitude
    below = plant_describing_function(lugre, 1.47, w)
    above = plant_describing_function(lugre, 1.49, w)
    assert abs(below) < 1e-4 and abs(above) > 1e-2
    u = measure_limit_cycle(res.t, res.u, t_start=6.0)
    assert 1.47 * 0.97 < u.half_range < 1.49  # the loop's force peaks at the breakaway amplitude (3 %)


class _CoulombViscous(control.DescribingFunctionNonlinearity):
    """``F = Fc sign(v) + c v`` as a nonlinearity of the velocity: ``N(A) = c + 4 Fc / (pi A)``."""

    def __init__(self, Fc, c):
        super().__init__()
        self.Fc, self.c = Fc, c

    def __call__(self, v):
        return self.Fc * np.sign(v) + self.c * v

    def describing_function(self, A):
        return self.c + 4.0 * self.Fc / (math.pi * A)


class _Relay(control.DescribingFunctionNonlinearity):
    def __call__(self, x):
        return np.sign(x)

    def describing_function(self, A):
        return 4.0 / (math.pi * A)


def test_predicted_cycles_and_their_stability_against_closed_forms():
    # relay around K / (s (s + 1)^2): omega = 1, |H| = K / 2, A = 4 / (pi N) = 2 K / pi; stable (textbook)
    K = 4.0
    cyc = predict_limit_cycle(control.tf([K], [1.0, 2.0, 1.0, 0.0]), _Relay(), np.logspace(-1, 2, 31))
    assert abs(cyc.omega - 1.0) < 1e-8 and abs(cyc.amplitude - 2.0 * K / math.pi) < 1e-8 and cyc.stable
    # Coulomb + viscous damper in a PID loop (no derivative filter), G = s^2 / (m s^3 + kd s^2 + kp s + ki):
    # Im G = 0 at omega^2 = kp / m, balance at N = c* = m ki / kp - kd, so A = 4 Fc / (pi (c* - c));
    # more damping stabilises this loop and N falls with A: the cycle is unstable
    m, kp, ki, kd, Fc, c = 1.0, 100.0, 300.0, 1.0, 1.0, 0.4
    G = velocity_loop(pf.Oscillator(pf.Dahl(1e5, Fc), mass=m), control.tf([kd, kp, ki], [1.0, 0.0]))
    cyc = predict_limit_cycle(G, _CoulombViscous(Fc, c), np.logspace(-2, 1, 31))
    cstar = m * ki / kp - kd
    assert abs(cyc.omega - math.sqrt(kp / m)) < 1e-7 * cyc.omega
    assert abs(cyc.amplitude - 4.0 * Fc / (math.pi * (cstar - c))) < 1e-7 * cyc.amplitude
    assert not cyc.stable and "unstable" in cyc.summary()


PID_UNSTABLE = controllers.PID(kp=100.0, ki=300.0, kd=1.0)  # ki > kd kp / m: the linear loop is unstable


def test_lugre_unstable_pid_loop_predicted_cycle_against_simulation():
    """docs/describing.md#unstable-loop: LuGre's velocity DF at the harmonic balance against bisection."""
    lugre = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
    G = velocity_loop(lugre, PID_UNSTABLE)
    block = VelocityDescribingFunction(lugre, 10.0, method="LSODA", rtol=1e-7, tol=1e-5)
    cyc = predict_limit_cycle(G, block, [0.3, 1.0, 3.0], omega=10.0, iterations=2)
    assert not cyc.stable
    # far above vs = 1 mm/s LuGre slides like Coulomb + viscous (the closed form above, within 1 %)
    ref = 4.0 / (math.pi * (3.0 - 1.0 - 0.4))
    assert abs(cyc.amplitude / ref - 1.0) < 1e-2 and abs(cyc.omega / 10.0 - 1.0) < 1e-2
    # simulated: runs from the predicted sinusoid scaled by 0.95 decay, by 1.05 grow; bisection between
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = trace_unstable_cycle(lugre, PID_UNSTABLE, cyc, bracket=(0.95, 1.05), steps=6, periods=12)
    assert tr.periods >= 2
    e_amp, e_T = tr.errors()
    assert abs(e_amp) < 0.05 and abs(e_T) < 0.02  # measured: +1.4 % and -0.34 % (30 steps)
    assert "unstable cycle" in tr.summary() and "TracedCycle" in repr(tr)


def test_velocity_and_trace_bad_arguments():
    lugre = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
    with pytest.raises(ValueError, match="needs a frequency"):
        VelocityDescribingFunction(lugre).describing_function(0.1)
    with pytest.raises(TypeError, match="controller must be"):
        velocity_loop(lugre, object())
    with pytest.raises(ValueError, match="continuous-time"):
        velocity_loop(lugre, control.tf([1.0], [1.0, 0.5], dt=0.1))
    stable = predict_limit_cycle(control.tf([4.0], [1.0, 2.0, 1.0, 0.0]), _Relay(), np.logspace(-1, 2, 31))
    with pytest.raises(ValueError, match="unstable LimitCycle"):
        trace_unstable_cycle(lugre, PID_UNSTABLE, stable)
    unstable = dataclasses.replace(stable, stable=False)
    with pytest.raises(ValueError, match="bracket must be"):
        trace_unstable_cycle(lugre, PID_UNSTABLE, unstable, bracket=(1.2, 0.8))
    with pytest.raises(ValueError, match="variable"):
        trace_unstable_cycle(lugre, PID_UNSTABLE, unstable, variable="force")
    with pytest.raises(ValueError, match="steps"):
        trace_unstable_cycle(lugre, PID_UNSTABLE, unstable, steps=1000)
