"""The three targets of ``prefriction bench`` as PASS/FAIL lines (``docs/bench.md#targets``)."""

from __future__ import annotations

import math
from typing import Sequence

from prefriction.cli.bench.cases import DEFAULT_METHOD
from prefriction.cli.bench.reference_rows import RowResult
from prefriction.cli.bench.stiff import StabilityRow
from prefriction.cli.bench.work_precision import Row


def _target1(sim: list[Row], stab: list[StabilityRow], ladder: list[float], checks: Sequence[RowResult]) -> str:
    """Target 1: every error within 10x its tolerance."""
    bad = [r for r in sim if not r.error <= 10.0 * r.tol]
    worst_stab = max((s.worst_ratio for s in stab), default=0.0)
    worst_rows = max((c.worst for c in checks), default=0.0)
    ok1 = not bad and all(s.worst_ratio <= 10.0 for s in stab) and all(c.passed for c in checks)
    worst_head = max((r.error / r.tol for r in sim), default=math.inf)
    return (f"target 1 (error within 10x tol, tol {max(ladder):g}..{min(ladder):g}, every case): "
            f"{'PASS' if ok1 else 'FAIL'}  (worst err/tol: headline {worst_head:.2f}, "
            f"stability cases {worst_stab:.2f}, rows against references {worst_rows:.2f})")


def _target2(rows: list[Row], sim: list[Row]) -> str:
    """Target 2: at error <= 1e-8, simulate at least 20x faster than the fastest scipy +events."""
    default = [r for r in sim if r.solver == f"simulate[{DEFAULT_METHOD}]" and r.error <= 1e-8]
    scipy_rows = [r for r in rows if r.solver.startswith("scipy") and "+events" in r.solver
                  and math.isfinite(r.seconds) and r.error <= 1e-8]
    if not (default and scipy_rows):
        return "target 2: not measured (no run reached max rel error <= 1e-8)"
    ours = min(default, key=lambda r: r.seconds)
    peer = min(scipy_rows, key=lambda r: r.seconds)
    ratio = peer.seconds / ours.seconds
    return (f"target 2 (at max rel error <= 1e-8, simulate[{DEFAULT_METHOD}] >= 20x faster than the fastest "
            f"scipy solve_ivp): {'PASS' if ratio >= 20 else 'FAIL'}  ratio {ratio:.1f}x "
            f"(simulate {ours.seconds * 1e3:.2f} ms at tol {ours.tol:g}, err {ours.error:.1e}; "
            f"{peer.solver} {peer.seconds * 1e3:.1f} ms at tol {peer.tol:g}, err {peer.error:.1e})")


def targets(rows: list[Row], stab: list[StabilityRow], t50: float, tlong: float, n_long: int,
            ladder: list[float], checks: Sequence[RowResult] = ()) -> list[str]:
    """The three target checks as printable lines.

    Parameters
    ----------
    rows : list of Row
        Headline rows (simulate and peers).
    stab : list of StabilityRow
        The stiff and extreme cases.
    t50, tlong : float
        Warm time per reversal at 50 and at ``n_long`` reversals [s] (:func:`linear_cost`).
    n_long : int
        Reversals of the long runs.
    ladder : list of float
        The tolerance ladder.
    checks : sequence of RowResult, optional
        The rows against independent references (part of target 1).

    Returns
    -------
    list of str
        Three lines starting with ``target 1``, ``target 2``, ``target 3``, each holding PASS or
        FAIL (target 2: ``not measured`` if no run reached 1e-8).
    """
    sim = [r for r in rows if r.solver.startswith("simulate")]
    ratio3 = tlong / t50
    return [
        _target1(sim, stab, ladder, checks),
        _target2(rows, sim),
        f"target 3 (time per reversal at {n_long} reversals <= 1.5x that at 50; interleaved rounds of "
        f"equal length, minimum per round): {'PASS' if ratio3 <= 1.5 else 'FAIL'}  {tlong * 1e6:.1f} us "
        f"vs {t50 * 1e6:.1f} us per reversal (ratio {ratio3:.2f})",
    ]
