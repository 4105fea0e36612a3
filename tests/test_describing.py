"""Describing functions: Dahl closed form against mpmath quadrature, the settled-cycle DF against
the closed form, python-control's own numerical DF, and predicted against simulated limit cycles."""

from __future__ import annotations

import math
import warnings

import control
import mpmath
import numpy as np
import pytest

import controllers
import prefriction as pf
from prefriction.describing import (
    DahlDescribingFunction,
    FrictionDescribingFunction,
    dahl_cycle,
    dahl_describing_function,
    friction_describing_function,
    friction_loop,
    measure_limit_cycle,
    plant_describing_function,
    predict_limit_cycle,
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
    assert predict_limit_cycle(H, FrictionDescribingFunction(lugre, 2.0 * math.pi / cyc.period, method="LSODA"),
                               [1e-3, 4e-3], iterations=1) is None
    # the plant block jumps at breakaway: stuck just below, sliding just above the force amplitude
    w = 2.0 * math.pi / cyc.period
    below = plant_describing_function(lugre, 1.47, w)
    above = plant_describing_function(lugre, 1.49, w)
    assert abs(below) < 1e-4 and abs(above) > 1e-2
    u = measure_limit_cycle(res.t, res.u, t_start=6.0)
    assert 1.47 * 0.97 < u.half_range < 1.49  # the loop's force peaks at the breakaway amplitude (3 %)
