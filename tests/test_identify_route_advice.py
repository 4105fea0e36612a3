"""The route advice of a Motion fit that did not converge (``identify/fit.py``).

The route check (:func:`prefriction.identify.recommend`) replays the record through the static
inverse model (mass, Coulomb, viscous, offset). On an open-loop record ruled by pre-sliding (the
elasto-plastic stage of ``python -m prefriction.identify._success_events``) that replay leaves the
positions within 10 samples, and the check calls the record closed-loop. A failed fit whose own
chain from the first sample follows the record must not then advise ``identify.fit_inverse``.
Reference: the scipy integration of the record (noise-free positions), standing in for a chain
of the true model; a chain that drifts keeps the advice.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from prefriction.identify import _success_events as se
from prefriction.identify.fit import _route_advice
from prefriction.identify.routes import recommend


def test_no_closed_loop_advice_where_the_fits_own_chain_follows_the_record() -> None:
    stage = next(s for s in se.EVENT_STAGES if s.name.startswith("ElastoPlastic"))
    run = se.event_run(stage.friction, 600)
    data = se.event_record_quantised(stage.friction, 600, 0, run)
    rec = recommend(data)
    assert rec.route == "inverse" and rec.horizon < 600 // 8          # the static replay's verdict
    true_chain = run[2].x - data.x                                     # within the encoder's error
    assert np.max(np.abs(true_chain)) < rec.tolerance
    assert _route_advice(data, SimpleNamespace(chain=true_chain)) == ""
    drift = true_chain + np.linspace(0.0, 10.0 * rec.tolerance, true_chain.size)
    assert "identify.fit_inverse" in _route_advice(data, SimpleNamespace(chain=drift))
    assert "identify.fit_inverse" in _route_advice(data)               # no chain: the check's advice
