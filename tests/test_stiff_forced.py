"""A stiff forced run: GMS with a stiff slip law (``C = 1e7`` N/s) under a sine force. The forced
native driver detects the stiffness (the explicit step held by stability, 2.75 M steps for
0.2 s) and the run continues on Radau (``prefriction/simulation/stiff_forced.py``), saying so in
``result.message``. Reference: scipy's Radau on the GMS equations in SI with the force written
here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.signals import Sine
from prefriction.simulation.compiled import jit_available

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native driver needs a C compiler")

GMS_P = dict(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=1e7)
MASS, AMP, FREQ, T_END = 1.0, 2.0, 5.0, 0.5


def _reference() -> np.ndarray:
    """Reversals (t, x, F) of m x'' = u(t) - sum F_i, u = AMP sin(2 pi FREQ t), from rest with the
    first motion in +x; GMS elements: sticking F_i' = k_i v, slipping F_i' = s C (1 - s F_i /
    (alpha_i S(v))), S(v) = Fc + (Fs - Fc) exp(-(v/vs)^2); an element slips from
    s F_i = alpha_i S(v) on; at a reversal every element sticks again."""
    k, alpha = np.array(GMS_P["k"]), np.array(GMS_P["alpha"])
    Fc, Fs, vs, C = GMS_P["Fc"], GMS_P["Fs"], GMS_P["vs"], GMS_P["C"]
    S = lambda v: Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))
    u = lambda t: AMP * math.sin(2 * math.pi * FREQ * t)
    n = len(k)
    s, slip, t, y, rows = 1.0, np.zeros(n, bool), 0.0, np.zeros(n + 2), []
    inside = True  # within 5 vs of v = 0 (toggled by the band's events)
    while t < T_END:
        sl = slip.copy()

        def rhs(tt, yy, s=s, sl=sl):
            dF = np.where(sl, s * C * (1.0 - s * yy[2:] / (alpha * S(yy[1]))), k * yy[1])
            return np.r_[yy[1], (u(tt) - yy[2:].sum()) / MASS, dF]

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

        events = [lambda _t, yy, s=s: s * yy[1] + (1e-30 if yy[1] == 0.0 else 0.0)]
        for j in range(n):
            events.append(lambda _t, yy, j=j, s=s, sl=sl: 1.0 if sl[j] else alpha[j] * S(yy[1]) - s * yy[2 + j])
        events.append(lambda _t, yy, s=s, inside=inside: (5 * vs - s * yy[1]) if inside else (s * yy[1] - 5 * vs))
        for ev in events:
            ev.terminal, ev.direction = True, -1.0
        sol = solve_ivp(rhs, (t, T_END), y, method="Radau", jac=jac, rtol=1e-10,
                        atol=np.r_[1e-19, 1e-17, np.full(n, 1e-16)], events=events,
                        max_step=0.05 * vs * MASS / max(abs(u(t) - y[2:].sum()), 1e-3) if inside else np.inf)
        assert sol.status >= 0
        if sol.status == 0:
            break
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
