"""Every harmonic balance and its stability over all modes, against an independent simulation.

python-control's own ``H_multiple`` loop (``control/tests/descfcn_test.py``:
``4 / (s^3 + 2 s^2 + 2 s + 1)`` times a (5, 4) Pade delay) with Dahl friction (gamma = 1,
sigma = Fc = 1) in its feedback path, ``x = -H F``. python-control finds two intersections,
A = 1.159 (omega 1.411) and A = 4.743 (omega 0.577). Loeb's condition on the crossing pair
alone called the first stable; another mode grows there. The reference here integrates the loop
from its equations with scipy (DOP853, restarted at every velocity reversal, where Dahl's
right-hand side switches): motions started at both amplitudes settle on one cycle near 4.74.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from prefriction.describing import (DahlDescribingFunction, measure_limit_cycle, predict_limit_cycle,
                                    predict_limit_cycles)

H_MULTIPLE = control.tf([1], [1, 2, 2, 1]) * control.tf(*control.pade(5, 4)) * 4
AMPLITUDES = np.linspace(0.6, 6.0, 60)


def _simulate(x0: float, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """The loop x = -H F with dF/dt = sigma (1 - sgn(v) F / Fc) v (sigma = Fc = 1), from x(0) = x0 at rest."""
    S = control.ss(H_MULTIPLE)
    A, B, C = S.A, S.B[:, 0], S.C[0]
    CA = C @ A  # v = C A xh: H has relative degree 3, so C B = 0
    y, t, s = np.append(np.linalg.pinv(S.C)[:, 0] * x0, 0.0), 0.0, 1.0
    ts, xs = [], []
    while t < t_end:
        def turn(t_, y_):
            return CA @ y_[:-1]
        turn.terminal, turn.direction = True, -s
        sol = solve_ivp(lambda t_, y_: np.append(A @ y_[:-1] - B * y_[-1], (1.0 - s * y_[-1]) * (CA @ y_[:-1])),
                        (t, t_end), y, method="DOP853", rtol=1e-9, atol=1e-12, events=turn)
        ts.append(sol.t)
        xs.append(C @ sol.y[:-1])
        t, y = sol.t[-1], sol.y[:, -1]
        s = -s if sol.status == 1 else s
    return np.concatenate(ts), np.concatenate(xs)


@pytest.fixture(scope="module")
def settled() -> list:
    out = []
    for x0 in (0.3, 1.16):  # below and on the unstable balance
        t, x = _simulate(x0, 300.0)
        tt = np.linspace(200.0, 300.0, 20001)
        out.append(measure_limit_cycle(tt, np.interp(tt, t, x), t_start=200.0))
    return out


def test_both_intersections_with_their_stability() -> None:
    low, high = predict_limit_cycles(H_MULTIPLE, DahlDescribingFunction(1.0, 1.0), AMPLITUDES)
    assert low.amplitude == pytest.approx(1.1586, abs=1e-3) and low.omega == pytest.approx(1.4110, abs=1e-3)
    assert high.amplitude == pytest.approx(4.7434, abs=1e-3) and high.omega == pytest.approx(0.5775, abs=1e-3)
    assert not low.stable and low.growing and 0.3 < low.growing[0].imag < 0.7  # the mode that grows
    assert high.stable and high.growing == ()
    assert predict_limit_cycle(H_MULTIPLE, DahlDescribingFunction(1.0, 1.0), AMPLITUDES) == high


def test_stable_prediction_is_where_simulations_settle(settled) -> None:
    high = predict_limit_cycle(H_MULTIPLE, DahlDescribingFunction(1.0, 1.0), AMPLITUDES)
    for cyc in settled:  # the first harmonic of x settles within the describing function's error
        assert cyc.amplitude == pytest.approx(high.amplitude, rel=0.03)
        assert 2 * math.pi / cyc.period == pytest.approx(high.omega, rel=0.03)
    low = predict_limit_cycles(H_MULTIPLE, DahlDescribingFunction(1.0, 1.0), AMPLITUDES)[0]
    assert all(cyc.amplitude > 3 * low.amplitude for cyc in settled)  # nothing stays at the unstable one


@pytest.mark.parametrize("grid", [[math.nan], [1.0, math.nan], [2.0, 1.0], [0.0, 1.0]])
def test_bad_omega_grid_is_refused(grid) -> None:
    with pytest.raises(ValueError, match="omega_grid must be"):
        predict_limit_cycle(H_MULTIPLE, DahlDescribingFunction(1.0, 1.0), AMPLITUDES, omega_grid=grid)


@pytest.mark.parametrize("H, error, match", [
    ("1/(s+1)", TypeError, "H must be a python-control LTI"),
    (lambda s: 1 / (s + 1), TypeError, "H must be a python-control LTI"),
    (control.tf([[[1], [1]], [[1], [1]]], [[[1, 1], [1, 1]], [[1, 1], [1, 1]]]), ValueError, "H must be SISO"),
    (control.tf([1], [1, 1], dt=0.1), ValueError, "continuous-time"),
])
def test_bad_linear_part_is_refused(H, error, match) -> None:
    with pytest.raises(error, match=match):
        predict_limit_cycle(H, DahlDescribingFunction(1.0, 1.0), AMPLITUDES)


def test_block_without_describing_function_is_refused() -> None:
    with pytest.raises(TypeError, match="block must be"):
        predict_limit_cycle(H_MULTIPLE, np.sign, AMPLITUDES)


def test_measure_limit_cycle_bad_samples_are_named() -> None:
    with pytest.raises(ValueError, match="same length"):
        measure_limit_cycle([0.0, 1.0], [0.0, 1.0, 2.0], t_start=0.1)
    with pytest.raises(ValueError, match="strictly increasing"):
        measure_limit_cycle([0.0, 2.0, 1.0], [0.0, 1.0, 2.0], t_start=0.1)
    with pytest.raises(TypeError, match="y must be"):
        measure_limit_cycle([0.0, 1.0], ["a", "b"], t_start=0.1)
