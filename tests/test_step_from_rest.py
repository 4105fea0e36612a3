"""A step force onto a mass at rest (issue 26, item 5), against scipy's Radau from the equations.

The mass rests (``v0 = 0``, ``F0 = 0``, no force) until the step at ``t = 10 ms``. The motion must
start at the step whatever samples are asked for: a dense call whose output interval ends at the
step used to keep the mass at rest (the jump of the rest-exit indicator fell between two output
intervals), so ``x`` stayed 0 and the first reversal came late or not at all.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf

T_STEP, U_STEP, T_END, MASS = 0.01, 0.8, 0.03, 1.0
LUGRE = dict(s0=1e5, s1=300.0, s2=0.4, Fc=1.0, Fs=1.5, vs=1e-3)
DAHL = dict(sigma=1e5, Fc=1.0)


def _rhs_lugre(t: float, y: np.ndarray) -> list[float]:
    """m x'' = u - F, z' = v - s0 |v| z / g(v), F = s0 z + s1 z' + s2 v (LuGre (1)-(3))."""
    x, v, z = y
    p = LUGRE
    g = p["Fc"] + (p["Fs"] - p["Fc"]) * np.exp(-((v / p["vs"]) ** 2))
    dz = v - p["s0"] * abs(v) * z / g
    F = p["s0"] * z + p["s1"] * dz + p["s2"] * v
    return [v, (U_STEP - F) / MASS, dz]


def _rhs_dahl(t: float, y: np.ndarray) -> list[float]:
    """m x'' = u - F, F' = sigma (v - |v| F / Fc) (Dahl, gamma = 1)."""
    x, v, F = y
    return [v, (U_STEP - F) / MASS, DAHL["sigma"] * (v - abs(v) * F / DAHL["Fc"])]


def _reference(rhs):
    """Radau from the step on (the mass rests before it), branch by branch to each zero of v
    (the sign of the new branch from the net force there)."""
    t0, y0, s, reversals, pieces = T_STEP, np.zeros(3), 1.0, [], []
    while t0 < T_END:
        stop = lambda t, y: y[1]
        stop.terminal, stop.direction = True, -s  # s v falls through zero
        sol = solve_ivp(rhs, (t0, T_END), y0, method="Radau", rtol=1e-12, atol=[1e-18, 1e-15, 1e-18],
                        events=stop, dense_output=True, first_step=1e-9)
        pieces.append((t0, sol.t[-1], sol.sol))
        if sol.status != 1:
            break
        t0, y0, s = sol.t[-1], sol.y[:, -1].copy(), -s
        y0[1] = 0.0
        reversals.append(t0)

    def x_of(t):
        t = np.minimum(np.atleast_1d(t), T_END)  # dense=True ends at t_end to round-off
        out = np.zeros(t.size)
        for a, b, f in pieces:
            k = (t >= a) & (t <= b)
            if k.any():
                out[k] = f(t[k])[0]
        return out
    return x_of, np.array(reversals)


@pytest.fixture(scope="module")
def references():
    return {"LuGre": _reference(_rhs_lugre), "Dahl": _reference(_rhs_dahl)}


def _system(name: str) -> pf.Oscillator:
    p = LUGRE if name == "LuGre" else DAHL
    model = pf.LuGre(*p.values()) if name == "LuGre" else pf.Dahl(*p.values())
    return pf.Oscillator(model, mass=MASS, u=pf.signals.Step(T_STEP, 0.0, U_STEP))


DENSE = {
    "two after the step": [0.0101, 0.011],
    "grid through the step": np.linspace(0.0, T_END, 61),
    "dense=True": True,
}


@pytest.mark.parametrize("name", ["LuGre", "Dahl"])
@pytest.mark.parametrize("which", list(DENSE))
def test_step_onto_rest_moves_whatever_samples(references, name: str, which: str) -> None:
    rtol = 1e-8
    x_ref, rev_ref = references[name]
    res = pf.simulate(_system(name), 0.0, t_end=T_END, rtol=rtol, dense=DENSE[which])
    scale = np.max(np.abs(x_ref(np.linspace(T_STEP, T_END, 2001))))
    err = np.abs(res.x - x_ref(res.t))
    assert np.max(err) <= 10 * rtol * scale, (which, np.max(err) / (rtol * scale))
    # the motion starts at the step: the first sample after it has moved (4e-9 m at 10.1 ms)
    after = res.t > T_STEP
    assert np.all(np.abs(res.x[after]) > 0)
    assert len(res.reversals.t) == len(rev_ref) >= (1 if name == "LuGre" else 0)  # Dahl creeps to 0.8 N
    np.testing.assert_allclose(res.reversals.t, rev_ref, rtol=10 * rtol)
