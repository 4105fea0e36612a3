"""The piece window of a long Motion fit (identify/pieces.py) against an independent scipy record.

The record: a 2.5 kg mass with Dahl friction (``gamma = 1``: ``dF/dt = sigma (v - |v| F / Fc)``,
Dahl (3.2)) and a force offset, driven open loop by a two-tone force held over each sample
(``m x'' = u - F - F_off``), integrated sample by sample by scipy's ``solve_ivp`` at tight
tolerances. Five reversals in 1,500 samples: a contiguous 600-sample window holds at most two.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import savgol_filter

from prefriction import Dahl
from prefriction.identify import Motion
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.motion_start import derivatives_of
from prefriction.identify.pieces import piece_window
from prefriction.identify.shooting import _directions, _layout, _Problem
from prefriction.identify.motion_step import segment_functions

MASS, SIGMA, FC, OFFSET = 2.5, 2e6, 3.0, 0.2
DT, N, WIDTH, K = 4e-4, 1_500, 600, 50


def _rhs(_t: float, y: np.ndarray, u: float) -> list[float]:
    x, v, F = y
    return [v, (u - F - OFFSET) / MASS, SIGMA * (v - abs(v) * F / FC)]


@pytest.fixture(scope="module")
def record() -> tuple[Motion, np.ndarray]:
    """The record (known mass) and the true ``[x, v, F]`` at every sample."""
    t = np.arange(N) * DT
    w = 2.0 * math.pi * 2.5 / (N * DT)
    u = 2.0 * FC * (np.sin(w * t) + 0.4 * np.sin(2.7 * w * t + 1.0))
    y = np.zeros((N, 3))
    for k in range(N - 1):
        sol = solve_ivp(_rhs, (t[k], t[k + 1]), y[k], args=(u[k],), rtol=1e-11, atol=[1e-15, 1e-12, 1e-9],
                        method="DOP853")
        y[k + 1] = sol.y[:, -1]
    return Motion(t, y[:, 0], u, MASS, "zoh"), y


def _reversals(v: np.ndarray) -> np.ndarray:
    return np.flatnonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0) + 1


def test_piece_window_cuts_whole_segments_around_reversals_of_both_directions(record):
    data, y = record
    rev = _reversals(y[:, 1])
    assert rev.size >= 4
    pieces = piece_window(data, 0, WIDTH, K)
    assert pieces is not None
    edges = np.r_[0, pieces.breaks, len(pieces)]
    assert len(pieces) <= WIDTH and np.all(np.asarray(pieces.breaks) % K == 0)
    dirs = set()
    for a, b, src, shift in zip(edges[:-1], edges[1:], pieces.source, pieces.shift):
        orig = np.arange(src, src + b - a)
        np.testing.assert_array_equal(pieces.x[a:b], data.x[orig])
        np.testing.assert_array_equal(pieces.u[a:b], data.u[orig])
        np.testing.assert_allclose(pieces.t[a:b] + shift, data.t[orig], rtol=0, atol=1e-12)
        inside = rev[(rev > src) & (rev < src + b - a)]
        assert inside.size >= 1                                    # every piece turns
        dirs |= {float(np.sign(y[r, 1])) for r in inside}
        if a:                                                      # one ordinary interval at the junction
            assert pieces.t[a] - pieces.t[a - 1] == pytest.approx(DT, rel=1e-9)
    assert dirs == {1.0, -1.0}


def test_piece_window_not_cut_when_the_contiguous_window_turns_often(record):
    data, _y = record
    assert piece_window(data, 0, len(data), K) is None           # the whole record as the window: all its reversals


def test_piece_window_not_cut_for_a_stage_resting_between_moves():
    """A point-to-point record (smoothstep moves of 300 samples, alternating, with rests of
    ``rest`` samples between them, as a closed loop's set-point changes): a 600-sample window's
    half (300 samples) cannot slide a 50-sample segment on both sides of a 400-sample rest, so no
    window of pieces is cut; with rests of 100 samples the same moves turn within it, and one is."""
    def moves(rest: int) -> Motion:
        s = np.linspace(0.0, 1.0, 300)
        up = 3.0 * s**2 - 2.0 * s**3
        x = np.concatenate([np.concatenate([1e-4 * (up if k % 2 == 0 else 1.0 - up), np.full(rest, 1e-4 * (k % 2 == 0))])
                            for k in range(8)])
        t = np.arange(x.size) * DT
        return Motion(t, x, np.zeros_like(x), MASS, "zoh")

    assert piece_window(moves(400), 0, WIDTH, K) is None
    pieces = piece_window(moves(100), 0, WIDTH, K)
    assert pieces is not None and len(pieces.breaks) >= 1


def test_node_values_are_smoothed_within_each_piece(record):
    data, _y = record
    pieces = piece_window(data, 0, WIDTH, K)
    xs, v, a = derivatives_of(pieces, 7)
    edges = np.r_[0, pieces.breaks, len(pieces)]
    for lo, hi in zip(edges[:-1], edges[1:]):
        h = float(np.mean(np.diff(pieces.t[lo:hi])))
        np.testing.assert_allclose(v[lo:hi], savgol_filter(pieces.x[lo:hi], 7, 3, deriv=1, delta=h), rtol=1e-12)
        np.testing.assert_allclose(a[lo:hi], savgol_filter(pieces.x[lo:hi], 7, 3, deriv=2, delta=h), rtol=1e-12)


def test_each_piece_is_simulated_from_its_own_start_and_the_junction_carries_no_constraint(record):
    data, y = record
    pieces = piece_window(data, 0, WIDTH, K)
    model = Dahl(sigma=SIGMA, Fc=FC, gamma=1.0)
    space = ParameterSpace(model, None, ["gamma"], None, mass=None, offset=FC, offset0=OFFSET)
    _x, v, _a = derivatives_of(pieces, 7)
    X, V = FC / SIGMA, FC / math.sqrt(MASS * SIGMA)
    lay = _layout(pieces, K, _directions(pieces.t, pieces.x, v, None), np.array([X, V]))
    prob = _Problem(model, space, pieces, lay, 8, False, MASS, 1e-9, native=False)
    single = segment_functions(model, space, K, 8, False, False)[0]
    # the true state at every node (scipy), the log-gap z = -ln(1 - s F / Fc) of Dahl (3.2)
    orig = np.concatenate([np.arange(s, s + b - a) for s, a, b in
                           zip(pieces.source, np.r_[0, pieces.breaks], np.r_[pieces.breaks, len(pieces)])])
    nodes = []
    for k, s in zip(lay.nodes, lay.s):
        xt, vt, Ft = y[orig[k]]
        nodes += [xt / X, vt / V, -math.log(max(1.0 - s * Ft / FC, 1e-14))]
    w = np.r_[space.theta0, nodes]
    # every node after a piece's start from the segment before (single shooting within each piece)
    w = prob.carry_states(w, single, everything=True)
    r, g = prob.plain_eval(w)
    n_breaks = len(pieces.breaks)
    assert g.size == prob.ny * (lay.J - 1 - n_breaks)             # no continuity rows into a piece's start
    np.testing.assert_array_less(np.abs(g), 1e-9)
    # the positions of each piece against scipy's, from the piece's own true start
    assert np.max(np.abs(r * prob.xs)) < 1e-3 * X
    # a residual of one piece does not depend on another piece's start state
    J = prob.reduced_jacobian(w)
    piece_of_row = np.searchsorted(np.asarray(pieces.breaks), pieces_samples(prob), side="right")
    for p in range(n_breaks + 1):
        cols = prob.nth + prob.ny * p + np.arange(prob.ny)
        assert np.all(J[piece_of_row != p][:, cols] == 0.0)
        assert np.any(J[piece_of_row == p][:, cols] != 0.0)


def pieces_samples(prob: _Problem) -> np.ndarray:
    """The sample (in the concatenation) of every residual row of ``prob``."""
    return prob.samples[prob.rows]


def test_window_weak_names_an_unpinned_parameter_and_a_stopped_fit():
    """``_window_weak``: a converged window whose residuals do not move with ``sigma`` (its
    Jacobian column zero, the other columns random) leaves ``sigma`` unpinned; with every column
    random it can start the record; a fit that did not converge cannot."""
    from prefriction.identify.continuation import _window_weak
    from prefriction.identify.shooting import MotionSolution

    space = ParameterSpace(Dahl(sigma=SIGMA, Fc=FC, gamma=1.0), None, ["gamma"], None, mass=None, offset=FC,
                           offset0=OFFSET)
    rng = np.random.default_rng(3)
    J = rng.standard_normal((400, space.n_free + 3))
    w = np.r_[space.theta0, np.zeros(3)]
    r = 1e-3 * rng.standard_normal(400)

    def solution(jac: np.ndarray, success: bool) -> MotionSolution:
        return MotionSolution(w, r, jac, None, np.zeros(400), {}, "stopped at max_iter", success)

    assert _window_weak(solution(J, True), space) == ""
    loose = J.copy()
    loose[:, space.free.index("sigma")] = 0.0
    weak = _window_weak(solution(loose, True), space)
    assert "sigma" in weak and "Fc" not in weak
    assert _window_weak(solution(J, False), space).startswith("did not converge (stopped at max_iter")


def test_long_hovers_flag_runs_of_three_slow_segments_and_the_moves_keep_the_rest():
    """A stage that moves (speed 1), rests for 200 samples (speed 0) and moves again: with
    50-sample segments the rest covers segments 4 to 7 (each holds at least ten consecutive slow
    samples; segment 3 ends on the rest's first sample), a run of four, so those are left out and
    the moves are the samples 0 to 199 and 400 to the end, each a whole number of segments."""
    from prefriction.identify.pieces import moves_of
    from prefriction.identify.hovers import hover_nodes, long_hovers

    n = 601
    speed = np.ones(n)
    speed[200:400] = 0.0
    nodes = np.arange(12) * K
    long = long_hovers(speed, nodes, K)
    assert np.flatnonzero(long).tolist() == [4, 5, 6, 7]
    assert np.flatnonzero(hover_nodes(speed, nodes, K)).tolist() == [5, 6, 7, 8]   # the nodes after them
    short = speed.copy()
    short[300:400] = 1.0                                          # a rest of 100 samples: two segments, kept
    assert not np.any(long_hovers(short, nodes, K))

    t = np.arange(n) * DT
    x = np.cumsum(speed) * 1e-8
    data = Motion(t, x, np.sin(t), MASS, "zoh")
    moves = moves_of(data, long, K)
    assert moves.source == (0, 400) and moves.breaks == (200,) and len(moves) == 200 + 201
    np.testing.assert_array_equal(moves.x, np.r_[x[:200], x[400:]])
    np.testing.assert_array_equal(moves.u, np.r_[data.u[:200], data.u[400:]])
    np.testing.assert_allclose(moves.t[200:] + moves.shift[1], t[400:], rtol=0, atol=1e-12)
    assert moves.t[200] - moves.t[199] == pytest.approx(DT, rel=1e-9)   # one ordinary interval at the junction
    assert moves_of(data, np.zeros(12, dtype=bool), K) is None          # nothing left out
    assert moves_of(data, np.ones(12, dtype=bool), K) is None           # nothing left


def test_moves_fit_is_the_result_only_where_its_misfit_is_of_the_noise(monkeypatch):
    """``_without_hovers`` fits the moves of a record with a long rest and keeps that fit only if
    its rms residual is within ``MISFIT`` times the record's position noise (the noise
    estimate of ``identify.derivatives``, here of Gaussian noise of 3 nm on smooth moves): a
    solver stand-in returning residuals of 1 nm rms is kept, with the moves as its data; one
    returning 100 nm rms (a local minimum) is not, and the note says why (the next stage of a
    continuation still fits the moves first: ``moves_converged``)."""
    import dataclasses

    from prefriction.identify import hovers, layouts, shooting
    from prefriction.identify.pieces import Pieces, moves_of

    n = 1_201
    t = np.arange(n) * DT
    s = np.clip((t - t[100]) / (t[500] - t[100]), 0.0, 1.0)
    x = 1e-4 * (3.0 * s**2 - 2.0 * s**3) + 3e-9 * np.random.default_rng(0).standard_normal(n)
    x[700:] += 1e-4 * (3.0 * np.clip((t[700:] - t[700]) / (t[1100] - t[700]), 0, 1)**2
                       - 2.0 * np.clip((t[700:] - t[700]) / (t[1100] - t[700]), 0, 1)**3)
    data = Motion(t, x, np.zeros(n), MASS, "zoh")
    space = ParameterSpace(Dahl(sigma=SIGMA, Fc=FC, gamma=1.0), None, ["gamma"], None, mass=None, offset=FC,
                           offset0=OFFSET)
    w = np.r_[space.theta0, np.zeros(3)]
    whole = shooting.MotionSolution(w, np.zeros(n), np.zeros((n, w.size)), None, np.zeros(n), {}, "stopped", False)

    def run(rms: float) -> tuple[shooting.MotionSolution, list[str]]:
        def stand_in(model, moves, *args, **kwargs):
            assert isinstance(moves, Pieces) and len(moves) < n        # the fit sees the moves alone
            r = rms * np.where(np.arange(len(moves)) % 2, 1.0, -1.0)
            return shooting.MotionSolution(w, r, np.zeros((r.size, w.size)), None, np.zeros(r.size), {}, "converged")
        monkeypatch.setattr(layouts, "_solve_record", stand_in)
        steps: list[str] = []
        _x, v, _a = derivatives_of(data, 7)
        moves = moves_of(data, hovers.long_hovers(np.abs(v), np.arange(24) * K, K), K)
        return layouts._without_hovers(data, moves, space, whole, None, 200, 1e-10, None, None, steps, 1), steps

    kept, steps = run(1e-9)
    assert isinstance(kept.data, Pieces) and kept.success and "FitResult.data holds the moves" in steps[0]
    assert kept.data.source == (0, 700) and kept.data.breaks == (500,)   # the 200-sample rest left out, not the short ones
    dropped, steps = run(1e-7)
    assert dropped == dataclasses.replace(whole, moves_converged=True)   # the chain's, the moves' convergence noted
    assert "local minimum" in steps[0] and "whole chain's result kept" in steps[0]


def test_a_cut_chain_far_above_the_noise_gives_way_to_the_moves(monkeypatch):
    """``layouts.solve_layouts``: a chain cut at the long hovers that converges with an rms residual above ``MISFIT``
    times the record's position noise (3 nm of Gaussian noise on smooth moves) is a local minimum,
    and the moves are fitted from its estimates; one within the limit is the result. The solver is a
    stand-in (whole chain: stopped; cut chain: converged at the given rms; moves: converged at 1 nm),
    so this tests the decision, not the fit."""
    from prefriction.identify import layouts, shooting
    from prefriction.identify.pieces import Pieces

    n = 1_201
    t = np.arange(n) * DT
    s = np.clip((t - t[100]) / (t[500] - t[100]), 0.0, 1.0)
    x = 1e-4 * (3.0 * s**2 - 2.0 * s**3) + 3e-9 * np.random.default_rng(0).standard_normal(n)
    data = Motion(t, x, np.zeros(n), MASS, "zoh")
    space = ParameterSpace(Dahl(sigma=SIGMA, Fc=FC, gamma=1.0), None, ["gamma"], None, mass=None, offset=FC,
                           offset0=OFFSET)
    w = np.r_[space.theta0, np.zeros(3)]

    def run(cut_rms: float) -> tuple[shooting.MotionSolution, list[str]]:
        def stand_in(model, record, sp, theta, n_sub, max_iter, tol, given, progress, weight, pieces=False,
                     least=1):
            m = len(record)
            r = (1e-9 if isinstance(record, Pieces) else cut_rms) * np.where(np.arange(m) % 2, 1.0, -1.0)
            done = isinstance(record, Pieces) or pieces
            return shooting.MotionSolution(w, r, np.zeros((m, w.size)), None, np.zeros(m), {},
                                           "converged" if done else "stopped", done)
        monkeypatch.setattr(layouts, "_solve_record", stand_in)
        steps: list[str] = []
        return layouts.solve_layouts(space.model, data, space, space.theta0, 2, 200, 1e-10, None, None, 0.01, steps), steps

    cut, steps = run(2e-9)
    assert cut.success and cut.data is None and len(steps) == 1 and steps[0].endswith("converged")
    moves, steps = run(1e-7)
    assert isinstance(moves.data, Pieces) and "more than 4 times the record's position noise" in steps[0]
    assert "FitResult.data holds the moves" in steps[1]


def test_static_start_of_pieces_stays_inside_each_piece() -> None:
    """The static least squares of a Pieces record: no window of the integrated force balance and no
    smoothing reaches across a junction, so the pieces of a seeded scipy record (Dahl ``gamma = 2`` +
    viscous, open loop) give the true mass, Coulomb force and offset as the whole record does (the
    windows across the junctions had made the estimates unphysical: ``None``)."""
    import dataclasses

    from prefriction.identify._success import STAGES, stage_record
    from prefriction.identify.motion_start import static_start
    from prefriction.identify.pieces import concatenate

    stage = dataclasses.replace(STAGES[2], closed=False, stroke=2.0)
    record = stage_record(stage, 1000, np.random.default_rng([0, 2]))
    for spans in ([(0, 300), (450, 700), (820, 1000)], [(0, 200), (300, 500), (600, 800), (850, 1000)]):
        s = static_start(concatenate(record, spans))
        assert s is not None
        assert abs(s.mass - stage.mass) < 0.02 * stage.mass and abs(s.Fc - 3.0) < 0.05 * 3.0
        assert abs(s.offset - stage.offset) < 0.02 * 3.0
