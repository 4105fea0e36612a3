"""prefriction.symbolic against the models' equations and an independent scipy integration.

References: Dahl's (3.2) ``dF/dx = sigma (1 - s F/Fc)^gamma`` in closed form, the LuGre
equations (1)-(3) of Canudas de Wit et al. 1995 in SI units, and scipy's DOP853/Radau on the
oscillator ``m x'' = u - F`` restarted at every reversal.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.symbolic import branch_functions, plant_step

RNG = np.random.default_rng(7)


def _dF_dt(b, z, m, v):
    """dF~/dt~ = (dF~/dz) dz/dt~ through CasADi's derivative of the force Function."""
    zs = ca.SX.sym("z", len(z))
    F = b.force(zs, m, v, b.q)
    return float(ca.Function("d", [zs], [ca.jtimes(F, zs, b.rate(zs, m, v, b.q))])(z))


@pytest.mark.parametrize("gamma", [1.0, 2.5, 0.5])
@pytest.mark.parametrize("s", [1.0, -1.0])
def test_dahl_rate_and_force_give_the_paper_equation_3_2(gamma, s):
    model = pf.Dahl(sigma=1e4, Fc=2.0, gamma=gamma)
    b = branch_functions(model, s)
    for f in RNG.uniform(-0.95, 0.95, 5):
        z, m = model.initial_state(float(f), s)
        assert float(b.force(z, m, 0.3, b.q)) == pytest.approx(f, abs=1e-14)
        v = s * float(RNG.uniform(0.1, 2.0))
        assert _dF_dt(b, z, m, v) == pytest.approx(v * (1.0 - s * f) ** gamma, rel=1e-12)


@pytest.mark.parametrize("gamma", [1.0, 3.0, 0.5])
def test_dahl_reset_keeps_the_force_and_flips_the_branch(gamma):
    model = pf.Dahl(sigma=1e4, Fc=1.0, gamma=gamma)
    b, after = branch_functions(model, 1.0), branch_functions(model, -1.0)
    z, m = model.initial_state(0.7, 1.0)
    zn, mn = b.reset(z, m, b.q, 1e-12)
    assert float(after.force(zn, mn, 0.0, after.q)) == pytest.approx(0.7, abs=1e-14)
    # on the new branch (s = -1) the force falls at rate v (1 + F)^gamma (3.2)
    v = -0.5
    assert _dF_dt(after, np.array(zn).ravel(), np.array(mn).ravel(), v) == pytest.approx(v * 1.7 ** gamma, rel=1e-12)


def test_dahl_saturation_event_for_gamma_below_one():
    model = pf.Dahl(sigma=1e4, Fc=1.0, gamma=0.5)
    b = branch_functions(model, 1.0)
    e = 1.0 - 0.5
    p_sat = 1.0 / e  # the branch distance where F = Fc: 1 - (1 - e p)^(1/e) = 1
    assert float(b.events([p_sat * (1 - 1e-9)], [0.0], 1.0, b.q)) > 0.0
    assert float(b.events([p_sat * (1 + 1e-9)], [0.0], 1.0, b.q)) < 0.0
    zs, ms = b.on_event[0]([p_sat], [0.0], b.q)
    assert float(ms) == 1.0 and float(b.force(zs, ms, 1.0, b.q)) == pytest.approx(1.0, abs=1e-15)
    assert float(b.rate(zs, ms, 1.0, b.q)) == 0.0  # saturated: the state stops


def test_lugre_functions_match_the_1995_equations_in_si_units():
    sigma0, sigma1, sigma2, Fc, Fs, vs, m = 1e5, 300.0, 0.4, 1.0, 1.5, 1e-3, 2.0
    system = pf.Oscillator(pf.LuGre(sigma0, sigma1, sigma2, Fc, Fs, vs), mass=m)
    sc = pf.Scales.of(system)
    for s in (1.0, -1.0):
        b = branch_functions(system, s)
        for zeta, w in zip(RNG.uniform(-1.4, 1.4, 4), RNG.uniform(1e-4, 5e-3, 4)):
            v = s * w  # [m/s]
            zb = zeta * Fc / sigma0  # bristle deflection [m]
            g = Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))
            dz = v - sigma0 * abs(v) * zb / g  # (1)
            F = sigma0 * zb + sigma1 * dz + sigma2 * v  # (2)
            assert float(b.force([zeta], [], v / sc.v, b.q)) * Fc == pytest.approx(F, rel=1e-12, abs=1e-14)
            assert float(b.rate([zeta], [], v / sc.v, b.q)) == pytest.approx(sigma0 * dz / Fc * sc.t, rel=1e-12)
        zn, _ = b.reset([0.3], [], b.q, 1e-9)
        assert float(zn) == 0.3  # the deflection is continuous


def _scipy_step(y0, u, h, gamma, s):
    """x~, v~, F~ after h of x~' = v~, v~' = u~ - F~, F~' = v~ (1 - s F~)^gamma, restarted at reversals."""
    t, y, n = 0.0, np.array(y0, dtype=float), 0
    while True:
        def rhs(_, w, s=s):
            return [w[1], u - w[2], w[1] * max(1.0 - s * w[2], 0.0) ** gamma]

        def reversal(_, w):
            return w[1]

        reversal.terminal, reversal.direction = True, -s
        sol = solve_ivp(rhs, (t, h), y, method="DOP853", rtol=1e-13, atol=1e-15, events=reversal)
        if sol.status == 0:
            return sol.y[:, -1], n
        t, y, n, s = float(sol.t_events[0][0]), sol.y_events[0][0].copy(), n + 1, -s
        y[1] = 0.0


@pytest.fixture(scope="module")
def dahl_step():
    return plant_step(pf.Dahl(sigma=1e4, Fc=1.0))


@pytest.mark.parametrize(("v0", "F0", "u", "h"), [(1.0, 0.0, 0.0, 3.0), (0.8, 0.3, -0.5, 4.0), (-0.4, 0.2, 0.6, 2.5)])
def test_plant_step_matches_scipy_over_a_step_with_reversals(dahl_step, v0, F0, u, h):
    model = pf.Dahl(sigma=1e4, Fc=1.0)
    s = math.copysign(1.0, v0)
    z, _ = model.initial_state(F0, s)
    y1, n, ok = dahl_step([0.2, v0, *z, s], model.runtime_params(), u, h, 1e-11)
    y1 = np.array(y1).ravel()
    ref, n_ref = _scipy_step([0.2, v0, F0], u, h, 1.0, s)
    F1 = float(branch_functions(model, y1[3]).force(y1[2:3], [], y1[1], model.runtime_params()))
    assert int(ok) == 1 and int(n) == n_ref >= 1
    np.testing.assert_allclose([y1[0], y1[1], F1], ref, rtol=0, atol=1e-9)


def test_plant_step_derivative_matches_scipy_differences(dahl_step):
    """d y1 / d u through CasADi's sensitivities of the event-locating integrator."""
    u = ca.MX.sym("u")
    y1 = dahl_step([0.0, 1.0, 0.0, 1.0], [1.0], u, 3.0, 1e-11)[0]
    J = np.array(ca.Function("J", [u], [ca.jacobian(y1[:2], u)])(0.2)).ravel()
    du = 1e-5
    hi, lo = _scipy_step([0.0, 1.0, 0.0], 0.2 + du, 3.0, 1.0, 1.0)[0], _scipy_step([0.0, 1.0, 0.0], 0.2 - du, 3.0, 1.0, 1.0)[0]
    np.testing.assert_allclose(J, (hi[:2] - lo[:2]) / (2 * du), rtol=1e-6)


def test_plant_step_lugre_matches_radau():
    sigma0, sigma1, sigma2, Fc, Fs, vs, m = 1e4, 50.0, 0.2, 1.0, 1.3, 2e-3, 1.0
    system = pf.Oscillator(pf.LuGre(sigma0, sigma1, sigma2, Fc, Fs, vs), mass=m)
    sc = pf.Scales.of(system)
    step = plant_step(system)
    v0, u, h = 0.02, -1.5, 0.02  # [m/s], [N], [s]: slides, reverses, slides back

    def rhs(_, w):  # SI: x, v, z (bristle deflection [m])
        g = Fc + (Fs - Fc) * math.exp(-((w[1] / vs) ** 2))
        dz = w[1] - sigma0 * abs(w[1]) * w[2] / g
        return [w[1], (u - sigma0 * w[2] - sigma1 * dz - sigma2 * w[1]) / m, dz]

    def rev(_, w):
        return w[1]

    rev.terminal = True
    first = solve_ivp(rhs, (0.0, h), [0.0, v0, 0.0], method="Radau", rtol=1e-12, atol=1e-16, events=rev)
    t1, y = float(first.t_events[0][0]), first.y_events[0][0]
    ref = solve_ivp(rhs, (t1, h), [y[0], 0.0, y[2]], method="Radau", rtol=1e-12, atol=1e-16).y[:, -1]
    y1, n, ok = step([0.0, v0 / sc.v, 0.0, 1.0], system.friction.runtime_params_for(sc), u / Fc, h / sc.t, 1e-11)
    y1 = np.array(y1).ravel()
    assert int(n) == 1 and int(ok) == 1
    got = np.array([y1[0] * sc.x, y1[1] * sc.v, y1[2] * Fc / sigma0])
    scale = np.array([abs(ref[0]), abs(v0), Fc / sigma0])
    assert np.max(np.abs(got - ref) / scale) < 1e-8


def test_bad_input_names_the_argument():
    with pytest.raises(TypeError, match="model must be"):
        branch_functions(1.0, 1.0)
    with pytest.raises(ValueError, match="s must be"):
        branch_functions(pf.Dahl(1e4, 1.0), 0.0)
    with pytest.raises(TypeError, match="model must be"):
        plant_step("Dahl")


def test_plant_step_derivative_from_rest_is_finite_and_right(dahl_step):
    """From rest the amplitude scale has a kink; the derivative must not see it."""
    u = ca.MX.sym("u")
    y1 = dahl_step([0.0, 0.0, 0.0, 1.0], [1.0], u, 2.0, 1e-11)[0]
    J = float(ca.Function("J", [u], [ca.jacobian(y1[0], u)])(0.5))
    du = 1e-5
    hi, lo = _scipy_step([0.0, 0.0, 0.0], 0.5 + du, 2.0, 1.0, 1.0)[0], _scipy_step([0.0, 0.0, 0.0], 0.5 - du, 2.0, 1.0, 1.0)[0]
    assert J == pytest.approx((hi[0] - lo[0]) / (2 * du), rel=1e-6)


def test_compiled_plant_step_gives_the_same_numbers(dahl_step):
    fast = plant_step(pf.Dahl(sigma=1e4, Fc=1.0), jit=True)
    args = ([0.1, 0.7, 0.2, 1.0], [1.0], -0.4, 3.5, 1e-10)
    for a, b in zip(fast(*args), dahl_step(*args)):
        np.testing.assert_allclose(np.array(a), np.array(b), rtol=1e-13, atol=1e-15)
