"""Input signals of every kind through simulate and the energy analysis.

References: scipy's DOP853 on the Dahl oscillator (3.2) with a constant force (restarted at
every reversal), the work of a constant force ``u (x_b - x_a)``, and the regular sample grid
that ``dense=True`` promises.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import energy


def _reference_reversals(v0: float, u: float, n: int, *, sigma: float, Fc: float, m: float) -> np.ndarray:
    """Reversal states (t [s], x [m], F [N]) of m x'' = u - F, dF/dx = sigma (1 - s F/Fc), gamma = 1."""
    T, X, V = math.sqrt(m / sigma), Fc / sigma, Fc / math.sqrt(m * sigma)
    y, t0, s, out = np.array([0.0, v0 / V, 0.0]), 0.0, float(np.sign(v0)), []
    for _ in range(n):
        def rhs(t, z, s=s):
            return [z[1], u / Fc - z[2], z[1] * (1.0 - s * z[2])]

        def ev(t, z):
            return z[1]

        ev.terminal, ev.direction = True, -s
        sol = solve_ivp(rhs, (t0, t0 + 1e3), y, method="DOP853", rtol=1e-12, atol=1e-14, events=ev)
        t0, y = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
        y[1] = 0.0
        out.append((t0 * T, y[0] * X, y[2] * Fc))
        s = -s
    return np.array(out)


def test_simulate_constant_input_force_matches_scipy():
    sigma, Fc, m, u = 1e4, 1.0, 1.0, 0.2
    system = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc), mass=m, u=u)
    res = pf.simulate(system, 0.05, t_end=0.2, rtol=1e-10)
    ref = _reference_reversals(0.05, u, 3, sigma=sigma, Fc=Fc, m=m)
    table = res.reversals
    assert len(table) >= 3
    np.testing.assert_allclose(table.t[:3], ref[:, 0], rtol=1e-7)
    np.testing.assert_allclose(table.x[:3], ref[:, 1], rtol=1e-7, atol=1e-7 * np.max(np.abs(ref[:, 1])))
    np.testing.assert_allclose(table.F[:3], ref[:, 2], rtol=1e-7, atol=1e-7 * Fc)
    # a constant force does work u (x_k - x_{k-1}) over each half-cycle
    np.testing.assert_allclose(res.work_input[1:3], u * np.diff(ref[:3, 1]), rtol=1e-6)


def test_dense_samples_on_the_regular_grid_with_sampled_input():
    sigma, Fc, m = 1e4, 1.0, 1.0
    ts = np.linspace(0.0, 1.0, 50)
    system = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc), mass=m, u=(ts, 0.3 * np.sin(50.0 * ts)))
    res = pf.simulate(system, 0.05, t_end=0.5, dense=True)
    step = 2.0 * math.pi / 64.0 * math.sqrt(m / sigma)  # 64 samples per small cycle
    k = np.arange(res.t.size - 1)
    np.testing.assert_allclose(res.t[:-1], k * step, rtol=1e-12, atol=1e-15)
    assert res.t[-1] == 0.5 and res.t[-2] < 0.5 < res.t[-2] + step  # the regular grid, then t_end


def test_analyze_samples_constant_input_work():
    sigma, Fc, m, u = 1e4, 1.0, 1.0, 0.2
    # the constant force as two equal samples (exactly u): the structure of the sampled inputs
    system = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=Fc), mass=m, u=(np.array([0.0, 0.3]), np.array([u, u])))
    res = pf.simulate(system, 0.05, t_end=0.3, dense=True, rtol=1e-10)
    rep = energy.analyze_samples(res.t, res.x, res.v, res.F, system=system, method="simpson")
    assert len(rep) >= 3
    # (2.10) with the input's work: E_d = E_p(k) - E_p(k+1) + u (x_{k+1} - x_k)
    expected = rep.E_p[:-1] - rep.E_p[1:] + u * np.diff(rep.x)
    assert np.max(np.abs(rep.E_d[1:] - expected)) <= 1e-5 * np.max(rep.E_p)
