"""The plain-C reference of prefriction bench: its reversals against exact_reversals, its bad
input, and the headline comparison's section and target line."""

from __future__ import annotations

import pytest

import prefriction as pf
from prefriction.cli.bench.c_reference import CComparison, c_available, c_comparison, c_section, c_target
from prefriction.cli.bench.cases import table_error
from prefriction.cli.bench.plain_c import c_reversals

pytestmark = pytest.mark.skipif(not c_available(), reason="no C compiler")


@pytest.mark.parametrize("gamma, sigma, v0, F0", [(1.0, 1e4, 1.0, 0.0), (2.5, 1e3, 0.3, 0.0), (1.0, 1e5, 0.0, 0.5)])
def test_c_reversals_match_the_exact_map(gamma: float, sigma: float, v0: float, F0: float) -> None:
    system = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=1.0, gamma=gamma), mass=2.0)
    ref = pf.exact_reversals(system, v0, 30, F0=F0)
    t, x, F, steps = c_reversals(system, v0, 30, 1e-8, F0)
    assert table_error(t, x, F, ref.t, ref.x, ref.F, 1.0 / sigma) <= 1e-8
    assert 20 * 30 <= steps <= 120 * 30  # about 55 steps per reversal at rtol 1e-8
    *_, steps6 = c_reversals(system, v0, 30, 1e-6, F0)
    assert steps6 < 0.6 * steps  # the tolerance acts: steps ~ tol^(-1/5), 100^(-1/5) = 0.4


def test_c_reversals_refuse_what_they_do_not_model() -> None:
    with pytest.raises(ValueError, match="gamma >= 1"):
        c_reversals(pf.Oscillator(pf.Dahl(1e4, 1.0, 0.5)), 1.0, 5)
    with pytest.raises(ValueError, match="gamma >= 1"):
        c_reversals(pf.Oscillator(pf.Dahl(1e4, 1.0, 1.0), u=0.1), 1.0, 5)
    with pytest.raises(ValueError, match="n must be >= 1"):
        c_reversals(pf.Oscillator(pf.Dahl(1e4, 1.0, 1.0)), 1.0, 0)


def test_headline_comparison_section_and_target() -> None:
    cmp = c_comparison(rounds=2)
    assert cmp.simulate_error <= 1e-8 and cmp.c_error <= 1e-8 and cmp.c_steps > 0 and cmp.calls > 0
    assert "simulate / C = " in c_section(cmp)
    fast = CComparison(2.9e-3, 1e-3, 5e-9, 5e-9, 2600, 55)
    slow = CComparison(3.1e-3, 1e-3, 5e-9, 5e-9, 2600, 55)
    inaccurate = CComparison(1e-3, 1e-3, 2e-8, 5e-9, 2600, 55)
    assert "PASS" in c_target(fast) and "FAIL" in c_target(slow) and "FAIL" in c_target(inaccurate)
