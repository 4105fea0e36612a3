"""GMS Motion fits with the parameters a fast-sliding record cannot pin held (the harness
``python -m prefriction.identify._success_events --fix C,Fs``).

Reference independent of the code: the record is scipy's DOP853 integration of GMS's published
equations with every reversal and slip located as a terminal event
(prefriction.identify.synthetic_events), quantised and noisy; the truth it was made with.
"""

from __future__ import annotations

import pytest

from prefriction.identify._success_events import EVENT_STAGES, EventStage, event_fit


@pytest.mark.slow
def test_gms_with_c_and_fs_held_lands_and_covers_from_a_factor_two_start():
    """GMS(2) + offset, 1,000 samples, k, Fc, mass and offset started within a factor 2 (seed 0),
    C and Fs held at their true values: converges, every estimate within 5 % of the truth and
    every 95 % interval holds it."""
    gms = EVENT_STAGES[1]
    stage = EventStage(gms.name, gms.friction, gms.fixed + ("C", "Fs"))
    f = event_fit(stage, 1000, 0, 2.0)
    assert f.converged and f.landed and f.covered, f
