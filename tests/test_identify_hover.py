"""Motion fits of records whose stage hovers about its set point (issue 25): the nodes inside a
hover start pieces of the shooting chain.

References independent of the fitter: the records and the true motion come from scipy LSODA
integrations of the equations (prefriction.identify._success.stage_record and the same loop
re-run here with its true state kept); the piecewise single-shooting Jacobian is checked against
central finite differences of the chained simulation.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from prefriction import identify
from prefriction.identify import hovers, shooting
from prefriction.identify._success import STAGES, stage_record, start_model
from prefriction.identify.motion_start import derivatives
from prefriction.identify.motion_step import segment_functions
from prefriction.identify.parameters import ParameterSpace, _entries

from _true_loop import true_run as _true_run

USER = STAGES[1]      # LuGre, 2.5 kg, 2e6 N/m, 3 N, 5 kHz, 10 nm encoder, closed loop
EMPS_LIKE = STAGES[3]


@pytest.mark.slow   # a scipy record of 2,000 samples: 10 to 20 s on a loaded machine
def test_hover_nodes_follow_the_slow_stretches_of_the_true_motion():
    """The nodes the data mark (after each segment of a long hover) follow segments in which the
    true stage lingers near rest, every node inside a long rest of the true stage is marked, and
    there the true stage hovers: it reverses again and again."""
    data, state = _true_run(USER, 2000, [0, 1])
    assert np.array_equal(data.x, stage_record(USER, 2000, np.random.default_rng([0, 1])).x)  # the harness's record
    v = state[1]
    _x, vs, _a = derivatives(data.t, data.x, shooting._NODE_WINDOW)
    K = shooting.SEGMENT
    nodes = np.arange(math.ceil((len(data) - 1) / K)) * K
    free = hovers.hover_nodes(np.abs(vs), nodes, K)
    slow = np.abs(v) <= hovers.HOVER * float(np.max(np.abs(v)))
    runs, flips = [], []
    for k in nodes[:-1]:                          # the true stage in each segment
        best = cur = 0
        for b in slow[k:k + K + 1]:
            cur = cur + 1 if b else 0
            best = max(best, cur)
        runs.append(best)
        flips.append(int(np.sum(np.diff(np.sign(v[k:k + K + 1])) != 0)))
    runs, flips = np.array(runs), np.array(flips)
    assert free.sum() >= 6
    assert np.all(runs[free[1:]] >= 5)                             # a marked node follows a slow stretch
    whole = runs == K + 1                                          # segments the true stage spends at rest
    inside = np.flatnonzero(whole[1:-1] & whole[:-2] & whole[2:]) + 1
    assert inside.size and np.all(free[inside + 1])                # the nodes inside long rests are marked
    assert np.median(flips[runs == K + 1]) >= 4                    # at rest the true stage hovers
    assert np.all(flips[runs == 0] == 0)                           # in the moves it does not


@pytest.mark.slow   # chained simulations of 600 samples: about 10 s on a loaded machine
def test_piecewise_jacobian_matches_finite_differences_of_the_chain():
    """The statistics' Jacobian with respect to the parameters and each piece's first node equals
    central differences of the residuals of the chain re-simulated from those values."""
    model = USER.model()
    data, state = _true_run(USER, 600, [5])
    space = ParameterSpace(model, None, ["sigma1", "vs"], None, mass=USER.mass, offset=3.0, offset0=USER.offset)
    _x, vs, _a = derivatives(data.t, data.x, shooting._NODE_WINDOW)
    K = 50
    X, V = model.Fc / model.sigma, model.Fc / math.sqrt(USER.mass * model.sigma)
    lay = shooting._layout(data, K, shooting._directions(data.t, data.x, vs, None), np.array([X, V]))
    free = np.zeros(lay.J, dtype=bool)
    free[[0, 4, 7]] = True                                          # three pieces
    lay = dataclasses.replace(lay, free=free)
    n_sub = shooting._substeps(model, data, USER.mass, float(np.max(np.abs(state[1]))), None)  # RK4 stable
    prob = shooting._Problem(model, space, data, lay, n_sub, True, USER.mass, 1e-6)
    single = segment_functions(model, space, K, n_sub, True)[0]
    w = np.r_[space.theta0, np.zeros(3 * lay.J)]
    for j in np.flatnonzero(free):                                  # each piece starts at the true state
        k = lay.nodes[j]
        w[space.n_free + 3 * j: space.n_free + 3 * j + 3] = [state[0, k] / X, state[1, k] / V,
                                                             model.sigma0 * state[2, k] / model.Fc]
    w = prob.carry_states(w, single, everything=True)
    r, g = prob.plain_eval(w)
    assert g.size == 3 * (lay.J - 3)                                # no continuity into a piece's start
    assert np.max(np.abs(g)) < 1e-9                                 # the chain is continuous inside each piece
    assert np.sqrt(np.mean(r**2)) * 1e-6 < 3.0 * USER.loop.quantum   # and follows the record (the truth)
    Jr = prob.reduced_jacobian(w)
    where = prob.columns()
    assert Jr.shape == (r.size, space.n_free + 3 * 3)
    for c in [*range(space.n_free), *range(space.n_free + 3, space.n_free + 6)]:   # parameters, 2nd piece's start
        h = 1e-6 * max(1.0, abs(w[where[c]]))
        plus, minus = w.copy(), w.copy()
        plus[where[c]] += h
        minus[where[c]] -= h
        rp = prob.plain_eval(prob.carry_states(plus, single, everything=True))[0]
        rm = prob.plain_eval(prob.carry_states(minus, single, everything=True))[0]
        fd = (rp - rm) / (2.0 * h)
        err = float(np.max(np.abs(Jr[:, c] - fd))) / max(float(np.max(np.abs(fd))), 1e-300)
        assert err < 2e-3, (c, err)                                 # central differences over the kinks of reversals


@pytest.mark.slow
@pytest.mark.parametrize("n", [10_000])
def test_user_stage_long_record_fits_from_a_factor_two_start(n):
    """The hovering 2.5 kg stage at 10,000 samples from a start within a factor 2 of the truth in
    every free parameter: converged, within 5 % of every true value."""
    data = stage_record(USER, n, np.random.default_rng([0, 1]))
    start, m0, off0 = start_model(USER, np.random.default_rng([7, 1]), 2.0)
    fixed = [e.name for e in _entries(start) if e.name not in USER.free]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(start, data, fixed=fixed, offset=True, mass0=m0, offset0=off0)
    assert res.success, res.message
    assert "start pieces of the chain" in res.message
    for name, truth in USER.truth().items():
        scale = USER.friction.Fc if name == "offset" else abs(truth)
        assert abs(res.estimate(name) - truth) <= 0.05 * scale, name


def test_border_variance_is_the_constrained_covariance_of_the_parameters():
    """``kkt_step``'s ``border_variance``: the parameters' diagonal of ``Z (Z^T J^T J Z)^-1 Z^T``,
    ``Z`` a basis of the constraints' null space (scipy), on a random shooting pattern with one
    parameter held."""
    import scipy.sparse as sp
    from scipy.linalg import null_space

    from prefriction.identify.kkt import kkt_step

    rng = np.random.default_rng(8)
    nth, ny, segments, per = 3, 2, 7, 9
    m = nth + ny * segments
    J = np.zeros((segments * per, m))
    A = np.zeros(((segments - 1) * ny, m))
    for j in range(segments):
        J[j * per:(j + 1) * per, :nth] = rng.standard_normal((per, nth))
        J[j * per:(j + 1) * per, nth + j * ny: nth + (j + 1) * ny] = rng.standard_normal((per, ny))
        if j < segments - 1:
            A[j * ny:(j + 1) * ny, :nth] = rng.standard_normal((ny, nth))
            A[j * ny:(j + 1) * ny, nth + j * ny: nth + (j + 1) * ny] = rng.standard_normal((ny, ny))
            A[j * ny:(j + 1) * ny, nth + (j + 1) * ny: nth + (j + 2) * ny] = -np.eye(ny)
    free = np.ones(m, dtype=bool)
    free[1] = False
    info: dict = {}
    kkt_step(sp.csr_matrix(J), sp.csr_matrix(A), rng.standard_normal(J.shape[0]), rng.standard_normal(A.shape[0]),
             free=free, border=nth, info=info)
    keep = np.flatnonzero(free)
    Z = null_space(A[:, keep])
    C = Z @ np.linalg.inv(Z.T @ J[:, keep].T @ J[:, keep] @ Z) @ Z.T
    np.testing.assert_allclose(info["border_variance"], np.diag(C)[:nth - 1], rtol=1e-8)
