"""The one-sample step of a Motion fit across a velocity reversal, against scipy.

A reversal is cut at the Euler-predicted zero of the velocity inside an RK4 sub-step
(``prefriction/identify/motion_step.py``). When that zero falls at the end of a sub-step, the
Runge-Kutta velocity at the cut may be left a little on the old side of zero. A step that took
that velocity for a turn back ran the next sub-step on the old branch with the new velocity: the
bristle of LuGre and of the elasto-plastic model (loaded, ``w = 1``) then grew at a fraction of
``v`` (LuGre: a third) instead of at ``v``, and the end state jumped by up to ``2.6e-3`` of ``Fc``
as the start moved the reversal across a sub-step boundary. That jump made the continuity defects of the 25,000-sample
ElastoPlastic fit of ``python -m prefriction.identify._success_events`` unresolvable.

Reference: scipy's DOP853 on the equations written out here (LuGre, Canudas de Wit et al. 1995;
elasto-plastic, Dupont et al. 2002, eqs. (7)-(9), ``alpha`` from its definition: it needs no
branch bookkeeping), restarted at the reversal.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.identify.motion_step import step_function

S0, S1, S2, FC, FS, VS, ZBA = 1e5, 100.0, 10.0, 1.0, 1.5, 5e-3, 5e-6
MASS, OFFSET, U = 1.0, 0.1, -0.5
DT = 0.1 * math.sqrt(MASS / S0)


def _fss(v: float) -> float:
    return FC + (FS - FC) * math.exp(-((v / VS) ** 2))


def _alpha(z: float, v: float, kind: str) -> float:
    if kind == "LuGre":
        return 1.0
    zss = _fss(v) / S0
    if math.copysign(1.0, z) != math.copysign(1.0, v) or abs(z) <= ZBA:
        return 0.0
    if abs(z) >= zss:
        return 1.0
    return 0.5 + 0.5 * math.sin(math.pi * (abs(z) - 0.5 * (zss + ZBA)) / (zss - ZBA))


def _reference(v0: float, zeta0: float, kind: str) -> np.ndarray:
    """``[x, v, zeta]`` after one sample of ``m x'' = U - F - F_off`` from ``[0, v0, zeta0]``
    (``zeta = sigma0 z / Fc``), scipy DOP853 restarted at the velocity's zero."""
    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        x, v, z = y
        dz = v - _alpha(z, v, kind) * S0 * abs(v) * z / _fss(v)
        return np.array([v, (U - (S0 * z + S1 * dz + S2 * v) - OFFSET) / MASS, dz])

    def stop(_t: float, y: np.ndarray) -> float:
        return y[1]
    stop.terminal = True  # type: ignore[attr-defined]

    atol = [1e-14 * FC / S0, 1e-14, 1e-14 * FC / S0]
    first = solve_ivp(rhs, (0.0, DT), [0.0, v0, zeta0 * FC / S0], method="DOP853", rtol=1e-12, atol=atol,
                      events=stop)
    assert first.status == 1                                 # the reversal lies inside the sample
    y = first.y[:, -1] * [1.0, 0.0, 1.0]
    y = solve_ivp(rhs, (first.t[-1], DT), y, method="DOP853", rtol=1e-12, atol=atol).y[:, -1]
    return np.array([y[0], y[1], y[2] * S0 / FC])


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["LuGre", "ElastoPlastic"])
@pytest.mark.parametrize("n_sub", [2, 4])
def test_end_state_is_continuous_across_a_reversal_at_a_substep_boundary(kind: str, n_sub: int) -> None:
    """Start velocities that move the reversal across sub-step boundaries: every end state within
    ``1e-6`` of the force unit of scipy's (the turn back missed it by up to ``2.6e-3``)."""
    if kind == "LuGre":
        model = pf.LuGre(sigma0=S0, sigma1=S1, sigma2=S2, Fc=FC, Fs=FS, vs=VS)
        start = [1.0, 1.0]                                   # zeta, s: saturated sliding forwards
    else:
        model = pf.ElastoPlastic(sigma0=S0, sigma1=S1, sigma2=S2, Fc=FC, Fs=FS, vs=VS, z_ba=ZBA)
        start = [1.0, 1.0, 0.0, 1.0]                         # zeta, broke, not saturated, s
    step = step_function(model, n_sub)
    pp = [MASS, S0, FC, OFFSET, *model.runtime_params()]
    X, V = FC / S0, FC / math.sqrt(MASS * S0)
    # the reversal moves through the second half of the sample: sub-step boundaries at 1/2, 3/4
    worst = np.zeros(3)
    for v0 in np.linspace(2.45e-4, 2.65e-4, 201):
        got = np.asarray(step([0.0, v0, *start], U, U, DT, pp)).ravel()
        assert got[-1] == -1.0                               # ends on the backward branch
        ref = _reference(v0, 1.0, type(model).__name__)
        worst = np.maximum(worst, np.abs(got[:3] - ref) / [X, V, 1.0])
    # measured at most 3.1e-8 (zeta), 8.5e-9 (x / X), 1.1e-8 (v / V); the turn back: 6.5e-4, 7.3e-6, 2.3e-4
    assert worst[2] < 1e-6 and worst[0] < 1e-7 and worst[1] < 1e-7, worst
