"""The RK4 sub-steps of a Motion fit are refined until doubling them moves no estimate.

The reference is scipy: the records come from :func:`prefriction.identify._success.stage_record`
(LSODA at ``rtol = 1e-10`` on each sample interval, restarted at every reversal), independent
of the fitter's RK4.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from prefriction.identify.substep_check import step_shift


def test_step_shift_is_the_gauss_newton_step_in_standard_errors():
    """For residuals that differ by ``J delta`` the step is ``delta`` exactly (closed form), and
    it is measured in ``s sqrt((J^T J)^-1_ii)``; nuisance columns are not reported."""
    rng = np.random.default_rng(3)
    J = rng.standard_normal((400, 3))
    r = rng.standard_normal(400)
    delta = np.array([0.02, -0.05, 3.0])
    s = np.sqrt(r @ r / (400 - 3))
    se = s * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    got = step_shift(J, r, r + J @ delta, np.array([0, 1]))
    assert got == pytest.approx(max(abs(delta[:2]) / se[:2]), rel=1e-10)
    assert step_shift(J, r, r + J @ delta, np.array([2])) == pytest.approx(abs(delta[2]) / se[2], rel=1e-10)
    assert step_shift(J, r, np.full(400, np.nan), np.array([0])) == np.inf


@pytest.mark.slow
def test_heavy_stage_intervals_hold_the_truth():
    """95.1 kg, PID at 1 kHz, 50 nm encoder, Dahl (1,000 samples, scipy record): two RK4
    sub-steps per sample (what the step rule picks) put ``sigma`` more than 3 standard errors
    off; the automatic choice doubles them until the estimates settle, and every interval
    holds the true value."""
    from prefriction.identify._success import GRID, STAGES, stage_record
    from prefriction.identify.fit import fit
    from prefriction.identify.parameters import _entries

    i = next(k for k, st in enumerate(GRID) if st.name == "Dahl closed (PID) 95.1 kg 1 kHz 50 nm")
    stage = GRID[i]
    data = stage_record(stage, 1000, np.random.default_rng([1, len(STAGES) + i]))
    truth = stage.truth()
    start = stage.model()
    fixed = [e.name for e in _entries(start) if e.name not in stage.free]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        coarse = fit(start, data, fixed=fixed, mass0=stage.mass, substeps=2)
        res = fit(start, data, fixed=fixed, mass0=stage.mass)
    z2 = (coarse.estimate("sigma") - truth["sigma"]) / coarse.stderr[coarse.names.index("sigma")]
    assert abs(z2) > 3.0, "the record no longer shows the bias of two sub-steps; the test needs another record"
    assert res.success
    assert "RK4 sub-steps per sample (doubling 2 moved an estimate" in res.message
    for name, value in truth.items():
        lo, hi = res.interval(name)
        assert lo <= value <= hi, (name, value, lo, hi, res.message)
