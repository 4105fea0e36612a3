"""Valid input that used to end in a SolverError (issue 21), each run against an independent reference.

1. A continuous PID around LuGre whose loop is unstable in sliding (kp 100, ki 3e4, kd 0.1):
   the plain (no dense output) path stopped at t = 0.51 s at every rtol, because a call sized by
   the last half-cycles needed more steps than the integrator allows once the motion grew (the
   bristle time constant g(v) / (sigma0 |v|) shrinks with the speed). Reference: the closed loop
   written here from LuGre's equations (1)-(3) of Canudas de Wit et al. (1995) and the PID's
   formula ``u = kp e + ki int e + kd (e - xf) / tau``, integrated by scipy Radau at rtol 1e-11,
   restarted at every zero of the velocity (the sign of |v| changes there).
2. ``check_model(..., t_end=...)`` on a model whose motion dies out (an overdamped LuGre).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import controllers
from prefriction.simulation.feedback import LinearFeedback
from prefriction.testing import check_model
from prefriction.units import Scales

S0, S1, S2, FC, FS, VS, MASS = 1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3, 1.0
KP, KI, KD, R0 = 100.0, 3e4, 0.1, 1e-3


def _pid_lugre_reference(t_end: float, tau: float, rtol: float = 1e-11) -> np.ndarray:
    """Reversals ``(t, x)`` [s, m] of the PID loop around the LuGre stage from rest at x = 0."""

    def forces(y: np.ndarray, s: float) -> tuple[float, float, float, float]:
        x, v, z, xi, xf = y
        e = R0 - x
        u = KP * e + KI * xi + KD * (e - xf) / tau
        g = FC + (FS - FC) * math.exp(-(v / VS) ** 2)
        zd = v - S0 * s * v * z / g  # |v| = s v on a branch of direction s
        return u, S0 * z + S1 * zd + S2 * v, zd, e

    def rhs(_t: float, y: np.ndarray, s: float) -> list[float]:
        u, F, zd, e = forces(y, s)
        return [y[1], (u - F) / MASS, zd, e, (e - y[4]) / tau]

    y, t, s, revs = np.zeros(5), 0.0, 1.0, []
    atol = rtol * np.array([1e-6, 1e-3, 1e-5, 1e-8, 1e-6])
    while t < t_end:
        def stop(_t: float, y: np.ndarray, s: float) -> float:
            return s * y[1]

        stop.terminal, stop.direction = True, -1.0
        sol = solve_ivp(rhs, (t, t_end), y, method="Radau", rtol=rtol, atol=atol, events=stop, args=(s,))
        assert sol.status in (0, 1), sol.message
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:  # v = 0: the next branch follows the net force
            y[1] = 0.0
            u, F, _, _ = forces(y, s)
            s = 1.0 if u > F else -1.0
            revs.append((t, y[0]))
    return np.array(revs)


def test_unstable_pid_around_lugre_runs_on_the_plain_path() -> None:
    stage = pf.Oscillator(pf.LuGre(S0, S1, S2, FC, FS, VS), mass=MASS)
    pid = controllers.PID(kp=KP, ki=KI, kd=KD)
    C = pid.ss()
    fb = LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, reference=R0)
    t_end = 0.7  # the motion grows to 240 m/s; five reversals, the last four while it grows
    ref = _pid_lugre_reference(t_end, pid.tau)
    res = pf.simulate(stage, 0.0, t_end=t_end, feedback=fb, rtol=1e-8)  # stopped at 0.51 s
    assert res.success
    assert len(res.reversals.t) == len(ref) == 5
    np.testing.assert_allclose(res.reversals.t, ref[:, 0], rtol=1e-6)
    np.testing.assert_allclose(res.reversals.x, ref[:, 1], rtol=0, atol=1e-6 * np.max(np.abs(ref[:, 1])))


def _lugre_free_reference(model: pf.LuGre, v0: float, t_end: float) -> tuple[int, float]:
    """Reversals and position (normalised) at ``t_end`` of the unforced unit-mass LuGre
    oscillator from x = 0, z = 0, v = v0 > 0, by Radau restarted at every zero of v."""
    s1, s2 = model.sigma1 / math.sqrt(model.sigma0), model.sigma2 / math.sqrt(model.sigma0)
    fs, vs = model.Fs / model.Fc, model.vs * math.sqrt(model.sigma0) / model.Fc

    def rhs(_t: float, y: np.ndarray, s: float) -> list[float]:
        x, v, z = y
        g = 1.0 + (fs - 1.0) * math.exp(-(v / vs) ** 2)
        zd = v - s * v * z / g
        return [v, -(z + s1 * zd + s2 * v), zd]

    def zero_v(_t: float, y: np.ndarray, s: float) -> float:
        return s * y[1]

    zero_v.terminal, zero_v.direction = True, -1.0
    y, t, s, n = np.array([0.0, v0, 0.0]), 0.0, 1.0, 0
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="Radau", rtol=1e-12, atol=1e-15, events=zero_v, args=(s,))
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:
            y[1], s, n = 0.0, -s, n + 1
    return n, float(y[0])


def test_check_model_with_t_end_checks_a_motion_that_dies_out() -> None:
    overdamped = pf.LuGre(1e5, 1e3, 0.4, 1.0, 1.5, 1e-3)  # pre-sliding damping ratio 1.6
    with pytest.raises(ValueError, match=r"motion dies out: after 1 reversals .* give t_end"):
        check_model(overdamped, v0=1.5, reversals=4)  # was: "reversals differ ... by 1.31"
    out = check_model(overdamped, v0=1.5, reversals=4, t_end=30.0)
    # check_model's reference is independent of simulate; this one is also independent of check_model
    n_ref, x_ref = _lugre_free_reference(overdamped, 1.5, 30.0)
    assert out.n_reversals == n_ref == 1
    system = pf.Oscillator(overdamped, mass=1.0)
    sc = Scales.of(system)
    res = pf.simulate(system, 1.5 * sc.v, t_end=30.0 * sc.t, dense=[30.0 * sc.t])
    assert abs(res.x[-1] / sc.x - x_ref) <= 1e-7 * abs(x_ref)


def test_check_model_t_end_is_checked() -> None:
    with pytest.raises(ValueError, match="t_end"):
        check_model(pf.Dahl(1e4, 1.0), t_end=-1.0)
    with pytest.raises(ValueError, match="t_end must be a normalised time <= 1e"):
        check_model(pf.Dahl(1e4, 1.0), t_end=1e13)
