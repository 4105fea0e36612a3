"""The native driver of unforced runs (docs/simulator.md#native) against the exact reversal map.

The driver and the compact CasADi loop it replaces (still used without a compiler) are each held
to ``exact_reversals`` (Ruderman 2023, (3.6)-(3.8): closed form for Dahl), on the same cases.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

import prefriction as pf
from prefriction.simulation.compiled import jit_available

pytestmark = pytest.mark.skipif(not jit_available(), reason="the native driver needs a C compiler")

RTOL = 1e-8


def _error(res: pf.SimulationResult, ref: pf.ReversalTable) -> float:
    """Largest relative error of reversal times, positions and forces against the exact map."""
    tab = res.reversals
    assert len(tab) == len(ref)
    scale = max(float(np.max(np.abs(ref.x))), 1e-300)
    return max(float(np.max(np.abs(tab.t / ref.t - 1.0))), float(np.max(np.abs(tab.x - ref.x))) / scale,
               float(np.max(np.abs(tab.F - ref.F) / np.abs(ref.F))))


@pytest.mark.parametrize("gamma", [1.0, 2.5])
def test_native_and_casadi_loops_both_follow_the_exact_map(gamma: float) -> None:
    """Dahl, 60 reversals from v0: both paths within 10 rtol of the closed form; the native run
    counts its steps (the compiled CasADi loop keeps none)."""
    system = pf.Oscillator(pf.Dahl(2e4, 0.7, gamma), mass=0.3)
    ref = pf.exact_reversals(system, 0.02, 60)
    native = pf.simulate(system, 0.02, reversals=60, rtol=RTOL)
    casadi = pf.simulate(system, 0.02, reversals=60, rtol=RTOL, jit=False)
    assert native.stats.jit in ("compiled", "cached") and native.stats.steps > 60
    assert _error(native, ref) <= 10 * RTOL
    assert _error(casadi, ref) <= 10 * RTOL


def test_reversals_in_several_blocks_equal_one_block(monkeypatch: pytest.MonkeyPatch) -> None:
    """The run's state carries over between C calls: blocks of 7 reversals give the table of one
    call, and both follow the exact map."""
    from prefriction.simulation.native import advance

    system = pf.Oscillator(pf.Dahl(1e4, 1.0, 1.5))
    ref = pf.exact_reversals(system, 1.0, 40)
    one = pf.simulate(system, 1.0, reversals=40, rtol=RTOL)
    monkeypatch.setattr(advance, "BLOCK", 7)
    blocks = pf.simulate(system, 1.0, reversals=40, rtol=RTOL)
    assert blocks.stats.calls == math.ceil(40 / 7) and one.stats.calls == 1
    np.testing.assert_array_equal(blocks.reversals.t, one.reversals.t)
    assert _error(blocks, ref) <= 10 * RTOL


def test_t_end_inside_a_branch_then_continued() -> None:
    """A run to t_end stops inside a branch at exactly t_end; its reversals are those of the exact
    map before t_end."""
    system = pf.Oscillator(pf.Dahl(1e4, 1.0, 1.0))
    ref = pf.exact_reversals(system, 1.0, 30)
    t_end = 0.5 * (ref.t[19] + ref.t[20])
    res = pf.simulate(system, 1.0, t_end=t_end, rtol=RTOL)
    assert res.status == 0 and len(res.reversals) == 20
    np.testing.assert_allclose(res.reversals.t, ref.t[:20], rtol=10 * RTOL)


def test_threads_run_the_driver_at_once_with_serial_results() -> None:
    """Four threads on one structure (ctypes releases the GIL) give the serial tables bit for bit."""
    systems = [pf.Oscillator(pf.Dahl(1e4 * (1 + k), 1.0, 1.0 + 0.5 * k)) for k in range(4)]
    serial = [pf.simulate(s, 1.0, reversals=200).reversals.t for s in systems]
    out: list = [None] * 4

    def work(k: int) -> None:
        out[k] = pf.simulate(systems[k], 1.0, reversals=200).reversals.t

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for a, b in zip(out, serial):
        np.testing.assert_array_equal(a, b)


def test_a_model_that_returns_nan_is_a_solver_error_naming_it() -> None:
    """A user model whose force turns NaN past half of Fc: a SolverError at the time the state
    gets there (F = 0.39 N, the last good step), saying the right-hand side became non-finite."""
    import casadi as ca

    class NaNDahl(pf.Dahl):
        def force(self, z, m, v, s, q):  # type: ignore[no-untyped-def]
            F = super().force(z, m, v, s, q)
            if isinstance(z[0], ca.SX):
                return F + ca.if_else(z[0] > 0.5, ca.SX(math.nan), 0.0)
            return F + (math.nan if z[0] > 0.5 else 0.0)

    with pytest.raises(pf.SolverError, match=r"failed after t = .* s .*right-hand side became non-finite"):
        pf.simulate(pf.Oscillator(NaNDahl(1e4, 1.0, 1.0)), 1.0, reversals=5)
