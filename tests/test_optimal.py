"""prefriction.optimal: the optimal force lands on the target, replayed through simulate and
through an independent scipy integration of the Dahl/LuGre stage (restarted at every reversal
and force jump); the smoothed and bang-bang references miss; bad input is refused.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import optimal

DAHL = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)  # N/m, N, kg
LUGRE = pf.Oscillator(pf.LuGre(sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3), mass=1.0)
D, UMAX = 1e-3, 5.0  # [m], [N]


@pytest.fixture(scope="module")
def dahl_move():
    return optimal.point_to_point(DAHL, D, u_max=UMAX)


@pytest.fixture(scope="module")
def effort_move(dahl_move):
    return optimal.point_to_point(DAHL, D, u_max=UMAX, objective="effort", t_final=1.3 * dahl_move.t_final)


def _scipy_dahl(u, t_final, sigma=1e5, Fc=1.0, m=1.0):
    """x, v, F at t_final of m x'' = u - F, dF/dt = sigma v (1 - s F / Fc) (3.2, gamma = 1), from rest;
    restarted at each jump of the held force and at each reversal (s = sign of the net force)."""
    y, s, n_rev = np.zeros(3), math.copysign(1.0, u.u[0]), 0
    edges = list(u.t) + [t_final]
    for k in range(len(u.t)):
        t0, t1, uk = edges[k], min(edges[k + 1], t_final), u.u[k]
        while t0 < t1:
            if y[1] == 0.0:
                s = math.copysign(1.0, uk - y[2])

            def rhs(_, w, s=s, uk=uk):
                return [w[1], (uk - w[2]) / m, sigma * w[1] * (1.0 - s * w[2] / Fc)]

            def rev(_, w):
                return w[1]

            rev.terminal, rev.direction = True, -s
            sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-13, atol=[1e-18, 1e-15, 1e-14], events=rev)
            if sol.status == 1 and sol.t_events[0][0] < t1:
                t0, y = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
                y[1], n_rev = 0.0, n_rev + 1
            else:
                t0, y = t1, sol.y[:, -1]
    return y, n_rev


def test_time_optimal_force_lands_through_simulate(dahl_move):
    r = dahl_move
    assert abs(r.replay.x_error) <= 1e-9
    assert abs(r.replay.v_final) <= 1e-8 * np.max(np.abs(r.v))  # simulate's default rtol, relative to the motion
    assert abs(r.replay.F_final) <= 1e-5 * DAHL.friction.Fc
    assert np.max(np.abs(r.u.u)) <= UMAX * (1 + 1e-9)
    assert r.modes == (1.0, -1.0) and r.iterations > 0 and r.solve_time > 0


def test_time_optimal_force_lands_through_independent_scipy(dahl_move):
    y, n_rev = _scipy_dahl(dahl_move.u, dahl_move.t_final)
    assert abs(y[0] - D) <= 1e-9
    assert abs(y[1]) <= 1e-8 * np.max(np.abs(dahl_move.v))
    assert n_rev == len(dahl_move.modes) - 1  # one velocity sign per phase


def test_time_optimal_move_is_near_the_coulomb_bound_and_bang_bang(dahl_move):
    """The optimiser saturates the force on the long phase (a bang-bang arc at +u_max then -u_max)."""
    r, bb = dahl_move, optimal.bang_bang(DAHL, D, u_max=UMAX)
    main = r.u.u[: len(r.u.u) // 2]
    assert np.mean(np.abs(np.abs(main) - UMAX) < 1e-6 * UMAX) > 0.8
    assert 0.9 < r.t_final / bb.t_final < 1.2


def test_finer_control_grid_is_not_slower(dahl_move):
    """Halving the control intervals nests the piecewise-constant forces: the optimum cannot get worse
    (up to the RK4 error, far below this); the switch inside an interval converges at first order."""
    coarse = optimal.point_to_point(DAHL, D, u_max=UMAX, intervals=12)
    assert dahl_move.t_final < coarse.t_final
    assert coarse.t_final - dahl_move.t_final < 2e-3 * dahl_move.t_final  # 0.1 % measured


def test_effort_optimal_move_lands_and_costs_less(effort_move, dahl_move):
    e = effort_move
    assert e.t_final == pytest.approx(1.3 * dahl_move.t_final, rel=1e-9)
    assert abs(e.replay.x_error) <= 1e-9
    assert e.effort < dahl_move.effort
    y, _ = _scipy_dahl(e.u, e.t_final)
    assert abs(y[0] - D) <= 1e-9
    # the node effort is int u^2 dt of the held force
    assert e.effort == pytest.approx(float(np.sum(e.u.u[:-1] ** 2 * np.diff(e.u.t))), rel=1e-12)


def _scipy_lugre(u, t_final, sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3, m=1.0):
    """x, v at t_final of m x'' = u - F with LuGre (1)-(3) of Canudas de Wit et al. 1995 in SI units,
    from rest; Radau restarted at each jump of the held force and at each zero of v (the kink of |v|)."""
    y = np.zeros(3)  # x [m], v [m/s], z [m]
    edges = list(u.t) + [t_final]
    for k in range(len(u.t)):
        t0, t1, uk = edges[k], min(edges[k + 1], t_final), u.u[k]
        while t0 < t1:
            a0 = uk - sigma0 * y[2] - sigma2 * y[1]
            s = math.copysign(1.0, y[1] if y[1] != 0.0 else a0)

            def rhs(_, w, s=s, uk=uk):
                g = Fc + (Fs - Fc) * math.exp(-((w[1] / vs) ** 2))
                dz = w[1] - sigma0 * s * w[1] * w[2] / g  # |v| = s v on this branch
                return [w[1], (uk - sigma0 * w[2] - sigma1 * dz - sigma2 * w[1]) / m, dz]

            def rev(_, w):
                return w[1]

            rev.terminal, rev.direction = True, -s
            sol = solve_ivp(rhs, (t0, t1), y, method="Radau", rtol=1e-12, atol=[1e-16, 1e-13, 1e-18], events=rev)
            if sol.status == 1 and sol.t_events[0][0] < t1 and sol.t_events[0][0] > t0:
                t0, y = float(sol.t_events[0][0]), sol.y_events[0][0].copy()
                y[1] = 0.0
            else:
                t0, y = t1, sol.y[:, -1]
    return y


def test_lugre_move_lands_through_simulate_and_scipy():
    r = optimal.point_to_point(LUGRE, -5e-4, u_max=4.0, intervals=16)
    assert r.modes == (-1.0, 1.0)
    assert abs(r.replay.x_error) <= 1e-9
    assert abs(r.replay.v_final) <= 1e-8 * np.max(np.abs(r.v))
    y = _scipy_lugre(r.u, r.t_final)
    assert abs(y[0] + 5e-4) <= 1e-9
    assert abs(y[1]) <= 1e-8 * np.max(np.abs(r.v))


def test_smoothed_and_bang_bang_forces_miss_the_target():
    smooth = optimal.smoothed_point_to_point(DAHL, D, u_max=UMAX, v_smooth=1e-3)
    bb = optimal.bang_bang(DAHL, D, u_max=UMAX)
    for r in (smooth, bb):
        assert abs(r.replay.x_error) > 1e-6  # more than a micrometre
        y, _ = _scipy_dahl(r.u, r.t_final)
        assert y[0] - D == pytest.approx(r.replay.x_error, rel=1e-6)
    assert "tanh" in smooth.summary() and "nm" in smooth.summary()


def test_zero_order_hold_signal():
    u = pf.signals.ZeroOrderHold([0.0, 1.0, 2.0], [3.0, -1.0, 0.5])
    np.testing.assert_array_equal(u(np.array([-1.0, 0.0, 0.999, 1.0, 1.5, 2.0, 9.0])), [3, 3, 3, -1, -1, 0.5, 0.5])
    assert u.bound(1.5) == 3.0 and u.bound(0.5) == 3.0 and list(u.breaks()) == [0.0, 1.0, 2.0]
    assert list(u.piece(1.0, 2.0)) == [1.0, -1.0, 0.0]
    back = pickle.loads(pickle.dumps(u))  # process pools and dask ship signals
    assert list(back.t) == list(u.t) and list(back.u) == list(u.u)
    with pytest.raises(ValueError, match="strictly increasing"):
        pf.signals.ZeroOrderHold([0.0, 0.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="same length"):
        pf.signals.ZeroOrderHold([0.0, 1.0], [1.0])


@pytest.mark.parametrize(("kwargs", "error", "match"), [
    ({"u_max": 0.5}, ValueError, "u_max must exceed"),
    ({"u_max": 5.0, "objective": "effort"}, ValueError, "needs t_final"),
    ({"u_max": 5.0, "objective": "fast"}, ValueError, "objective"),
    ({"u_max": 5.0, "t_final": 1.0}, ValueError, "t_final"),
    ({"u_max": 5.0, "modes": (1.0, 1.0)}, ValueError, "alternate"),
    ({"u_max": 5.0, "modes": (-1.0, 1.0)}, ValueError, "away from the target"),
    ({"u_max": 5.0, "intervals": 10_000}, ValueError, "intervals"),
    ({"u_max": 5.0, "tol": -1.0}, ValueError, "tol"),
    ({"u_max": 5.0, "max_iter": 0}, ValueError, "max_iter"),
    ({"u_max": "5"}, TypeError, "u_max"),
])
def test_bad_input_names_the_argument(kwargs, error, match):
    with pytest.raises(error, match=match):
        optimal.point_to_point(DAHL, D, **kwargs)


def test_models_with_events_are_refused():
    stage = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0, gamma=0.5))
    with pytest.raises(ValueError, match="without flags or in-branch events"):
        optimal.point_to_point(stage, D, u_max=5.0, modes=(1.0, -1.0))
    with pytest.raises(ValueError, match="distance"):
        optimal.point_to_point(DAHL, 0.0, u_max=5.0)
    with pytest.raises(ValueError, match="system.u must be None"):
        optimal.point_to_point(pf.Oscillator(DAHL.friction, u=1.0), D, u_max=5.0)
    with pytest.raises(TypeError, match="system must be"):
        optimal.bang_bang(DAHL.friction, D, u_max=5.0)
    with pytest.raises(ValueError, match="v_smooth"):
        optimal.smoothed_point_to_point(DAHL, D, u_max=5.0, v_smooth=0.0)


def test_unloading_phase_ends_at_the_branch_zero_crossing_3_6(dahl_move):
    """The stage stops unloaded (F = 0) at the target: the reversal branch's zero crossing (3.6),
    from the reversal that simulate located, is the target; for a reversal from gross sliding
    (F = Fc) the overshoot is (Fc/sigma) ln 2."""
    rev = dahl_move.replay.run.reversals
    assert len(rev) == 1
    x0 = float(pf.dahl.zero_crossing(rev.x[0], rev.F[0], 1e5, 1.0, direction=-1))
    assert abs(x0 - D) <= 1e-9
    assert rev.F[0] == pytest.approx(1.0, abs=1e-4)  # reversed from gross sliding
    assert rev.x[0] - D == pytest.approx(1e-5 * math.log(2.0), rel=1e-4)
