"""Accuracy of ``simulate`` against an independent scipy reference written here from (3.2).

The reference (:func:`dahl_reference`) integrates the Dahl oscillator in normalised units
(``docs/mathematics.md#normalised-units``) with scipy DOP853 at ``rtol = 1e-13``, restarted at
every reversal and every saturation, without the package's plant or model code. On a branch of
direction ``s`` its state is ``(x, v, F)`` with ``F' = v (1 - s F)^gamma`` for gamma >= 1; for
gamma < 1 it is ``(x, v, r)`` with ``r = (1 - s F)^(1 - gamma)``, which (3.2) makes linear in
the position, ``r' = -(1 - gamma) s v``: saturation is the transversal zero of ``r``, after
which ``F = s`` until the next reversal. A zero of the velocity is a reversal if the net force
turns the mass back, else a touch.

Errors as in ``docs/bench.md#error``: times and forces relative to themselves, positions
relative to ``max(|x|, Fc / sigma)``; every case must have the reference's number of reversals.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.signals import Sine

SIGMA, MASS = 1e4, 1.0  # Fc = 1 N: the time unit is sqrt(m / sigma) = 0.01 s, the position unit 1e-4 m


def dahl_reference(gamma: float, v0: float, *, n: int | None = None, t_end: float = math.inf,
                   amp: float = 0.0, w: float = 1.0, s0: float | None = None,
                   saturations: list | None = None) -> np.ndarray:
    """Reversals ``(t~, x~, F~)`` of ``x~'' = amp sin(w t~) - F~`` from ``x = F = 0``, ``v~ = v0``
    (normalised units); the first ``n`` or those before ``t_end``. ``s0`` is the first direction
    when ``v0 = 0``. ``saturations``, if given, receives the number of saturations (0 or 1) of
    each half-cycle, the last one that after the last reversal."""
    e = 1.0 - gamma
    saturating = gamma < 1.0
    s = s0 if s0 is not None else math.copysign(1.0, v0)
    x, v, F, t, sat = 0.0, v0, 0.0, 0.0, False
    rows: list = []
    sats = [0]
    atol = 1e-15 * max(abs(v0), amp, 1e-300)
    while (n is None or len(rows) < n) and t < t_end:
        def force(y: np.ndarray, s: float = s, sat: bool = sat) -> float:
            if not saturating:
                return float(y[2])
            return s if sat else s * (1.0 - max(float(y[2]), 0.0) ** (1.0 / e))

        def rhs(tt: float, y: np.ndarray, s: float = s, sat: bool = sat) -> list:
            acc = amp * math.sin(w * tt) - force(y)
            if saturating:
                return [y[1], acc, 0.0 if sat else -e * s * y[1]]
            return [y[1], acc, y[1] * (1.0 - s * y[2]) ** gamma]

        def reversal(tt: float, y: np.ndarray, s: float = s) -> float:
            return s * y[1] + (1e-300 if y[1] == 0.0 else 0.0)  # positive at a branch start

        def saturation(tt: float, y: np.ndarray) -> float:
            return y[2]

        reversal.terminal, reversal.direction = True, -1.0
        saturation.terminal, saturation.direction = True, -1.0
        events = [reversal] + ([saturation] if saturating and not sat else [])
        y0 = [x, v, (0.0 if sat else (1.0 - s * F) ** e) if saturating else F]
        stop = t_end if t_end < math.inf else t + 1e5
        sol = solve_ivp(rhs, (t, stop), y0, method="DOP853", rtol=1e-13, atol=atol, events=events)
        assert sol.status >= 0, sol.message
        if sol.status == 0:
            break
        t, i = min((float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te))
        y = sol.y_events[i][0]
        x, v = float(y[0]), float(y[1])
        if i == 1:
            F, sat = s, True
            sats[-1] += 1
            continue
        F, v = force(y), 0.0
        if s * (amp * math.sin(w * t) - F) < 0.0:  # the net force turns the mass back
            rows.append((t, x, F))
            s, sat = -s, False
            sats.append(0)
    if saturations is not None:
        saturations.extend(sats)
    return np.array(rows).reshape(-1, 3)


def normalised(res: pf.SimulationResult) -> np.ndarray:
    """The reversal table of ``res`` as rows ``(t~, x~, F~)`` (``sigma = 1e4``, ``Fc = 1``, ``m = 1``)."""
    tab = res.reversals
    return np.column_stack([tab.t * 100.0, tab.x * SIGMA, tab.F])


def error(got: np.ndarray, ref: np.ndarray) -> float:
    """Largest relative error of times, positions (relative to max(|x|, 1)) and forces."""
    assert got.shape == ref.shape, f"{len(got)} reversals, the reference has {len(ref)}"
    scale = np.abs(ref)
    scale[:, 1] = np.maximum(scale[:, 1], 1.0)
    return float(np.max(np.abs(got - ref) / scale))


def test_reference_agrees_with_the_exact_map() -> None:
    """The reference itself against ``exact_reversals`` (closed-form branches and quadrature)."""
    for gamma, v0 in ((0.3, 2.0), (1.0, 1.0), (0.0, 0.5)):
        system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, gamma), MASS)
        ex = pf.exact_reversals(system, v0 / 100.0, 20)
        exact = np.column_stack([ex.t * 100.0, ex.x * SIGMA, ex.F])
        assert error(dahl_reference(gamma, v0, n=20), exact) <= 1e-11


def test_no_reversal_pair_missed_under_a_sine() -> None:
    """gamma = 0.5, ``u = 0.5 sin(5 t)`` N from rest: 30 reversals, two of them 1.8 ms apart near
    t = 0.131 s (the speed dips below zero inside one step at rtol 1e-6; 28 were found before
    the least-speed event), each within 10 rtol."""
    system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, 0.5), MASS, u=Sine(0.5, 5.0 / (2.0 * math.pi)))
    ref = dahl_reference(0.5, 0.0, amp=0.5, w=0.05, t_end=251.33, s0=1.0)
    assert len(ref) == 30 and ref[1, 0] - ref[0, 0] < 0.2
    for rtol in (1e-6, 1e-8):
        got = normalised(pf.simulate(system, 0.0, t_end=2.5133, rtol=rtol))
        assert error(got, ref) <= 10 * rtol


def test_gamma_0_below_saturation_conserves_energy() -> None:
    """gamma = 0 below saturation is the linear oscillator ``x~'' = -F~``, ``F~' = v~``: from
    ``x = F = 0`` the reversals are at ``t~ = (k - 1/2) pi`` with ``x~ = F~ = +-v0~`` (energy
    conserved). 500 reversals within 10 rtol at rtol 1e-6 (integrated, the energy drifted by
    17 rtol over 500 reversals and 340 rtol over 1e4); with ``t_end`` inside a half-cycle the
    reversals before it."""
    system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, 0.0), MASS)
    v0 = 0.5  # normalised: 0.005 m/s
    k = np.arange(1, 501)
    exact = np.column_stack([(k - 0.5) * math.pi, v0 * (-1.0) ** (k + 1), v0 * (-1.0) ** (k + 1)])
    for rtol in (1e-6, 1e-10):
        got = normalised(pf.simulate(system, v0 / 100.0, reversals=500, rtol=rtol))
        assert error(got, exact) <= 10 * rtol
        assert np.max(np.abs(got[:, 2] ** 2 / v0 ** 2 - 1.0)) <= rtol
    got = normalised(pf.simulate(system, v0 / 100.0, t_end=(20.3 * math.pi) / 100.0, rtol=1e-6))
    assert error(got, exact[:20]) <= 1e-5


def test_gamma_0_saturating_and_from_a_force() -> None:
    """gamma = 0 with a saturating first excursion (``v0~ = 2``), and released from ``F0 = 0.7 Fc``
    at rest: 200 reversals against the closed forms of ``exact_reversals`` within rtol."""
    system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, 0.0), MASS)
    for v0, F0 in ((0.02, 0.0), (0.0, 0.7)):
        ex = pf.exact_reversals(system, v0, 200, F0=F0)
        exact = np.column_stack([ex.t * 100.0, ex.x * SIGMA, ex.F])
        for rtol in (1e-6, 1e-10):
            got = normalised(pf.simulate(system, v0, F0=F0, reversals=200, rtol=rtol))
            assert error(got, exact) <= rtol


def test_response_far_below_its_forcing() -> None:
    """``u = 0.5 sin(30 w0 t)`` N from rest: the friction force reaches 1/30 of the forcing (its
    reversals 1/150 to 1/30). Reversal times within rtol, positions and forces within 10 rtol of their largest
    values (measured 0.9-1.3 rtol; with the error control relative to the forcing 18-49 rtol)."""
    w = 30.0  # normalised (w0 = 1)
    system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, 1.0), MASS, u=Sine(0.5, w * 100.0 / (2.0 * math.pi)))
    ref = dahl_reference(1.0, 0.0, amp=0.5, w=w, t_end=10.0, s0=1.0)
    assert len(ref) == 95 and np.max(np.abs(ref[:, 2])) < 0.5 / 25
    for rtol in (1e-6, 1e-9):
        got = normalised(pf.simulate(system, 0.0, t_end=0.1, rtol=rtol))
        assert got.shape == ref.shape
        assert np.max(np.abs(got[:, 0] / ref[:, 0] - 1.0)) <= rtol
        for col in (1, 2):
            assert np.max(np.abs(got[:, col] - ref[:, col])) <= 10 * rtol * np.max(np.abs(ref[:, col]))


def test_saturating_first_excursion_at_full_order() -> None:
    """0 < gamma < 1 from ``v0~ = 2`` (the first excursion saturates): 30 reversals within 3 rtol
    at rtol 1e-6 ... 1e-10 (measured 0.3-0.6; a Runge-Kutta step across the singular point
    ``(1 - e p)^(1/e)`` of saturation put 3-19 rtol into every position after it), one
    saturation counted."""
    for gamma in (0.3, 0.2, 0.1):
        system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, gamma), MASS)
        ref = dahl_reference(gamma, 2.0, n=30)
        for rtol in (1e-6, 1e-8, 1e-10):
            res = pf.simulate(system, 0.02, reversals=30, rtol=rtol)
            assert error(normalised(res), ref) <= 3 * rtol, (gamma, rtol)
            assert res.stats.events == res.events[0] == 1


def test_forced_saturation_at_full_order() -> None:
    """0 < gamma < 1 driven through saturation in every half-cycle (``u = 2 sin(0.7 w0 t)`` N from
    rest): reversals within 3 rtol of the reference at rtol 1e-6 ... 1e-10 (measured <= 1.2 rtol).
    The speed at each saturation comes from the branch's energy balance; taken from the dense
    output of the step across the singular point it put 27-236 rtol into the positions."""
    for gamma in (0.3, 0.25):
        system = pf.Oscillator(pf.Dahl(SIGMA, 1.0, gamma), MASS, u=Sine(2.0, 70.0 / (2.0 * math.pi)))
        sats: list = []
        ref = dahl_reference(gamma, 0.0, amp=2.0, w=0.7, t_end=50.0, s0=1.0, saturations=sats)
        assert len(ref) == 10 and sum(sats) >= 10
        for rtol in (1e-6, 1e-8, 1e-10):
            res = pf.simulate(system, 0.0, t_end=0.5, rtol=rtol)
            assert error(normalised(res), ref) <= 3 * rtol, (gamma, rtol)
            assert res.stats.events == sum(sats)
