"""``prefriction bench --models``: error against run time for every friction model beside Dahl.

For each model case (an unforced oscillator, normalised initial speed ``v0~``, ``n`` reversals)
it measures, in one run, the maximum relative error of the reversal times, positions and forces
against the model's reference and the warm run time, for :func:`prefriction.simulate` over the
tolerances 1e-4..1e-10 and for scipy ``solve_ivp`` (Radau, BDF, LSODA, DOP853) restarted at every
reversal and every model event (:func:`prefriction.testing.reference_reversals`, the same
equations evaluated in Python). The reference is the closed form where there is one
(:class:`prefriction.MaxwellSlip`: the event-by-event solution) and otherwise scipy Radau at
rtol 1e-12 with restarts.

Targets, printed as PASS/FAIL: every model within 10x rtol over the ladder; at the loosest
tolerance where ``simulate`` reaches error <= 1e-7, at least 10x faster than the fastest scipy
method that reaches the same error in the same run (``docs/bench.md#models``).
"""

from __future__ import annotations

import csv
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from prefriction.cli.bench.timing import min_time, progress
from prefriction.models import FrictionModel, MaxwellSlip, Oscillator
from prefriction.simulation.simulate import simulate
from prefriction.testing import reference_reversals
from prefriction.units import Scales

__all__ = ["LADDER", "ModelCase", "ModelRow", "main", "model_cases", "run", "table", "targets"]

LADDER = (1e-4, 1e-6, 1e-8, 1e-10)
PEERS = ("Radau", "BDF", "LSODA", "DOP853")
TARGET_ERROR = 1e-7


@dataclass(frozen=True)
class ModelCase:
    """One model case: the model, its normalised initial speed and the number of reversals."""

    name: str
    model: FrictionModel
    v0: float
    n: int
    exact: Optional[Callable[[Oscillator, float, int], np.ndarray]] = None
    """Closed-form reversal rows ``(t~, x~, F~)``; None: scipy Radau at rtol 1e-12."""


@dataclass(frozen=True)
class ModelRow:
    """One measured point: case, solver, tolerance, max relative error, warm run time [s]."""

    case: str
    solver: str
    tol: float
    error: float
    seconds: float


def _maxwell_exact(system: Oscillator, v0: float, n: int) -> np.ndarray:
    from prefriction.analysis.maxwell_slip_exact import maxwell_slip_reversals

    sc = Scales.of(system)
    tab = maxwell_slip_reversals(system, v0 * sc.v, n)
    return np.column_stack([tab.t / sc.t, tab.x / sc.x, tab.F / sc.F])


def model_cases() -> list[ModelCase]:
    """The benchmarked cases (mass 1 kg): for each model a typical case first, then stiff and
    extreme ones. Maxwell-slip: 3 elements; 8 elements with stiffnesses over 7 decades; gross
    sliding at 20x the speed. LuGre (1995 Table I); bristles 1000x stiffer; a Stribeck velocity
    100x smaller. GMS: 3 elements; stiff elements (1e7 N/m) with a sharp Stribeck curve."""
    from prefriction.models import GMS, LuGre

    ms3 = MaxwellSlip([3e4, 3e4, 4e4], [0.15, 0.35, 0.5])
    return [
        ModelCase("MaxwellSlip N=3", ms3, 1.5, 20, _maxwell_exact),
        ModelCase("MaxwellSlip N=8, k 1e2..1e9", MaxwellSlip(np.geomspace(1e2, 1e9, 8), np.full(8, 0.125)),
                  1.2, 20, _maxwell_exact),
        ModelCase("MaxwellSlip N=3, v0~=30", ms3, 30.0, 20, _maxwell_exact),
        ModelCase("LuGre (1995 Table I)", LuGre(1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3), 1.0, 6),
        ModelCase("LuGre sigma0=1e8", LuGre(1e8, math.sqrt(1e8), 0.4, 1.0, 1.5, 1e-3), 1.0, 6),
        ModelCase("LuGre vs=1e-5", LuGre(1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-5), 1.0, 6),
        ModelCase("GMS N=3", GMS([3e4, 2e4, 5e4], [0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-2, C=2e3), 1.5, 12),
        ModelCase("GMS N=3 stiff, vs=1e-4", GMS([1e7, 2e7, 5e7], [0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-4, C=2e3),
                  1.5, 12),
    ]


def _error(rows: np.ndarray, ref: np.ndarray) -> float:
    """Max relative error of reversal times, positions (relative to max(|x|, 1)) and forces (inf if
    reversals are missing or a value is not finite)."""
    if len(rows) < len(ref):
        return math.inf
    rows = rows[: len(ref)]
    et = np.abs(rows[:, 0] - ref[:, 0]) / np.abs(ref[:, 0])
    ex = np.abs(rows[:, 1] - ref[:, 1]) / np.maximum(np.abs(ref[:, 1]), 1.0)
    eF = np.abs(rows[:, 2] - ref[:, 2]) / np.maximum(np.abs(ref[:, 2]), 1e-300)
    err = float(np.max([et.max(), ex.max(), eF.max()]))  # np.max: a NaN stays NaN (max() would drop it)
    return err if math.isfinite(err) else math.inf


def run(cases: list[ModelCase], ladder: tuple[float, ...] = LADDER, peers: tuple[str, ...] = PEERS,
        budget: float = 0.3) -> list[ModelRow]:
    """Measure every case: simulate and the scipy peers over ``ladder``; progress on stderr."""
    rows: list[ModelRow] = []
    for k, case in enumerate(cases, 1):
        progress(f"models [{k}/{len(cases)}]: {case.name}")
        system = Oscillator(case.model, mass=1.0)
        sc = Scales.of(system)
        if case.exact is not None:
            ref = case.exact(system, case.v0, case.n)
        else:
            ref = reference_reversals(case.model, case.v0, case.n, rtol=1e-12, method="Radau")[0]
        simulate(system, case.v0 * sc.v, reversals=case.n, rtol=1e-6)  # compile outside the timing

        for tol in ladder:
            def sim(tol: float = tol) -> np.ndarray:
                tab = simulate(system, case.v0 * sc.v, reversals=case.n, rtol=tol).reversals
                return np.column_stack([tab.t / sc.t, tab.x / sc.x, tab.F / sc.F])

            got, sec = min_time(sim, most=math.inf, fill=budget, stop_best=0.05)
            rows.append(ModelRow(case.name, "simulate[native]", tol, _error(got, ref), sec))
        for method in peers:
            for tol in ladder:
                def peer(tol: float = tol, method: str = method) -> np.ndarray:
                    return reference_reversals(case.model, case.v0, case.n, rtol=tol, method=method)[0]

                try:
                    got, sec = min_time(peer)
                    err = _error(got, ref)
                except (RuntimeError, ValueError) as exc:  # a peer that fails is reported, not fatal
                    progress(f"{method} at {tol:g} failed: {exc}")
                    sec, err = math.nan, math.inf
                rows.append(ModelRow(case.name, f"scipy {method} +events", tol, err, sec))
                if sec > 5.0:  # tighter tolerances would only take longer
                    break
    return rows


def table(rows: list[ModelRow]) -> str:
    """The rows as a text table."""
    head = f"{'case':<30} {'solver':<20} {'tol':>7} {'max rel error':>14} {'err/tol':>9} {'warm run [s]':>13}"
    out = [head, "-" * len(head)]
    for r in rows:
        out.append(f"{r.case:<30} {r.solver:<20} {r.tol:7.0e} {r.error:14.3e} {r.error / r.tol:9.2f} {r.seconds:13.5f}")
    return "\n".join(out)


def targets(rows: list[ModelRow]) -> list[str]:
    """PASS/FAIL lines: error within 10x rtol for every model; >= 10x faster than scipy at matched error."""
    lines = []
    for case in dict.fromkeys(r.case for r in rows):
        mine = [r for r in rows if r.case == case and r.solver.startswith("simulate")]
        worst = max(r.error / r.tol for r in mine)
        lines.append(f"target models/accuracy ({case}: error within 10x rtol, rtol "
                     f"{mine[0].tol:g}..{mine[-1].tol:g}): {'PASS' if worst <= 10 else 'FAIL'}  "
                     f"(worst err/tol {worst:.2f})")
        ok = [r for r in mine if r.error <= TARGET_ERROR]
        if not ok:
            lines.append(f"target models/speed ({case}): FAIL  (simulate never reached {TARGET_ERROR:g})")
            continue
        best = min(ok, key=lambda r: r.seconds)
        peers = [r for r in rows if r.case == case and not r.solver.startswith("simulate")
                 and r.error <= max(best.error, TARGET_ERROR)]
        if not peers:
            lines.append(f"target models/speed ({case}: >= 10x the fastest scipy at error <= "
                         f"{max(best.error, TARGET_ERROR):.1e}): PASS  (no scipy method reached it)")
            continue
        peer = min(peers, key=lambda r: r.seconds)
        ratio = peer.seconds / best.seconds
        lines.append(f"target models/speed ({case}: >= 10x the fastest scipy at the same error): "
                     f"{'PASS' if ratio >= 10 else 'FAIL'}  ratio {ratio:.1f}x (simulate {best.seconds * 1e3:.2f} ms "
                     f"at tol {best.tol:g}, err {best.error:.1e}; {peer.solver} {peer.seconds * 1e3:.1f} ms at "
                     f"tol {peer.tol:g}, err {peer.error:.1e})")
    return lines


def main(out: Path, quick: bool) -> int:
    """``prefriction bench --models``: print the table and the target lines, write ``models.csv``.

    Parameters
    ----------
    out : pathlib.Path
        Output directory, created if missing.
    quick : bool
        The first case only, two tolerances, DOP853 only, a 0.05 s timing budget.

    Returns
    -------
    int
        0 if every target passes, else 1.
    """
    start = time.perf_counter()
    cases = model_cases()
    rows = run(cases[:1] if quick else cases, ladder=LADDER[:2] if quick else LADDER,
               peers=("DOP853",) if quick else PEERS, budget=0.05 if quick else 0.3)
    print("Friction models: error over the first reversals against the reference, warm run time\n")
    print(table(rows))
    lines = targets(rows)
    print()
    print("\n".join(lines))
    out.mkdir(parents=True, exist_ok=True)
    with (out / "models.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "solver", "tol", "max_rel_error", "warm_run_s"])
        w.writerows([r.case, r.solver, r.tol, r.error, r.seconds] for r in rows)
    print(f"\nwrote {out / 'models.csv'} ({time.perf_counter() - start:.0f} s)")
    return 0 if all("PASS" in line for line in lines) else 1
