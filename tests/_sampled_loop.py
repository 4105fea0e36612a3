"""The sampled stage both native-sampled-loop test files use: the 10 kHz PID around a 1 kg stage
tracking a 5 um sine, its models, the agreement of a native run with CasADi's loop, and the
independent reference of a Dahl loop: python-control's discrete PID around ``solve_ivp``."""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import controllers
from prefriction.signals import Sine

TS, STROKE = 1e-4, 5e-6  # s, m
REF = Sine(0.5 * STROKE, 50.0, phase=-math.pi / 2, offset=0.5 * STROKE)
MODELS = {
    "dahl": pf.Dahl(sigma=1e6, Fc=1.0),
    "lugre": pf.LuGre(sigma0=1e6, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3),
    "maxwell_slip": pf.MaxwellSlip([4e5, 3e5, 3e5], [0.3, 0.3, 0.4]),
}


def feedback(stage: pf.Oscillator, reference=REF) -> tuple[pf.LinearFeedback, object]:
    """The 10 kHz discrete PID (ZOH of the 150 Hz design) as a sampled LinearFeedback, and ``c2d``'s system."""
    Cd = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7).c2d(TS)
    return pf.LinearFeedback(A=Cd.A, B=Cd.B, C=Cd.C, D=Cd.D, Ts=TS, reference=reference), Cd


def agree(a: pf.SimulationResult, b: pf.SimulationResult, t_end: float) -> None:
    """Native ``a`` and CasADi ``b`` (each at rtol 1e-8): the same samples, applied force,
    controller states and reversals to 1e-8 of the stroke and of the run's length ``t_end`` [s]."""
    assert a.stats.steps is not None and b.stats.steps is None  # the native loop counts its steps; CasADi does not
    assert a.status == b.status and len(a.t) == len(b.t) > 10
    np.testing.assert_allclose(a.t, b.t, rtol=1e-13, atol=0)  # (CasADi: the break times to round-off)
    assert np.max(np.abs(a.x - b.x)) <= 1e-8 * STROKE
    assert np.max(np.abs(a.u - b.u)) <= 1e-7 * np.max(np.abs(b.u))
    assert np.max(np.abs(a.xc - b.xc)) <= 1e-8 * np.max(np.abs(b.xc))
    assert len(a.reversals) == len(b.reversals) >= 2
    np.testing.assert_allclose(a.reversals.t, b.reversals.t, rtol=0, atol=1e-8 * t_end)
    np.testing.assert_allclose(a.reversals.x, b.reversals.x, rtol=0, atol=1e-8 * STROKE)


def assert_dahl_loop_matches_reference(res: pf.SimulationResult, Cd: object, sigma: float, Fc: float, m: float,
                                       t_end: float, disturbance=None) -> None:
    """``res`` (the loop of :func:`feedback` around a Dahl stage, gamma = 1) against python-control's
    discrete PID (``Cd.output`` / ``Cd.dynamics``) around ``solve_ivp`` (DOP853, rtol 1e-12) of
    ``m x'' = u_k + d(t) - F``, ``F' = sigma (v - |v| F / Fc)``, ``u_k`` held over each period and
    ``d`` the ``disturbance`` [N] (a function of t [s], written from the equations by the caller):
    sample times, positions to 1e-7 of the stroke, applied forces ``u_k + d(t_k)`` to 1e-6 of their
    largest, and reversal times to 1e-8 of ``t_end`` [s]."""
    n_s = len(res.t)
    tk = np.arange(n_s) * TS
    y, xc = np.zeros(3), np.zeros(Cd.nstates)
    xs, us, rev = np.zeros(n_s), np.zeros(n_s), []
    d = disturbance if disturbance is not None else (lambda t: 0.0)

    def vzero(t, s, u):
        return s[1]

    def rhs(t, s, u):
        return [s[1], (u + d(t) - s[2]) / m, sigma * (s[1] - abs(s[1]) * s[2] / Fc)]

    for k in range(n_s):
        e = float(REF(tk[k])) - y[0]
        uk = float(Cd.output(tk[k], xc, [e])[0])
        us[k] = uk + d(tk[k])  # the applied force: held controller output and the input
        xs[k] = y[0]
        xc = np.asarray(Cd.dynamics(tk[k], xc, [e]), dtype=float)
        if k == n_s - 1:
            break
        if disturbance is None and uk == 0.0 and not np.any(y):  # at rest without force: v = 0 identically
            continue
        sol = solve_ivp(rhs, (tk[k], tk[k + 1]), y, method="DOP853", rtol=1e-12, atol=1e-20, events=vzero,
                        args=(uk,))
        rev += [t for t in sol.t_events[0] if t > tk[k]]
        y = sol.y[:, -1]
    np.testing.assert_allclose(res.t, tk, rtol=1e-12, atol=0)
    assert np.max(np.abs(res.x - xs)) <= 1e-7 * STROKE
    assert np.max(np.abs(res.u - us)) <= 1e-6 * np.max(np.abs(us))
    assert len(res.reversals) == len(rev) >= 2
    np.testing.assert_allclose(res.reversals.t, rev, rtol=0, atol=1e-8 * t_end)
