"""LoopResult.friction_loop for models other than Dahl: Maxwell-slip (exact branches) and LuGre
(the output samples with the reversals inserted).

References: Masing's rules for the Maxwell-slip model (Iwan 1966): from the unloaded state the
force follows the virgin curve ``phi(x) = sum_i sign(x) min(k_i |x|, W_i)``; after a reversal at
``(x_i, F_i)`` it follows ``F_i + 2 phi((x - x_i) / 2)`` while the half-cycles are nested,
written here from the element parameters. For LuGre the force depends on the velocity: the
curve must be the run's output samples and reversals in time order, and the position must be
monotone between two reversals (the velocity has no other zero).

The loops are those of ``tests/test_energy_loops.py`` (same structures: no new compile).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from prefriction import controllers
import prefriction as pf

M, R0, T_END = 1.0, 2e-5, 0.05
KP, KD, TAU = 3e4, 50.0, 1e-4
K, W = np.array([6e4, 3e4, 1e4]), np.array([0.2, 0.3, 0.5])
LUGRE = (1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3)  # sigma0, sigma1, sigma2, Fc, Fs, vs
T_OUT = np.concatenate((np.linspace(0.0, 1e-3, 201)[:-1], np.linspace(1e-3, T_END, 2000)))


def loop(model: pf.models.FrictionModel) -> controllers.LoopResult:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", controllers.UnstableLoopWarning)  # LuGre's linearisation
        return controllers.simulate_loop(pf.Oscillator(model, mass=M), controllers.pd(KP, KD, tau=TAU), R0, T_END,
                                         t_out=T_OUT, rtol=1e-11)


def virgin(y: np.ndarray) -> np.ndarray:
    """Masing's virgin curve of the elements [N] at displacement ``y`` [m]."""
    return np.sign(y) * np.minimum(np.abs(y)[:, None] * K, W).sum(axis=1)


@pytest.fixture(scope="module")
def ms_loop() -> controllers.LoopResult:
    return loop(pf.MaxwellSlip(K, W))


def test_maxwell_slip_curve_follows_masing_branches(ms_loop: controllers.LoopResult) -> None:
    rev = ms_loop.reversals
    xs = np.concatenate(([0.0], rev.x, [ms_loop.x[-1]]))
    swings = np.abs(np.diff(xs))
    assert len(rev) >= 4 and np.all(swings[1:] <= swings[:-1])  # nested half-cycles: Masing holds
    assert np.max(np.abs(rev.x)) * K.max() > W.min()  # an element slips: the branches are not linear
    lx, lF = ms_loop.friction_loop(points_per_branch=50)
    assert lx.size == 1 + 49 * (len(rev) + 1) and (lx[0], lF[0]) == (0.0, 0.0) and lx[-1] == ms_loop.x[-1]
    ref = np.empty_like(lF)
    for b in range(len(rev) + 1):
        part = slice(1 + 49 * b, 1 + 49 * (b + 1))
        ref[part] = virgin(lx[part]) if b == 0 else rev.F[b - 1] + 2.0 * virgin((lx[part] - rev.x[b - 1]) / 2.0)
    assert np.max(np.abs(lF - ref)) <= 1e-12 * W.sum()
    # the curve meets the simulator at every reversal and at the end
    np.testing.assert_allclose(lF[49 :: 49][: len(rev)], rev.F, rtol=0.0, atol=1e-8 * W.sum())
    assert lF[-1] == pytest.approx(ms_loop.F[-1], abs=1e-8 * W.sum())


def test_lugre_curve_is_the_samples_with_the_reversals() -> None:
    res = loop(pf.LuGre(*LUGRE))
    rev = res.reversals
    lx, lF = res.friction_loop()
    assert len(rev) >= 2 and lx.size == res.t.size + len(rev)
    k = np.searchsorted(res.t, rev.t, side="right") + np.arange(len(rev))  # where each reversal goes in time order
    np.testing.assert_array_equal(lx[k], rev.x)
    np.testing.assert_array_equal(lF[k], rev.F)
    rest = np.delete(np.arange(lx.size), k)
    np.testing.assert_array_equal(lx[rest], res.x)
    np.testing.assert_array_equal(lF[rest], res.F)
    for a, b in zip(np.concatenate(([0], k)), np.concatenate((k, [lx.size - 1]))):
        steps = np.diff(lx[a : b + 1])
        assert np.all(steps >= 0.0) or np.all(steps <= 0.0)  # the position turns at reversals only
    # the PD bound at rest is the static force: LuGre's bristles hold up to Fs (kp e = F at rest)
    assert res.error_bound == pytest.approx(LUGRE[4] / KP, rel=1e-12)
    assert "PD bound F_max/kp" in res.summary()


def test_points_per_branch_is_checked(ms_loop: controllers.LoopResult) -> None:
    with pytest.raises(ValueError, match="points_per_branch must be an integer >= 2, got 1"):
        ms_loop.friction_loop(points_per_branch=1)
    with pytest.raises(TypeError, match="points_per_branch must be an integer, got 2.5"):
        ms_loop.friction_loop(points_per_branch=2.5)
    with pytest.raises(ValueError, match=r"points_per_branch must be an integer <= 1_666_666, got 10000000000: "
                                         r"the limit \(memory: 6 branches\)"):
        ms_loop.friction_loop(points_per_branch=10**10)
