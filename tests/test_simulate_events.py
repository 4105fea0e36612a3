"""Model events counted by ``simulate`` (``result.events`` per half-cycle, ``stats.events`` in all)
against independent references:

- Maxwell-slip: the closed form, event by event, of :func:`prefriction.analysis.maxwell_slip_exact.maxwell_slip_trajectory`
  (its ``slips`` per half-cycle; an element that touches its slip force at a reversal, or slips
  within 1e-6 of it, is a near-coincidence that either count may resolve);
- GMS: the SI scipy reference ``GMSReference`` of ``tests/test_gms.py`` (DOP853 at rtol 1e-12
  with restarts at every reversal and slip), unforced and under a cosine force;
- Dahl with gamma < 1: unforced, a half-cycle saturates if and only if it ends at ``|F| = Fc``
  (``exact_reversals``); forced, the scipy reference ``dahl_reference`` of
  ``tests/test_accuracy.py`` (DOP853 at rtol 1e-13, restarted at every reversal and saturation).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import prefriction as pf
from prefriction.analysis.maxwell_slip_exact import maxwell_slip_trajectory

sys.path.insert(0, str(Path(__file__).parent))
from test_accuracy import dahl_reference  # noqa: E402  (the Dahl reference of the accuracy tests)
from test_gms import MASS, PD, P, GMSReference  # noqa: E402  (the reference of the GMS tests)
from test_maxwell_slip import ENDLESS, FINITE, TIES, slip_bounds  # noqa: E402  (the Maxwell-slip cases)


@pytest.mark.parametrize(("params", "v0n", "n"), [(FINITE, 2.2, 12), (ENDLESS, 2.2, 10), (TIES, 1.3, 8)])
def test_maxwell_slip_counts_are_the_closed_form(params, v0n, n) -> None:
    """Slips per half-cycle (unforced and with dense output, the two plants) within the closed
    form's bounds, exactly where no touch makes them ambiguous; two tied elements count 2."""
    system = pf.Oscillator(pf.MaxwellSlip(**params), mass=0.1)
    v0 = v0n * pf.Scales.of(system).v
    traj = maxwell_slip_trajectory(system, v0, n)
    lo, hi = slip_bounds(traj)
    assert int(np.sum(lo < hi)) <= n // 2
    for dense in (False, True):
        res = pf.simulate(system, v0, reversals=n, rtol=1e-10, dense=dense)
        assert res.events.dtype.kind == "i" and res.events.shape == (n,)
        assert np.all(lo <= res.events) and np.all(res.events <= hi), (dense, res.events, traj.slips)
        assert res.stats.events == res.events.sum()  # stopped at its last reversal
    if params is TIES:
        assert res.events[0] == 2 == traj.slips[0]


@pytest.mark.parametrize("params", [P, PD], ids=["undamped", "damped"])
def test_gms_unforced_counts_are_the_reference(params) -> None:
    system = pf.Oscillator(pf.GMS(**params), mass=MASS)
    v0 = 2.5 * pf.Scales.of(system).v
    _, slips = GMSReference(params, MASS).run(v0, n=14)
    for rtol in (1e-6, 1e-9):
        res = pf.simulate(system, v0, reversals=14, rtol=rtol)
        np.testing.assert_array_equal(res.events, slips[:14])


def test_gms_forced_counts_are_the_reference() -> None:
    """A cosine force through gross sliding and back 22 times in 0.1 s (0 to 3 slips per
    half-cycle), on the register plant: per half-cycle, and in all with those after the last
    reversal."""
    A, f = 1.3, 40.0
    u = pf.signals.Sine(amplitude=A, frequency=f, phase=math.pi / 2)
    system = pf.Oscillator(pf.GMS(**PD), mass=MASS, u=u)
    ref = GMSReference(PD, MASS, u=lambda t: A * math.cos(2.0 * math.pi * f * t))
    rows, slips = ref.run(0.0, t_end=0.1)
    assert len(rows) == 22 and slips.max() == 3 and slips.min() == 0
    times = np.linspace(0.0, 0.1, 401)[1:]
    res = pf.simulate(system, 0.0, t_end=0.1, rtol=1e-8, dense=times)
    np.testing.assert_array_equal(res.events, slips[:22])
    assert res.stats.events == slips.sum()
    assert f"model events: {slips.sum()}" in res.summary()


def test_dahl_saturations_against_the_reference() -> None:
    """gamma = 0.3: unforced, only the first half-cycle saturates (it ends at ``|F| = Fc``,
    ``exact_reversals``); forced at resonance (``u = 0.5 sin(w0 t)`` N), the saturations of each
    half-cycle as the scipy reference of ``tests/test_accuracy.py`` finds them."""
    system = pf.Oscillator(pf.Dahl(1e4, 1.0, 0.3), 1.0)
    ex = pf.exact_reversals(system, 0.03, 10)
    res = pf.simulate(system, 0.03, reversals=10, rtol=1e-8)
    np.testing.assert_array_equal(res.events, (np.abs(ex.F) >= 1.0 - 1e-12).astype(int))
    assert res.events[0] == 1 and res.stats.events == 1
    forced = pf.Oscillator(pf.Dahl(1e4, 1.0, 0.3), 1.0, u=pf.signals.Sine(0.5, 100.0 / (2.0 * math.pi)))
    sats: list = []
    rows = dahl_reference(0.3, 0.0, amp=0.5, w=1.0, t_end=50.0, s0=1.0, saturations=sats)
    assert sum(sats) >= 4 and 0 in sats[: len(rows)]
    res = pf.simulate(forced, 0.0, t_end=0.5, rtol=1e-8)
    assert len(res.reversals) == len(rows)
    np.testing.assert_array_equal(res.events, sats[: len(rows)])
    assert res.stats.events == sum(sats)
    assert pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0, 1.5), 1.0), 0.03, reversals=3).stats.events == 0
