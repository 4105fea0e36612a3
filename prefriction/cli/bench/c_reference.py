"""The headline case against the plain-C reference (``docs/bench.md#plain-c``).

:func:`c_comparison` times :func:`prefriction.simulate` (end to end, warm) and the plain-C
reference of :mod:`prefriction.cli.bench.plain_c` (the same Runge-Kutta 5(4), states and
scaling, in C; called through ctypes) on the headline case, 50 reversals at ``rtol = 1e-8``, in
interleaved rounds, keeping the minimum of each, and reports both errors against
:func:`prefriction.exact_reversals` and the ratio (target 4: at most 3).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from prefriction.cli.bench.cases import HEADLINE, N_REV, Case, reversal_error
from prefriction.cli.bench.plain_c import c_available, c_reversals

C_TARGET = 3.0  # simulate / C on the headline case
RTOL = 1e-8


@dataclass
class CComparison:
    """Warm times [s] (minima over the rounds), errors and steps of simulate and the C reference."""

    simulate_s: float
    c_s: float
    simulate_error: float
    c_error: float
    c_steps: int
    calls: int

    @property
    def ratio(self) -> float:
        """simulate over C."""
        return self.simulate_s / self.c_s


def c_comparison(rounds: int = 20, case: Case = HEADLINE) -> CComparison:
    """Interleaved warm rounds of simulate and the C reference on ``case`` (50 reversals, rtol 1e-8).

    Parameters
    ----------
    rounds : int, optional
        Rounds; each times one simulate run and one C run (default 20).
    case : Case, optional
        An unforced Dahl case with gamma >= 1 (default the headline case).

    Returns
    -------
    CComparison
        The minima, the errors against the exact reversals and the steps of the C run.
    """
    import prefriction as pf

    ref = pf.exact_reversals(case.system, case.v0, N_REV, F0=case.F0)
    first = pf.simulate(case.system, case.v0, F0=case.F0, reversals=N_REV, rtol=RTOL)  # compile or load
    t, x, F, steps = c_reversals(case.system, case.v0, N_REV, RTOL, case.F0)
    best_sim = best_c = math.inf
    for _ in range(rounds):
        start = time.perf_counter()
        res = pf.simulate(case.system, case.v0, F0=case.F0, reversals=N_REV, rtol=RTOL)
        best_sim = min(best_sim, time.perf_counter() - start)
        start = time.perf_counter()
        c_reversals(case.system, case.v0, N_REV, RTOL, case.F0)
        best_c = min(best_c, time.perf_counter() - start)
    tab = res.reversals
    return CComparison(best_sim, best_c, reversal_error(case, tab.t, tab.x, tab.F, ref),
                       reversal_error(case, t, x, F, ref), steps, first.stats.calls)


def c_section(cmp: CComparison) -> str:
    """The lines printed by ``prefriction bench`` for :func:`c_comparison`."""
    return (f"\nPlain-C reference (headline, {N_REV} reversals, rtol {RTOL:g}; same Runge-Kutta 5(4) tableau, "
            f"states, scaling and step control as simulate, Newton on the dense output; gcc -O2, ctypes):\n"
            f"  simulate {cmp.simulate_s * 1e3:.3f} ms end to end ({cmp.calls} compiled call{'' if cmp.calls == 1 else 's'}), error "
            f"{cmp.simulate_error:.2e}\n"
            f"  plain C  {cmp.c_s * 1e3:.3f} ms ({cmp.c_steps} steps, {cmp.c_s / cmp.c_steps * 1e9:.0f} ns per step), "
            f"error {cmp.c_error:.2e}\n"
            f"  simulate / C = {cmp.ratio:.2f}")


def c_target(cmp: CComparison) -> str:
    """Target 4: simulate at most :data:`C_TARGET` times the plain-C reference on the headline case."""
    ok = cmp.ratio <= C_TARGET and cmp.simulate_error <= RTOL
    return (f"target 4 (headline, {N_REV} reversals, error <= {RTOL:g}: simulate <= {C_TARGET:g}x the plain-C "
            f"reference): {'PASS' if ok else 'FAIL'}  ratio {cmp.ratio:.2f} (simulate {cmp.simulate_s * 1e3:.3f} ms, "
            f"C {cmp.c_s * 1e3:.3f} ms)")


__all__ = ["C_TARGET", "CComparison", "c_available", "c_comparison", "c_section", "c_target"]
