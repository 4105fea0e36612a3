"""``prefriction bench --native``: its numba references against scipy, and its verdicts.

The references of the native rows (``prefriction/cli/bench/numba_refs.py``) are held to scipy
integrations written from the same equations here; the row's verdict follows its ratio.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from prefriction.cli.bench.native_rows import NativeRow, main

numba_refs = pytest.importorskip("prefriction.cli.bench.numba_refs")
if not numba_refs.available():
    pytest.skip("numba is not installed (an optional extra)", allow_module_level=True)

SIGMA, FC, M = 1e4, 1.0, 1.0


def _dahl_scipy(u, t_end: float) -> np.ndarray:
    """Reversal times of forced Dahl (gamma = 1) from rest, scipy DOP853 restarted at each zero of v."""
    def rhs(t, y, s):
        x, v, F = y
        return [v, (u(t) - F) / M, SIGMA * v * (1.0 - s * F / FC)]

    def falling(t, y, s):  # s v turns negative: the reversal (a start at v = 0 rises: not one)
        return s * y[1]

    falling.terminal, falling.direction = True, -1.0
    t0, y0, s, times = 0.0, [0.0, 0.0, 0.0], 1.0, []
    while t0 < t_end:
        sol = solve_ivp(rhs, (t0, t_end), y0, args=(s,), method="DOP853", rtol=1e-12, atol=1e-15, events=falling)
        if sol.status != 1:
            break
        t0, y0 = float(sol.t_events[0][0]), list(sol.y_events[0][0])
        y0[1] = 0.0
        times.append(t0)
        s = -s
    return np.array(times)


@pytest.mark.slow  # numba compiles the integrator (about 10 s)
def test_numba_forced_dahl_against_scipy() -> None:
    w = 2 * np.pi * 5.0
    ref = _dahl_scipy(lambda t: 2.0 * math.sin(w * t), 0.5)
    scale = np.array([FC / SIGMA, FC / math.sqrt(SIGMA * M), FC])
    rev, _, steps = numba_refs.forced_run(numba_refs.DAHL, np.array([SIGMA, FC, M]), numba_refs.SINE,
                                          np.array([2.0, w]), np.zeros(1), np.zeros(1), np.zeros(3), 1.0, 0.5,
                                          1e-10, 1e-10 * scale, np.zeros(0))
    assert rev.shape[1] == len(ref) >= 4 and steps > 100
    assert np.max(np.abs(rev[0] - ref)) <= 1e-8


def test_numba_maxwell_slip_along_against_its_closed_form() -> None:
    """One element: elastic up to the slip force, then sliding; back elastic after the reversal."""
    x = np.array([0.0, 1e-5, 3e-5, 2e-5, -4e-5])
    F = numba_refs.maxwell_slip_along(x, np.array([1e4]), np.array([0.2]))
    np.testing.assert_allclose(F, [0.0, 0.1, 0.2, 0.1, -0.2], rtol=0, atol=1e-15)


def test_rows_pass_by_their_ratio(capsys: pytest.CaptureFixture) -> None:
    ok = NativeRow("a", "C", 2e-3, 1e-3, 1e-9, 1e-9, 2.0)
    bad = NativeRow("b", "numba", 7e-9, 1e-9, 1e-9, 1e-9, 3.0, erk_s=5e-8)
    assert "PASS" in ok.line() and "ratio  2.00" in ok.line()
    assert "FAIL" in bad.line() and "ns" in bad.line() and "CasADi path" in bad.line()
    assert main(rows=[ok]) == 0 and main(rows=[ok, bad]) == 1
    assert main(rows=[]) == 1 and "no reference available" in capsys.readouterr().out
