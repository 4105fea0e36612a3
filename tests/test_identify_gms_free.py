"""GMS Motion fits with the attraction rate C and the static force Fs free (identify/held_first.py,
identify/settled.py).

References independent of the code: the records from scipy's DOP853 integration of the GMS
equations with every reversal and slip located as a terminal event
(prefriction.identify.synthetic_events, through the record of prefriction.identify._success_events),
quantised and noisy; the truth they were made with; and, for the settled check, a linear least-
squares problem whose minimum is known in closed form.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from prefriction.identify.fit import fit
from prefriction.identify.settled import SETTLED, unsettled, unsettled_message
from prefriction.identify._success_events import EVENT_STAGES, MASS, OFFSET, _start, event_record_quantised

STAGE = next(s for s in EVENT_STAGES if s.name.startswith("GMS"))
TRUTH = {"k[0]": 6e4, "k[1]": 4e4, "Fc": 1.0, "Fs": 1.3, "C": 50.0, "mass": MASS, "offset": OFFSET}


def test_unsettled_measures_the_distance_to_a_known_minimum():
    """Linear residuals ``r = J (theta - theta*) + e`` with ``e`` orthogonal to ``J``: the
    Gauss-Newton step is ``theta* - theta`` exactly; an estimate displaced by 3 standard errors is
    reported with 3 (to rounding), one displaced by 0.5 is not, and neither is an estimate not
    pinned (its step is not judged)."""
    rng = np.random.default_rng(3)
    J = rng.standard_normal((400, 3))
    e = rng.standard_normal(400)
    e -= J @ np.linalg.lstsq(J, e, rcond=None)[0]          # orthogonal to the columns
    s2 = float(e @ e) / (400 - 3)
    se = np.sqrt(np.diag(np.linalg.inv(J.T @ J)) * s2)
    shift = np.array([3.0, 0.5, 4.0]) * se                 # theta - theta*, in standard errors
    r = J @ shift + e
    found = unsettled(J, r, ["a", "b", "c"], np.ones(3), se, np.array([True, True, False]))
    assert [n for n, _ in found] == ["a"]
    assert found[0][1] == pytest.approx(3.0, rel=1e-9)
    assert SETTLED < 3.0
    said = unsettled_message(found, (("c", "relative standard error 80 % > 50 %"),))
    assert "a by 3 standard errors" in said and "fixed=['c']" in said


def _fit(seed: int, n: int = 1000):
    data = event_record_quantised(STAGE.friction, n, seed)
    start, mass0 = _start(STAGE, 2.0, np.random.default_rng(1000 + seed))   # every free parameter up to 2x off
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(start, data, fixed=list(STAGE.fixed), offset=True, mass0=mass0)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 4])
def test_gms_with_c_and_fs_free_lands_from_a_factor_two_start(seed):
    """GMS(2) + offset, 1,000 quantised noisy samples, C, Fs, the stiffnesses, Fc, mass and offset
    free from a factor-2 start (10 to 40 s: slow): a success, every estimate the data pin within
    5 % of the truth (the offset within 5 % of Fc), every 95 % interval holds the truth, and C and
    Fs (the record slides far faster than vs and pins them only in a combination) are reported as
    not identifiable. (Seed 4's first fit stops short of the minimum, which the fit detects and
    continues from: identify/settled.py.)"""
    res = _fit(seed)
    assert res.success, res.message
    truth = np.array([TRUTH[k] for k in res.names])
    assert {"C", "Fs"} <= set(res.unidentifiable)
    inside = (res.low <= truth) & (truth <= res.high)
    assert np.all(inside), dict(zip(res.names, zip(res.low, res.high)))
    for name, est, true in zip(res.names, res.estimates, truth):
        if name not in res.unidentifiable:
            assert abs(est - true) <= 0.05 * (TRUTH["Fc"] if name == "offset" else abs(true)), (name, est)
    assert any("with C held" in line for line in res.start)
