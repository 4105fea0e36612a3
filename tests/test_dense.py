"""Dense output: the sample buffer, its memory against the arrays returned, samples vs scipy."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.simulation.samples import DENSE_STEP, SampleBuffer

SYSTEM = pf.Oscillator(pf.Dahl(1e4, 1.0, 1.0), mass=1.0)


def _sample(k: float, width: int) -> tuple:
    return (k, 2 * k, 3 * k, 4 * k, 5 * k, np.full(width, 6 * k))


@pytest.mark.parametrize("width", [0, 2])
def test_buffer_grows_in_place_and_keeps_every_sample(width: int) -> None:
    buf = SampleBuffer(width, capacity=3)
    for k in range(5):  # past the capacity: grows
        buf.append(_sample(float(k), width))
    ks = np.arange(5.0, 1000.0)
    buf.extend(ks, 2 * ks, 3 * ks, 4 * ks, 5 * ks, np.outer(6 * ks, np.ones(width)))
    buf.extend(np.array([1000.0]), [2000.0], [3000.0], [4000.0], 5000.0, np.full(width, 6000.0))
    assert len(buf) == 1001 and buf.capacity >= 1001
    assert [s[0] for s in buf][:3] == [0.0, 1.0, 2.0]
    t, x, v, F, Ef, xc = buf.columns()
    ref = np.arange(1001.0)
    for col, factor in zip((t, x, v, F, Ef), (1, 2, 3, 4, 5)):
        np.testing.assert_array_equal(col, factor * ref)
    assert xc.shape == (1001, width)
    np.testing.assert_array_equal(xc, np.outer(6 * ref, np.ones(width)))
    assert len(buf) == 0  # handed out


def test_dense_memory_near_the_returned_arrays() -> None:
    """Peak traced memory of a dense run <= 2x the arrays it returns + 0.5 MB (issue 10)."""
    pf.simulate(SYSTEM, 1.0, reversals=4, dense=True)  # load the compiled plant outside the trace
    tracemalloc.start()
    try:
        res = pf.simulate(SYSTEM, 1.0, reversals=500, dense=True)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    returned = sum(a.nbytes for a in (res.t, res.x, res.v, res.F, res.E_k, res.E_f))
    assert len(res.t) > 15_000 and len(res.reversals) == 500
    assert peak <= 2 * returned + 500_000, (peak, returned)


def _scipy_branches(v0: float, t_end: float) -> tuple:
    """Normalised Dahl gamma = 1 by DOP853 (rtol 1e-12) restarted at every reversal: a dense
    solution for each branch."""
    t0, y, s, sols = 0.0, np.array([0.0, v0, 0.0]), 1.0, []
    while t0 < t_end:
        def rev(t, z, s=s):  # noqa: ANN001, ANN202
            return s * z[1]

        rev.terminal, rev.direction = True, -1.0
        sol = solve_ivp(lambda t, z, s=s: [z[1], -z[2], z[1] * (1.0 - s * z[2])], (t0, t_end), y,
                        method="DOP853", rtol=1e-12, atol=1e-14, events=rev, dense_output=True)
        sols.append((t0, sol.t[-1], sol.sol))
        t0, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:
            y[1], s = 0.0, -s
    return sols


def test_dense_samples_against_scipy_with_restarts() -> None:
    """Every ``DENSE_STEP`` sample (x, v, F) of 40 reversals against an independent scipy solve."""
    res = pf.simulate(SYSTEM, 1.0, reversals=40, dense=True, rtol=1e-9)
    sc = pf.Scales.of(SYSTEM)
    t = res.t / sc.t
    np.testing.assert_allclose(np.diff(t), DENSE_STEP, rtol=1e-9)
    assert math.isclose(t[-1], res.reversals.t[-1] / sc.t, rel_tol=0, abs_tol=DENSE_STEP)
    sols = _scipy_branches(1.0 / sc.v, float(t[-1]) + 1e-9)
    ref = np.empty((3, len(t)))
    for a, b, sol in sols:
        inside = (t >= a) & (t <= b)
        ref[:, inside] = sol(t[inside])
    amp = np.hypot(ref[1], ref[2])  # the error control is relative to the current amplitude
    for got, want, scale in ((res.x / sc.x, ref[0], np.maximum(np.abs(ref[0]), 1.0)),
                             (res.v / sc.v, ref[1], amp), (res.F / sc.F, ref[2], amp)):
        assert np.max(np.abs(got - want) / scale) < 1e-7
