"""A Motion fit of a record's moves leaves every rest out (issue 25): a short rest kept inside a
move's piece of the chain traps the fit of a closed-loop Dahl ``gamma = 2`` stage in a misfit above
the measurement error, with intervals that miss the truth.

References independent of the fitter: the record and the true motion come from scipy LSODA
integrations of the equations (prefriction.identify._success.stage_record's loop, re-run with its
true state kept), and the measurement error is the rms of the recorded positions about the true
ones.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from prefriction import identify
from prefriction.identify import hovers
from prefriction.identify._success import STAGES, stage_record
from prefriction.identify.data import Motion
from prefriction.identify.motion_start import derivatives
from prefriction.identify.pieces import moves_of
from prefriction.identify.shooting import SEGMENT, node_starts

from _true_loop import true_run

DAHL = STAGES[2]      # Dahl gamma 2 + viscous + offset, 2.5 kg, 2 kHz, 10 nm encoder, closed loop


@pytest.fixture(scope="module")
def move_rest_move() -> tuple[Motion, float]:
    """Samples 200 to 699 of the seed-0 record at 2,500 samples (a move, a rest of about 60
    samples, the next move) and the rms [m] of its positions about the true ones."""
    data, state = true_run(DAHL, 2500, [0, 2], rtol=1e-12)
    assert np.array_equal(data.x, stage_record(DAHL, 2500, np.random.default_rng([0, 2])).x)  # the harness's record
    part = slice(200, 700)
    record = Motion(data.t[part], data.x[part], data.u[part], None, hold="zoh")
    return record, float(np.sqrt(np.mean(np.square(record.x - state[0, part]))))


@pytest.mark.slow   # a scipy record of 2,500 samples and a fit of 400 of them: about 40 s
def test_the_moves_without_a_short_rest_fit_to_the_measurement_error(move_rest_move):
    """Samples 200 to 699 of the seed-0 record at 2,500 samples: a move, a rest of about 60 samples
    (too short for a long hover) and the next move. Every rest left out (``least=1``), the fit of
    the two moves from the truth ends at the measurement error and every 95 % interval holds the
    truth; the rest is a long hover for nobody, so ``long_hovers`` keeps it."""
    record, error = move_rest_move          # error: noise and rounding, about 4.5e-9 m
    _x, v, _a = derivatives(record.t, record.x)
    nodes = node_starts(len(record), SEGMENT)
    assert not hovers.long_hovers(np.abs(v), nodes, SEGMENT).any()
    rests = hovers.long_hovers(np.abs(v), nodes, SEGMENT, least=1)
    assert 1 <= rests.sum() <= 3
    moves = moves_of(record, rests, SEGMENT)
    assert len(moves.source) == 2
    truth = DAHL.truth()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(DAHL.model(), moves, offset=True, offset0=truth["offset"], mass0=truth["mass"])
    assert res.success
    rms = float(np.sqrt(np.mean(np.square(res.residuals))))
    assert rms <= 1.1 * error
    for name, value in truth.items():
        lo, hi = res.interval(name)
        assert lo <= value <= hi, (name, lo, value, hi)


@pytest.mark.slow   # two fits of 500 samples: about 40 s
def test_a_stage_after_one_on_the_moves_fits_the_moves_first(move_rest_move):
    """``solve_layouts(..., moves_first=True)`` (the stage before converged on its moves): the
    moves, every rest left out, are the first layout fitted, and where they explain the record
    (within ``MISFIT`` times its noise) they are the solution, ``data`` the moves and
    ``moves_converged`` set; without it the whole chain through the rest is fitted and converges
    above the measurement error (the local minimum the rest makes)."""
    from prefriction.identify.layouts import solve_layouts
    from prefriction.identify.parameters import ParameterSpace

    record, error = move_rest_move
    truth = DAHL.truth()
    model = DAHL.model()
    space = ParameterSpace(model, None, None, None, mass=truth["mass"], offset=model.Fc, offset0=truth["offset"])
    theta = space.theta_of(dict(space.start))
    out = {}
    for first in (True, False):
        steps: list[str] = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out[first] = solve_layouts(model, record, space, theta, None, 200, 1e-8, None, None, 0.01, steps,
                                       moves_first=first), steps
    sol, steps = out[True]
    assert sol.success and sol.moves_converged and sol.data is not None and len(sol.data.source) == 2
    assert "the stage before converged on its moves" in steps[0]
    assert float(np.sqrt(np.mean(np.square(sol.residuals)))) <= 1.1 * error
    chain, steps = out[False]
    assert chain.data is None and not steps
    assert float(np.sqrt(np.mean(np.square(chain.residuals)))) > 1.3 * error
