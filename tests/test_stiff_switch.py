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
from scipy.integrate import solve_ivp

import prefriction as pf

GMS_P = dict(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=1e7)
MASS, V0, N_REV = 1.0, 0.05, 6


def _gms_reference():
    """Reversals (t, x, F) of m x'' = -sum F_i, GMS elements: sticking F_i' = k_i v, slipping
    F_i' = s C (1 - s F_i / (alpha_i S(v))), S(v) = Fc + (Fs - Fc) exp(-(v/vs)^2); an element
    slips from s F_i = alpha_i S(v) on; at a reversal every element sticks again."""
    k, alpha = np.array(GMS_P["k"]), np.array(GMS_P["alpha"])
    Fc, Fs, vs, C = GMS_P["Fc"], GMS_P["Fs"], GMS_P["vs"], GMS_P["C"]
    S = lambda v: Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))
    n = len(k)
    s, slip, t, y, rows = 1.0, np.zeros(n, bool), 0.0, np.r_[0.0, V0, np.zeros(n)], []
    inside = False  # within 5 vs of v = 0 (toggled by the band's events)
    while len(rows) < N_REV:
        sl = slip.copy()

        def rhs(_t, yy, s=s, sl=sl):
            dF = np.where(sl, s * C * (1.0 - s * yy[2:] / (alpha * S(yy[1]))), k * yy[1])
            return np.r_[yy[1], -yy[2:].sum() / MASS, dF]

        def jac(_t, yy, s=s, sl=sl):
            J = np.zeros((n + 2, n + 2))
            J[0, 1] = 1.0
            J[1, 2:] = -1.0 / MASS
            Sv = S(yy[1])
            dS = -2.0 * yy[1] / vs**2 * (Sv - Fc)
            for i in range(n):
                if sl[i]:
                    J[2 + i, 2 + i] = -C / (alpha[i] * Sv)
                    J[2 + i, 1] = C * yy[2 + i] / alpha[i] * dS / Sv**2
                else:
                    J[2 + i, 1] = k[i]
            return J

        events = [lambda _t, yy, s=s: s * yy[1]]
        for j in range(n):
            events.append(lambda _t, yy, j=j, s=s, sl=sl: 1.0 if sl[j] else alpha[j] * S(yy[1]) - s * yy[2 + j])
        # the Stribeck curve is narrow (vs = 1 mm/s against 5 cm/s): within 5 vs of v = 0 the
        # steps are at most vs / 20 of speed (Radau's steps would jump over it)
        events.append(lambda _t, yy, s=s, inside=inside: (5 * vs - s * yy[1]) if inside else (s * yy[1] - 5 * vs))
        for ev in events:
            ev.terminal, ev.direction = True, -1.0
        sol = solve_ivp(rhs, (t, t + 10.0), y, method="Radau", jac=jac, rtol=1e-10,
                        atol=np.r_[1e-19, 1e-17, np.full(n, 1e-16)], events=events,
                        max_step=0.05 * vs * MASS / max(abs(y[2:].sum()), 1e-3) if inside else np.inf)
        assert sol.status == 1
        te, i = min((float(e[0]), i) for i, e in enumerate(sol.t_events) if len(e))
        t, y = te, sol.y_events[i][0].copy()
        if i == n + 1:
            inside = not inside
            continue
        if i == 0:
            s, slip[:], y[1], inside = -s, False, 0.0, True
            rows.append((t, y[0], y[2:].sum()))
        else:
            slip[i - 1] = True
    return np.array(rows)


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
