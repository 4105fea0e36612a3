"""Models in parallel (``a + b``, :class:`prefriction.Parallel`) and :class:`prefriction.Viscous`:
names in a fit, fits and simulations against closed forms and scipy references."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.identify import ForceDisplacement, fit


def dahl1_along(x: np.ndarray, sigma: float, Fc: float) -> np.ndarray:
    """Dahl gamma = 1 along samples of a motion, closed form per branch from F = 0 (virgin)."""
    F = np.zeros_like(x)
    Fr, xr, s = 0.0, x[0], 1.0
    for i in range(1, x.size):
        d = x[i] - x[i - 1]
        if d != 0.0 and np.sign(d) != s:
            Fr, xr, s = F[i - 1], x[i - 1], -s
        F[i] = s * Fc * (1.0 - (1.0 - s * Fr / Fc) * np.exp(-sigma * s * (x[i] - xr) / Fc))
    return F


def test_sum_flattens_and_names_follow_the_rule():
    a, b, c = pf.Dahl(1e5, 1.0), pf.Dahl(2e5, 0.5, 0.5), pf.Viscous(3.0)
    total = a + b + c
    assert isinstance(total, pf.Parallel) and total.models == (a, b, c)
    assert total.parameter_names == ("dahl1.sigma", "dahl1.Fc", "dahl1.gamma", "dahl2.sigma", "dahl2.Fc",
                                     "dahl2.gamma", "b")
    ms = pf.MaxwellSlip([1e4, 2e4], [0.3, 0.4]) + pf.Viscous(1.0)
    assert ms.parameter_names == ("stiffness[0]", "stiffness[1]", "slip_force[0]", "slip_force[1]", "b")
    assert (total.sigma, total.Fc) == (3e5, 1.5)


def test_bad_terms_are_refused():
    with pytest.raises(TypeError, match="models must be a tuple"):
        pf.Parallel((pf.Dahl(1e5, 1.0), 3.0))
    with pytest.raises(ValueError, match="1 to 16"):
        pf.Parallel(())
    with pytest.raises(ValueError, match="b must"):
        pf.Viscous(-1.0)
    with pytest.raises(ValueError, match=r"F0 must lie in \[-0.0, 0.0\] N"):
        pf.friction_along(pf.Viscous(1.0), np.linspace(0.0, 1.0, 5), np.zeros(5), F0=0.5)


@pytest.fixture(scope="module")
def loops():
    t = np.linspace(0.0, 2.0, 801)
    x = 2e-4 * np.sin(2 * np.pi * t)
    return t, x


def test_fit_recovers_dahl_plus_viscous(loops):
    t, x = loops
    F = dahl1_along(x, 2e4, 1.0) + 30.0 * np.gradient(x, t)  # the fit's default velocity: central differences
    start = pf.Dahl(sigma=1.5e4, Fc=0.8) + pf.Viscous(b=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fit(start, ForceDisplacement(t, x, F), fixed=["gamma"])
    got = dict(zip(res.names, res.estimates))
    assert got == pytest.approx({"sigma": 2e4, "Fc": 1.0, "b": 30.0}, rel=1e-7)
    assert isinstance(res.model, pf.Parallel) and res.model.models[1].b == pytest.approx(30.0, rel=1e-7)


def test_fit_takes_prefixed_names_in_fixed_and_bounds(loops):
    t, x = loops
    F = dahl1_along(x, 2e4, 0.6) + dahl1_along(x, 5e3, 0.4)
    start = pf.Dahl(2e4, 0.5) + pf.Dahl(5e3, 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fit(start, ForceDisplacement(t, x, F), fixed=["dahl1.gamma", "dahl2.gamma", "dahl1.sigma", "dahl2.sigma"],
                  bounds={"dahl1.Fc": (0.1, 2.0)})
    got = dict(zip(res.names, res.estimates))
    assert got == pytest.approx({"dahl1.Fc": 0.6, "dahl2.Fc": 0.4}, rel=1e-6)
    with pytest.raises(ValueError, match="dahl1.sigma"):
        fit(start, ForceDisplacement(t, x, F), fixed=["sigma"])


def test_simulate_dahl_plus_viscous_matches_scipy():
    """Free decay of m x'' = -(F + b x'), F' = sigma x' (1 - sign(x') F / Fc), integrated by scipy
    from the equations, restarted at every velocity reversal."""
    m, sigma, Fc, b, v0 = 1.0, 1e4, 1.0, 2.0, 0.02
    res = pf.simulate(pf.Oscillator(pf.Dahl(sigma, Fc) + pf.Viscous(b), m), v0, reversals=4, rtol=1e-10)

    def rhs(_t, y, s):
        x, v, F = y
        return [v, -(F + b * v) / m, sigma * v * (1.0 - s * F / Fc)]

    def turn(_t, y, s):
        return s * y[1]

    turn.terminal, turn.direction = True, -1.0
    y, t0, s, rev = np.array([0.0, v0, 0.0]), 0.0, 1.0, []
    for _ in range(4):
        sol = solve_ivp(rhs, (t0, t0 + 1.0), y, args=(s,), events=turn, rtol=1e-12, atol=1e-15, method="DOP853")
        t0, y = float(sol.t_events[0][0]), sol.y_events[0][0]
        rev.append((t0, y[0], y[2]))
        s = -s
    rev = np.array(rev)
    np.testing.assert_allclose(res.reversals.t, rev[:, 0], rtol=1e-7)
    np.testing.assert_allclose(res.reversals.x, rev[:, 1], rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(res.reversals.F, rev[:, 2], rtol=1e-7, atol=1e-9)
