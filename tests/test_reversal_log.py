"""The run's reversal log (four columns of doubles) and the reversal table built from it."""

from __future__ import annotations

import numpy as np
import pytest

import prefriction as pf
import prefriction.simulation.lazy_table as lazy_table
from prefriction.simulation.reversal_log import ReversalLog


def test_log_behaves_as_the_list_of_tuples() -> None:
    log = ReversalLog()
    assert len(log) == 0 and not log
    log.append((1.0, 2.0, 3.0, 4.0))
    log.extend([(5.0, 6.0, 7.0, 8.0), (9.0, 10.0, 11.0, 12.0)])
    assert len(log) == 3 and log and log[1] == (5.0, 6.0, 7.0, 8.0) and log[-1][0] == 9.0
    assert log.t[-1] - log.t[-2] == 4.0
    t, x, F, W = log.columns(2)
    assert t.tolist() == [1.0, 5.0] and W.tolist() == [4.0, 8.0]
    with pytest.raises(ValueError):
        t[0] = 0.0  # read-only views
    t, *_ = log.columns(writable=True)
    t *= 2.0  # a writable view converts the log in place
    assert log[0][0] == 2.0 and len(log.columns(0)[0]) == 0


def test_blocked_energies_match_the_exact_reversals(monkeypatch: pytest.MonkeyPatch) -> None:
    # energies computed in blocks of 7 reversals (the start in the first): E_p and E_d of the
    # exact reversal map, with the start's energy E_0 (F0 != 0: the start's branch energy counts)
    monkeypatch.setattr(lazy_table, "_ENERGY_BLOCK", 7)
    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=2.0, gamma=1.5), mass=0.5)
    res = pf.simulate(system, 0.4, F0=0.5, reversals=30)
    ref = pf.exact_reversals(system, 0.4, 30, F0=0.5)
    tab = res.reversals
    assert tab.E_0 == pytest.approx(ref.E_0, rel=1e-14)
    assert np.max(np.abs(tab.E_p / ref.E_p - 1.0)) < 1e-7
    assert np.max(np.abs(tab.E_d - ref.E_d) / ref.E_d) < 1e-6
    assert np.max(np.abs(tab.t / ref.t - 1.0)) < 1e-8
    assert isinstance(tab, lazy_table.LazyReversalTable) and isinstance(tab.eager(), pf.ReversalTable)
    np.testing.assert_array_equal(tab.eager().E_d, tab.E_d)


def test_lazy_table_pickles_and_computes_its_energies_once_read() -> None:
    """The table of a run pickles before its energies were read; both copies give the energies of
    the exact reversal map (Ruderman 2023, (3.9), (2.10))."""
    import pickle

    system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=2.0), mass=0.5)
    tab = pf.simulate(system, 0.4, reversals=12).reversals
    assert "_done" not in tab.__dict__  # not computed yet
    copy = pickle.loads(pickle.dumps(tab))
    ref = pf.exact_reversals(system, 0.4, 12)
    for t in (tab, copy):
        assert np.max(np.abs(t.E_p / ref.E_p - 1.0)) < 1e-7
        assert np.max(np.abs(t.E_d - ref.E_d) / ref.E_d) < 1e-6
        assert t.E_0 == pytest.approx(ref.E_0, rel=1e-14)
