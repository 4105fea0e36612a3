"""``prefriction bench --elements``: compile time and cost per reversal against the element count.

For Maxwell-slip and GMS with ``N`` elements (3, 10, 30, 100; ``--quick``: 3 and 10) it
measures, in this process: the time to build and compile the structure's native driver
(``docs/simulator.md#native``) into an empty compiled-code cache (a temporary ``$PREFRICTION_CACHE``), and the warm time per reversal
of an unforced run of 50 reversals (``rtol = 1e-8``, the least of 3 interleaved rounds). The
elements: stiffnesses ``k_i`` spread over [1, 2] x 1e4 / N N/m and slip forces over [1, 3] / N
(Maxwell-slip; GMS: the fractions ``alpha_i`` the same, ``Fc = 1`` N, ``Fs = 1.5`` N,
``vs = 1e-2`` m/s, ``C = 2e3 x 3 / N`` N/s), ``m = 1`` kg, ``v0 = 0.5`` m/s
(``docs/bench.md#elements``). GMS's ``C`` shrinks with ``N`` so that each element's slip
relaxation rate ``C / (alpha_i S)`` is the same at every ``N``: with ``C`` fixed and
``alpha_i ~ 1 / N`` the slip law stiffens in proportion to ``N`` and an explicit integrator needs
proportionally more steps (20 reversals: 2,965 steps at 3 elements, 18,652 at 30; with
``C ~ 1 / N``: 2,965 and 3,640), which is the model's stiffness, not the plant's cost.

Target (both models): compile at 30 elements <= 2 s, and cost per reversal at 30 elements
<= 1.5 x (30 / 3) times that at 3 elements (linear in ``N`` within 1.5x).
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from dataclasses import dataclass

import numpy as np

from prefriction.cli.bench.timing import progress
from prefriction.models import GMS, MaxwellSlip, Oscillator

__all__ = ["ElementRow", "SIZES", "element_rows", "element_system", "element_table", "element_targets"]

SIZES, QUICK_SIZES = (3, 10, 30, 100), (3, 10)
COMPILE_TARGET, LINEAR_TARGET = 2.0, 1.5  # s at 30 elements; per-reversal cost over linear from 3
N_REV = 50


@dataclass
class ElementRow:
    """One model and element count: compile time [s] and warm time per reversal [s]."""

    model: str
    n: int
    compile_s: float
    per_reversal_s: float


def element_system(model: str, n: int) -> Oscillator:
    """The oscillator of ``model`` (``"MaxwellSlip"`` or ``"GMS"``) with ``n`` elements.

    Parameters
    ----------
    model : str
        ``"MaxwellSlip"`` or ``"GMS"``.
    n : int
        Number of elements, 1 to 100.

    Returns
    -------
    Oscillator
        Unforced, ``m = 1`` kg.
    """
    k = np.linspace(1.0, 2.0, n) * 1e4 / n
    w = np.linspace(1.0, 3.0, n)
    w = w / w.sum()
    if model == "MaxwellSlip":
        return Oscillator(MaxwellSlip(stiffness=k, slip_force=w), mass=1.0)
    return Oscillator(GMS(k, w, Fc=1.0, Fs=1.5, vs=1e-2, C=2e3 * 3.0 / n), mass=1.0)


def element_rows(sizes: tuple[int, ...], models: tuple[str, ...] = ("MaxwellSlip", "GMS")) -> list[ElementRow]:
    """Compile (into an empty cache) and time every model and size.

    Parameters
    ----------
    sizes : tuple of int
        Element counts.
    models : tuple of str, optional
        ``"MaxwellSlip"`` and/or ``"GMS"``.

    Returns
    -------
    list of ElementRow
        One row per model and size, in that order.
    """
    from prefriction.simulation.simulate import simulate

    systems = {(m, n): element_system(m, n) for m in models for n in sizes}
    compile_s = {}
    saved = os.environ.get("PREFRICTION_CACHE")
    with tempfile.TemporaryDirectory(prefix="prefriction-bench-elements-") as tmp:
        os.environ["PREFRICTION_CACHE"] = tmp
        try:
            for key, system in systems.items():
                progress(f"elements: {key[0]} N={key[1]}: build and compile")
                compile_s[key] = simulate(system, 0.5, reversals=2).stats.setup_time
        finally:
            if saved is None:
                del os.environ["PREFRICTION_CACHE"]
            else:
                os.environ["PREFRICTION_CACHE"] = saved
    best = {key: math.inf for key in systems}
    for _ in range(3):
        for key, system in systems.items():
            start = time.perf_counter()
            simulate(system, 0.5, reversals=N_REV)
            best[key] = min(best[key], time.perf_counter() - start)
    return [ElementRow(m, n, compile_s[(m, n)], best[(m, n)] / N_REV) for (m, n) in systems]


def element_table(rows: list[ElementRow]) -> str:
    """The table of :func:`element_rows`, with the cost per reversal over the linear growth from
    the smallest count."""
    lines = [f"Elements: plant built and compiled into an empty cache, and warm cost per reversal ({N_REV} "
             f"reversals, rtol 1e-8, least of 3 rounds)",
             f"{'model':<12} {'N':>4} {'compile s':>10} {'us/reversal':>12} {'/ linear':>9}"]
    for r in rows:
        base = min((b for b in rows if b.model == r.model), key=lambda b: b.n)
        linear = base.per_reversal_s * r.n / base.n
        lines.append(f"{r.model:<12} {r.n:>4} {r.compile_s:>10.2f} {r.per_reversal_s * 1e6:>12.1f} "
                     f"{r.per_reversal_s / linear:>9.2f}")
    return "\n".join(lines)


def element_targets(rows: list[ElementRow], quick: bool) -> list[str]:
    """The target line: at 30 elements, compile <= 2 s and cost per reversal within 1.5x of
    linear growth from 3 elements (not checked with ``--quick``, which stops at 10)."""
    parts, ok = [], True
    for model in dict.fromkeys(r.model for r in rows):
        by_n = {r.n: r for r in rows if r.model == model}
        if 3 not in by_n or 30 not in by_n:
            parts.append(f"{model}: 30 elements not measured")
            continue
        r3, r30 = by_n[3], by_n[30]
        growth = r30.per_reversal_s / (r3.per_reversal_s * 10.0)
        ok &= r30.compile_s <= COMPILE_TARGET and growth <= LINEAR_TARGET
        parts.append(f"{model}: compile {r30.compile_s:.2f} s, cost {growth:.2f}x linear")
    verdict = "PASS" if ok or quick else "FAIL"
    return [f"target elements (30 elements: compile <= {COMPILE_TARGET:g} s, cost per reversal <= "
            f"{LINEAR_TARGET:g}x linear from 3): {verdict}  ({'; '.join(parts)})"]


def main(quick: bool) -> int:
    """``prefriction bench --elements``: print the table and the target line; 0 if it passes."""
    rows = element_rows(QUICK_SIZES if quick else SIZES)
    print(element_table(rows))
    print()
    lines = element_targets(rows, quick)
    print("\n".join(lines))
    return 0 if all("PASS" in line for line in lines) else 1
