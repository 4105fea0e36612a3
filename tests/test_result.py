"""Result objects: compact repr, summary(), and success/status/message as scipy's OdeResult."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.reversals import ReversalTable
from prefriction.simulation.sweep import SweepResult

SYSTEM = pf.Oscillator(pf.Dahl(1e4, 1.0), mass=1.0)


def test_attributes_as_scipys_ode_result() -> None:
    """The names and meanings scipy uses: status 0 = end of the interval, 1 = a termination event."""
    ode = solve_ivp(lambda t, y: -y, (0.0, 1.0), [1.0])
    ended = pf.simulate(SYSTEM, 1.0, t_end=0.01)
    ref = pf.exact_reversals(SYSTEM, 1.0, 3)
    stopped = pf.simulate(SYSTEM, 1.0, reversals=3)
    for res in (ended, stopped):
        for name in ("status", "success", "message"):
            assert type(getattr(res, name)) is type(getattr(ode, name)), name
    assert ode.status == 0 and ended.status == 0 and ended.success
    assert ended.message == "reached t_end = 0.01 s"
    assert stopped.status == 1 and stopped.success
    assert stopped.message.startswith(f"reached 3 reversals at t = {ref.t[-1]:.6g}"[:30])


def test_simulation_result_repr_and_summary_are_compact() -> None:
    res = pf.simulate(SYSTEM, 1.0, reversals=20, dense=True)
    text = repr(res)
    assert text.startswith(f"SimulationResult(20 reversals, {len(res.t)} samples, status 1") and len(text) < 200
    summary = res.summary()
    assert str(res) == summary and len(summary.splitlines()) == 4 and len(summary) < 400
    assert "reversals: 20" in summary and f"samples: {len(res.t)}" in summary
    assert "array" not in summary and "\n[" not in summary


def test_reversal_table_repr_and_summary() -> None:
    tab = pf.exact_reversals(SYSTEM, 1.0, 200)
    text = repr(tab)
    assert text.startswith("ReversalTable(200 reversals in [") and len(text) < 160 and "array" not in text
    lines = tab.summary().splitlines()
    assert lines[0] == f"200 reversals in [{tab.t[0]:.9g}, {tab.t[-1]:.9g}] s"
    assert lines[2].startswith(f"last: t = {tab.t[-1]:.9g} s") and "E_p" in lines[2]
    # (2.10): the half-cycles dissipate E_0 - E_p(last); the printed total agrees with that balance
    total = float(lines[3].split("half-cycles ")[1].split(" J")[0])
    assert abs(total - (tab.E_0 - tab.E_p[-1])) <= 1e-5 * tab.E_0
    assert repr(ReversalTable(*(np.zeros(0),) * 5, E_0=0.5)) == "ReversalTable(0 reversals, E_0 = 0.5 J)"


def test_reversal_table_summary_without_stored_energy() -> None:
    nan = np.full(2, np.nan)  # a rate-dependent model (LuGre): no branch energy
    tab = ReversalTable(t=np.array([1.0, 2.0]), x=np.array([0.1, -0.1]), F=np.array([1.0, -1.0]),
                        E_p=nan, E_d=nan, E_0=0.25)
    summary = tab.summary()
    assert "not defined" in summary and "nan" not in summary


def test_sweep_result_status_success_message() -> None:
    ok = SweepResult(["a", "b"], wall_time=0.5)
    assert (ok.status, ok.success, ok.message) == (0, True, "all 2 runs succeeded")
    bad = SweepResult(["a", ValueError("v0 must be finite"), "c"], wall_time=0.5)
    assert bad.status == -1 and not bad.success  # scipy: -1 when the integration failed
    assert bad.message.startswith("1 of 3 runs failed (indices 1)") and "v0 must be finite" in bad.message
    assert repr(bad) == "SweepResult(3 runs, 1 failed, 0.50 s)"
    assert "[1] ValueError: v0 must be finite" in bad.summary()


def test_summary_names_the_model_events() -> None:
    """A saturating Dahl run (gamma = 0.3, one saturation in its first half-cycle) adds one line;
    ``events`` is an int array aligned with the reversals."""
    res = pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0, 0.3), 1.0), 0.03, reversals=5)
    assert res.events.tolist() == [1, 0, 0, 0, 0] and res.stats.events == 1
    lines = res.summary().splitlines()
    assert len(lines) == 4 and lines[2] == "model events: 1 (per half-cycle: events)"
