"""``prefriction bench``: error against run time of :func:`prefriction.simulate` and its peers.

One run measures, against :func:`prefriction.exact_reversals`:

- the work-precision of every ``simulate`` method over the tolerance ladder 1e-4 ... 1e-11, of
  scipy ``solve_ivp`` (RK45, DOP853, LSODA, Radau, BDF) with event restarts at ``v = 0``, of
  scipy without events on the ``|v|`` form ``F' = sigma (v - |v| F / Fc)`` (reversals located
  afterwards on the dense output) and of python-control ``input_output_response`` (``|v|`` form),
  on the headline case ``sigma / Fc = 1e4``, ``m = 1``, ``v0 = 1`` (SI units);
- the stiff and extreme cases (``sigma / Fc`` 1e-2 ... 1e10, mass 1e-6 ... 1e3, first-excursion
  energy ratio ``sigma m v0^2 / (2 Fc^2)`` 1e-20 ... 1e6, ``F0 = +-0.999999 Fc``, gamma in
  {0, 0.5, 1, 2, 5}) over the same ladder, plus one run of 1e4 reversals each.

Error = max relative error over the first 50 reversals of the times, the positions (relative to
``max(|x|, Fc / sigma)``) and the forces; a missing or extra reversal is an infinite error.
Run times are warm (compiled code loaded, minimum of repeats); the one-time JIT compile time is
reported separately. Peers integrate the same normalised equations
(``docs/mathematics.md#normalised-units``), with ``rtol = tol`` and ``atol = tol / 100``. The
error definition, the cases and the targets are described in ``docs/bench.md``.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from prefriction.analysis.dahl import next_amplitude
from prefriction.cli import bench_stability
from prefriction.models import Dahl, Oscillator
from prefriction.reversals import ReversalTable
from prefriction.simulation.simulate import METHODS, simulate
from prefriction.units import Scales

N_REV = 50
LADDER = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
QUICK_LADDER = [1e-6, 1e-9]
SCIPY_METHODS = ["RK45", "DOP853", "LSODA", "Radau", "BDF"]
DEFAULT_METHOD = "erk"


@dataclass(frozen=True)
class Case:
    """One benchmark case: an unforced Dahl oscillator and its initial state (SI)."""

    name: str
    sigma: float
    Fc: float
    mass: float
    v0: float
    F0: float = 0.0
    gamma: float = 1.0

    @property
    def system(self) -> Oscillator:
        """The oscillator of the case."""
        return Oscillator(Dahl(self.sigma, self.Fc, self.gamma), mass=self.mass)


HEADLINE = Case("headline sigma/Fc=1e4 m=1 v0=1", 1e4, 1.0, 1.0, 1.0)


def stability_cases() -> list[Case]:
    """The stiff and extreme cases of the issue (SI units)."""
    cases = [HEADLINE]
    for r in (1e-2, 1e10):
        cases.append(Case(f"sigma/Fc={r:g}", r, 1.0, 1.0, 1.0))
    for m in (1e-6, 1e3):
        cases.append(Case(f"mass={m:g} kg", 1e4, 1.0, m, 1.0))
    for ratio in (1e-20, 1e6):  # sigma m v0^2 / (2 Fc^2)
        cases.append(Case(f"energy ratio={ratio:g}", 1e4, 1.0, 1.0, math.sqrt(2.0 * ratio / 1e4)))
    for F0 in (0.999999, -0.999999):
        cases.append(Case(f"F0={F0:+g} Fc", 1e4, 1.0, 1.0, 1.0, F0))
    cases.append(Case("F0=+0.999999 Fc, v0=0", 1e4, 1.0, 1.0, 0.0, 0.999999))
    for g in (0.0, 0.5, 2.0, 5.0):
        cases.append(Case(f"gamma={g:g}", 1e4, 1.0, 1.0, 1.0, 0.0, g))
    return cases


def _exact(case: Case, n: int) -> ReversalTable:
    from prefriction.analysis.exact import exact_reversals

    return exact_reversals(case.system, case.v0, n, x0=0.0, F0=case.F0)


def reversal_error(case: Case, t: np.ndarray, x: np.ndarray, F: np.ndarray, ref: ReversalTable,
                   n: int = N_REV) -> float:
    """Max relative error of the first ``n`` reversal times, positions and forces (inf if missing)."""
    if len(t) < n or len(ref.t) < n:
        return math.inf
    xs = case.Fc / case.sigma
    et = np.abs(t[:n] - ref.t[:n]) / np.abs(ref.t[:n])
    ex = np.abs(x[:n] - ref.x[:n]) / np.maximum(np.abs(ref.x[:n]), xs)
    eF = np.abs(F[:n] - ref.F[:n]) / np.abs(ref.F[:n])
    err = float(max(et.max(), ex.max(), eF.max()))
    return err if math.isfinite(err) else math.inf


# --- peers, in normalised units ---------------------------------------------------------------


def _scipy_events(case: Case, tol: float, method: str, n: int = N_REV) -> tuple[np.ndarray, ...]:
    """solve_ivp with a terminal event at ``s v = 0`` (direction -1) and a restart on the new branch."""
    from scipy.integrate import solve_ivp

    sc = Scales.of(case.system)
    g = case.gamma
    y = np.array([0.0, case.v0 / sc.v, case.F0 / sc.F])
    s = 1.0 if y[1] > 0 else (-1.0 if y[1] < 0 else -math.copysign(1.0, y[2]))
    t0 = 0.0
    out = []

    def make_event(s: float) -> Callable:
        def event(t: float, z: np.ndarray) -> float:
            return s * z[1]

        event.terminal = True
        event.direction = -1.0  # after a restart at v = 0 the indicator starts at 0 and grows
        return event

    span = 64.0 + 4.0 * abs(y[1]) + 2.0 * abs(y[1]) ** 2
    while len(out) < n:
        rhs = lambda t, z, s=s: [z[1], -z[2], z[1] * max(1.0 - s * z[2], 0.0) ** g]  # noqa: E731
        sol = solve_ivp(rhs, (t0, t0 + span), y, method=method, rtol=tol, atol=tol * 1e-2,
                        events=make_event(s))
        if sol.status == 1:
            t0 = float(sol.t_events[0][0])
            y = np.array(sol.y_events[0][0])
            out.append((t0, y[0], y[2]))
            s = -s
        elif sol.status == 0:
            t0, y = float(sol.t[-1]), sol.y[:, -1]
        else:
            raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    R = np.array(out)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def _locate(t: np.ndarray, x: Callable, v: np.ndarray, F: Callable, vfun: Callable, n: int) -> np.ndarray:
    """Reversals (t, x, F) at the sign changes of ``v`` on a grid, refined by ``vfun`` if given."""
    from scipy.optimize import brentq

    idx = np.nonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)[0][:n]
    out = []
    for i in idx:
        if vfun is None:
            tr = t[i] - v[i] * (t[i + 1] - t[i]) / (v[i + 1] - v[i])
        else:
            tr = brentq(vfun, t[i], t[i + 1], xtol=1e-15, rtol=1e-15)
        out.append((tr, x(tr), F(tr)))
    return np.array(out).reshape(-1, 3)


def _abs_form_span(case: Case) -> float:
    """Normalised time span that holds the first 50 reversals (gamma = 1)."""
    sc = Scales.of(case.system)
    return 1.15 * N_REV * 3.6 + 4.0 * abs(case.v0 / sc.v)


def _scipy_noevents(case: Case, tol: float, method: str) -> tuple[np.ndarray, ...]:
    """solve_ivp without events on the |v| form; reversals from the dense output afterwards."""
    from scipy.integrate import solve_ivp

    sc = Scales.of(case.system)
    rhs = lambda t, z: [z[1], -z[2], z[1] - abs(z[1]) * z[2]]  # noqa: E731
    span = _abs_form_span(case)
    sol = solve_ivp(rhs, (0.0, span), [0.0, case.v0 / sc.v, case.F0 / sc.F], method=method,
                    rtol=tol, atol=tol * 1e-2, dense_output=True)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    R = _locate(sol.t, lambda tr: sol.sol(tr)[0], sol.y[1], lambda tr: sol.sol(tr)[2],
                lambda tr: sol.sol(tr)[1], N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def _control(case: Case, tol: float) -> tuple[np.ndarray, ...]:
    """python-control ``input_output_response`` of the |v| form (no events), reversals on its grid."""
    import control as ct

    sc = Scales.of(case.system)
    sys_ = ct.NonlinearIOSystem(
        lambda t, z, u, params: np.array([z[1], -z[2], z[1] - abs(z[1]) * z[2]]),
        lambda t, z, u, params: z, inputs=1, outputs=3, states=3, name="dahl",
    )
    span = _abs_form_span(case)
    T = np.linspace(0.0, span, int(span * 20) + 1)
    resp = ct.input_output_response(sys_, T, 0.0, X0=[0.0, case.v0 / sc.v, case.F0 / sc.F],
                                    solve_ivp_kwargs={"rtol": tol, "atol": tol * 1e-2})
    y = np.asarray(resp.outputs)
    R = _locate(resp.time, lambda tr: np.interp(tr, resp.time, y[0]), y[1],
                lambda tr: np.interp(tr, resp.time, y[2]), None, N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


# --- measurement ---------------------------------------------------------------------------------


@dataclass
class Row:
    """One measured point of the work-precision table."""

    case: str
    solver: str
    tol: float
    error: float
    seconds: float
    compile_seconds: float = 0.0
    note: str = ""


def _timed(fn: Callable[[], tuple], repeats: int) -> tuple[tuple, float]:
    """Result and minimum wall time of ``repeats`` calls (one call if it takes over 0.5 s)."""
    best, res = math.inf, None
    for k in range(repeats):
        t0 = time.perf_counter()
        res = fn()
        best = min(best, time.perf_counter() - t0)
        if best > 0.5:
            break
    return res, best


def _simulate_point(case: Case, tol: float, method: str, ref: ReversalTable, repeats: int,
                    n: int = N_REV, min_seconds: float = 0.3) -> Row:
    """Compile (timed separately), then time warm runs of simulate."""
    first = simulate(case.system, case.v0, F0=case.F0, reversals=n, rtol=tol, method=method)
    comp = first.stats.setup_time

    def run() -> tuple:
        r = simulate(case.system, case.v0, F0=case.F0, reversals=n, rtol=tol, method=method)
        return r.reversals.t, r.reversals.x, r.reversals.F, r.stats.wall_time

    # millisecond runs: the minimum over at least `repeats` runs and `min_seconds` of them (at most 500)
    best, spent, k = math.inf, 0.0, 0
    res = None
    while k < repeats or (spent < min_seconds and k < 500):
        res = run()
        best = min(best, res[3])
        spent += res[3]
        k += 1
    err = reversal_error(case, res[0], res[1], res[2], ref, min(n, N_REV))
    return Row(case.name, f"simulate[{method}]", tol, err, best, comp, first.stats.jit)


def headline(ladder: list[float], repeats: int, peers: bool, budget: float) -> list[Row]:
    """Work-precision rows of the headline case for simulate and (if ``peers``) every peer."""
    case = HEADLINE
    ref = _exact(case, N_REV)
    # simulate runs take milliseconds: more repeats for the same confidence in the minimum
    _progress(f"headline: simulate over {len(ladder)} tolerances")
    rows = [_simulate_point(case, tol, m, ref, 4 * repeats) for m in METHODS for tol in ladder]
    if not peers:
        return rows
    solvers: list[tuple[str, Callable[[float], tuple]]] = []
    for m in SCIPY_METHODS:
        solvers.append((f"scipy {m} +events", lambda tol, m=m: _scipy_events(case, tol, m)))
    for m in ("DOP853", "LSODA"):
        solvers.append((f"scipy {m} |v| form", lambda tol, m=m: _scipy_noevents(case, tol, m)))
    solvers.append(("python-control |v| form", lambda tol: _control(case, tol)))
    for name, fn in solvers:
        _progress(f"headline: {name}")
        for tol in ladder:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res, sec = _timed(lambda: fn(tol), repeats)
                err = reversal_error(case, res[0], res[1], res[2], ref)
                rows.append(Row(case.name, name, tol, err, sec))
            except Exception as exc:  # a peer failing is a measured outcome, not a bench failure
                rows.append(Row(case.name, name, tol, math.inf, math.nan, note=f"failed: {exc}"[:60]))
                sec = 0.0
            if sec > budget:  # tighter tolerances would only take longer
                rows.append(Row(case.name, name, math.nan, math.nan, math.nan,
                                note=f"tighter tolerances skipped (run took {sec:.1f} s > {budget:g} s)"))
                break
    return rows


@dataclass
class StabilityRow:
    """Result of one stiff or extreme case."""

    case: str
    worst_ratio: float  # max over the ladder of error / tol (50 reversals)
    worst_tol: float
    err_long_50: float
    err_long_all: float
    n_long: int
    tol_long: float
    seconds_long: float
    energy_drift: float
    passed: bool


def stability(ladder: list[float], n_long: int, tol_long: float,
              cases: Optional[list[Case]] = None) -> tuple[list[StabilityRow], list[Row]]:
    """Every stiff/extreme case (default :func:`stability_cases`) over the ladder (50 reversals)
    and one run of ``n_long`` reversals."""
    out, rows = [], []
    cases = stability_cases() if cases is None else cases
    for k, case in enumerate(cases, 1):
        _progress(f"stability [{k}/{len(cases)}]: {case.name}")
        ref = _exact(case, max(n_long, N_REV))
        worst, worst_tol = 0.0, ladder[0]
        for tol in ladder:
            row = _simulate_point(case, tol, DEFAULT_METHOD, ref, 1, min_seconds=0.0)  # errors only
            rows.append(row)
            if row.error / tol > worst:
                worst, worst_tol = row.error / tol, tol
        r = simulate(case.system, case.v0, F0=case.F0, reversals=n_long, rtol=tol_long)
        tab = r.reversals
        e50 = reversal_error(case, tab.t, tab.x, tab.F, ref, N_REV)
        eall = reversal_error(case, tab.t, tab.x, tab.F, ref, n_long)
        drift = abs(tab.E_p[-1] / ref.E_p[n_long - 1] - 1.0) if len(tab) == n_long else math.inf
        ok = worst <= 10.0 and e50 <= 10.0 * tol_long and eall <= 10.0 * tol_long * n_long / N_REV
        out.append(StabilityRow(case.name, worst, worst_tol, e50, eall, len(tab), tol_long,
                                r.stats.wall_time, drift, ok))
    return out, rows


def _progress(message: str) -> None:
    """One progress line on stderr (the tables go to stdout)."""
    print(f"  ... {message}", file=sys.stderr, flush=True)


def analytics_timing(repeats: int, n_amp: int = 1_000_000, n_rev: int = 10_000) -> list[str]:
    """Lines timing the exact analytics: :func:`prefriction.analysis.dahl.next_amplitude` on ``n_amp``
    amplitudes against ``numpy.exp`` on the same array, and :func:`exact_reversals` for ``n_rev``
    reversals of the headline case (minimum of ``repeats`` warm runs)."""
    a = np.logspace(-12, 0, n_amp)
    _, t_map = _timed(lambda: (next_amplitude(a),), repeats)
    _, t_exp = _timed(lambda: (np.exp(a),), repeats)
    _, t_ref = _timed(lambda: (_exact(HEADLINE, n_rev),), max(1, repeats // 2))
    return [
        f"next_amplitude on {n_amp:.0e} amplitudes in [1e-12, 1]: {t_map * 1e3:.1f} ms "
        f"= {t_map / t_exp:.0f} x numpy.exp on the same array ({t_exp * 1e3:.2f} ms)",
        f"exact_reversals, {n_rev} reversals of the headline case: {t_ref * 1e3:.0f} ms "
        f"({t_ref / n_rev * 1e6:.1f} us per reversal)",
    ]


def linear_cost(tol: float, n_long: int, repeats: int) -> tuple[float, float]:
    """Warm time per reversal of the headline case at 50 and at ``n_long`` reversals [s].

    Load on the machine must neither fake a failure nor a pass, so the two are measured in
    interleaved rounds of equal length: one round is ``n_long / 50`` runs of 50 reversals
    followed by one run of ``n_long`` reversals (the same number of reversals, so both see the
    same load), and for each the minimum over at least three rounds is kept.
    """
    case = HEADLINE

    def wall(n: int) -> float:
        return simulate(case.system, case.v0, reversals=n, rtol=tol).stats.wall_time

    wall(N_REV)
    wall(n_long)  # compiled code loaded, caches warm
    k = max(1, round(n_long / N_REV))
    t50 = tl = math.inf
    for _ in range(max(3, repeats)):
        t50 = min(t50, sum(wall(N_REV) for _ in range(k)) / (k * N_REV))
        tl = min(tl, wall(n_long) / n_long)
    return t50, tl


# --- report --------------------------------------------------------------------------------------


def format_rows(rows: list[Row]) -> str:
    """Readable work-precision table."""
    head = f"{'solver':<28} {'tol':>8} {'max rel error':>14} {'err/tol':>9} {'warm run [s]':>13} {'compile [s]':>12}  note"
    lines = [head, "-" * len(head)]
    for r in rows:
        if math.isnan(r.tol):
            lines.append(f"{r.solver:<28} {'':>8} {'':>14} {'':>9} {'':>13} {'':>12}  {r.note}")
            continue
        ratio = r.error / r.tol if math.isfinite(r.error) else math.inf
        comp = f"{r.compile_seconds:12.3f}" if r.compile_seconds else f"{'':>12}"
        lines.append(f"{r.solver:<28} {r.tol:8.0e} {r.error:14.3e} {ratio:9.2f} {r.seconds:13.5f} {comp}  {r.note}")
    return "\n".join(lines)


def format_stability(rows: list[StabilityRow]) -> str:
    """Readable stability table."""
    head = (f"{'case':<32} {'max err/tol':>11} {'at tol':>7} {'n':>6} {'err 1st 50':>11} "
            f"{'err all n':>11} {'E_p drift':>10} {'run [s]':>8} {'us/rev':>7} result")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.case:<32} {r.worst_ratio:11.2f} {r.worst_tol:7.0e} {r.n_long:>6} {r.err_long_50:11.2e} "
            f"{r.err_long_all:11.2e} {r.energy_drift:10.2e} {r.seconds_long:8.3f} "
            f"{1e6 * r.seconds_long / max(r.n_long, 1):7.1f} {'pass' if r.passed else 'FAIL'}"
        )
    return "\n".join(lines)


def _write_csv(path: Path, rows: list[Row]) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "solver", "tol", "max_rel_error", "warm_run_s", "compile_s", "note"])
        for r in rows:
            w.writerow([r.case, r.solver, r.tol, r.error, r.seconds, r.compile_seconds, r.note])


def _plot(path: Path, rows: list[Row]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    for solver in dict.fromkeys(r.solver for r in rows):
        pts = [(r.seconds, r.error) for r in sorted(rows, key=lambda r: -r.tol)
               if r.solver == solver and math.isfinite(r.error) and math.isfinite(r.seconds)]
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if "simulate" in solver else ".--",
                      label=solver, lw=2 if "simulate" in solver else 1)
    ax.set_xlabel("warm run time for 50 reversals [s]")
    ax.set_ylabel("max relative error of reversal t, x, F [-]")
    ax.set_title("Work-precision, Dahl oscillator, sigma/Fc = 1e4 1/m, m = 1 kg, v0 = 1 m/s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def targets(rows: list[Row], stab: list[StabilityRow], t50: float, tlong: float, n_long: int,
            ladder: list[float], checks: Sequence["bench_stability.RowResult"] = ()) -> list[str]:
    """The three target checks of the issue, as printable lines (``checks``: the rows against
    independent references, part of target 1)."""
    lines = []
    sim = [r for r in rows if r.solver.startswith("simulate")]
    bad = [r for r in sim if not r.error <= 10.0 * r.tol]
    worst_stab = max((s.worst_ratio for s in stab), default=0.0)
    worst_rows = max((c.worst for c in checks), default=0.0)
    ok1 = not bad and all(s.worst_ratio <= 10.0 for s in stab) and all(c.passed for c in checks)
    worst_head = max((r.error / r.tol for r in sim), default=math.inf)
    lines.append(
        f"target 1 (error within 10x tol, tol {max(ladder):g}..{min(ladder):g}, every case): "
        f"{'PASS' if ok1 else 'FAIL'}  (worst err/tol: headline {worst_head:.2f}, "
        f"stability cases {worst_stab:.2f}, rows against references {worst_rows:.2f})"
    )
    default = [r for r in sim if r.solver == f"simulate[{DEFAULT_METHOD}]" and r.error <= 1e-8]
    scipy_rows = [r for r in rows if r.solver.startswith("scipy") and "+events" in r.solver
                  and math.isfinite(r.seconds) and r.error <= 1e-8]
    if default and scipy_rows:
        ours = min(default, key=lambda r: r.seconds)
        peer = min(scipy_rows, key=lambda r: r.seconds)
        ratio = peer.seconds / ours.seconds
        lines.append(
            f"target 2 (at max rel error <= 1e-8, simulate[{DEFAULT_METHOD}] >= 20x faster than the fastest "
            f"scipy solve_ivp): {'PASS' if ratio >= 20 else 'FAIL'}  ratio {ratio:.1f}x "
            f"(simulate {ours.seconds * 1e3:.2f} ms at tol {ours.tol:g}, err {ours.error:.1e}; "
            f"{peer.solver} {peer.seconds * 1e3:.1f} ms at tol {peer.tol:g}, err {peer.error:.1e})"
        )
    else:
        lines.append("target 2: not measured (no run reached max rel error <= 1e-8)")
    ratio3 = tlong / t50
    lines.append(
        f"target 3 (time per reversal at {n_long} reversals <= 1.5x that at 50; interleaved rounds of "
        f"equal length, minimum per round): {'PASS' if ratio3 <= 1.5 else 'FAIL'}  {tlong * 1e6:.1f} us "
        f"vs {t50 * 1e6:.1f} us per reversal (ratio {ratio3:.2f})"
    )
    return lines


def _models_main(out: Path, quick: bool) -> int:
    """``--models``: the table, ``models.csv`` and the target lines; 0 if every target passes."""
    from prefriction.cli import bench_models as bm

    start = time.perf_counter()
    cases = bm.model_cases()
    rows = bm.run(cases[:1] if quick else cases, ladder=bm.LADDER[:2] if quick else bm.LADDER,
                  peers=("DOP853",) if quick else bm.PEERS, budget=0.05 if quick else 0.3)
    print("Friction models: error over the first reversals against the reference, warm run time\n")
    print(bm.table(rows))
    lines = bm.targets(rows)
    print()
    print("\n".join(lines))
    out.mkdir(parents=True, exist_ok=True)
    with (out / "models.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "solver", "tol", "max_rel_error", "warm_run_s"])
        w.writerows([r.case, r.solver, r.tol, r.error, r.seconds] for r in rows)
    print(f"\nwrote {out / 'models.csv'} ({time.perf_counter() - start:.0f} s)")
    return 0 if all("PASS" in line for line in lines) else 1


_DESCRIPTION = """\
Measure the accuracy of prefriction.simulate against its run time, next to scipy solve_ivp
and python-control on the same equations, on the headline case (sigma/Fc = 1e4, m = 1 kg,
v0 = 1 m/s) and on stiff and extreme cases; print the tables and the three targets.

The error of a run is the largest relative error of the reversal times, positions and forces
over the first 50 reversals against the exact reversal table. Run times are warm (compiled
code loaded; the minimum of repeated runs). Exit status 0 only if every target passes.
Definitions, cases and targets: docs/bench.md."""

_EPILOG = """\
output (in --out): bench.csv (every measured point), work_precision.png, stability.txt;
  with --models models.csv, with --sweep sweep.csv

examples:
  prefriction bench --quick          two tolerances, one repeat, 500 long reversals
  prefriction bench --stability      simulate only: stiff and extreme cases, no peers
  prefriction bench --repeats 9      more warm repeats per point
  prefriction bench --models         Maxwell-slip, LuGre and GMS against scipy
  prefriction bench --sweep          parameter sweeps in cold and warm processes"""

MAX_REPEATS = 1000


def _repeats(text: str) -> int:
    """``--repeats``: an integer in [1, MAX_REPEATS]."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 1 <= value <= MAX_REPEATS or str(value) != text.strip().lstrip("+"):
        raise argparse.ArgumentTypeError(f"must be an integer in [1, {MAX_REPEATS}], got {text!r}")
    return value


def main(argv: Optional[list[str]] = None) -> int:
    """Command line entry point of ``prefriction bench``; returns 0 if every target passes."""
    from prefriction.cli.bench_sweep import out_dir

    ap = argparse.ArgumentParser(prog="prefriction bench", description=_DESCRIPTION, epilog=_EPILOG,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="bench_out", type=out_dir, metavar="DIR",
                    help="output directory, created if missing (default: bench_out)")
    ap.add_argument("--quick", action="store_true",
                    help="small run: two tolerances, one repeat, 500 long reversals")
    ap.add_argument("--repeats", type=_repeats, default=None, metavar="N",
                    help=f"warm repeats per point, 1..{MAX_REPEATS}; the minimum time is kept "
                         "(default: 5, 1 with --quick)")
    what = ap.add_mutually_exclusive_group()
    what.add_argument("--stability", action="store_true",
                      help="simulate only: the stiff and extreme cases, no peers (target 2 not measured)")
    what.add_argument("--models", action="store_true",
                      help="instead: Maxwell-slip, LuGre and GMS, error against run time next to scipy "
                           "Radau, BDF, LSODA and DOP853 with restarts at every event")
    what.add_argument("--sweep", action="store_true",
                      help="instead: parameter sweeps, compiles and end-to-end time of cold and warm "
                           "processes against scipy DOP853")
    args = ap.parse_args(argv)
    if args.repeats is not None and (args.sweep or args.models):
        ap.error("--repeats applies to the headline and stability sections, not to --sweep or --models")
    if args.sweep:
        from prefriction.cli.bench_sweep import main as sweep_main

        return sweep_main(["--out", str(args.out)] + (["--quick"] if args.quick else []))
    if args.models:
        return _models_main(args.out, args.quick)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    ladder = QUICK_LADDER if args.quick else LADDER
    repeats = args.repeats or (1 if args.quick else 5)
    n_long = 500 if args.quick else 10_000
    budget = 0.5 if args.quick else 4.0
    t_start = time.perf_counter()

    rows = headline(ladder, repeats, peers=not args.stability, budget=budget)
    print(f"Headline case: {HEADLINE.name} (error over the first {N_REV} reversals vs exact_reversals)\n")
    print(format_rows(rows))
    stab, stab_rows = stability(ladder, n_long, 1e-8)
    print(f"\nStiff and extreme cases: tolerance ladder {ladder[0]:g}..{ladder[-1]:g} over {N_REV} reversals, "
          f"then {n_long} reversals at rtol 1e-8 in one run.\npass: max err/tol <= 10 over the ladder, "
          f"first-50 error <= 10 rtol, all-{n_long} error <= 10 rtol n/{N_REV} (global error grows "
          f"linearly with the number of cycles)\n")
    print(format_stability(stab))
    checks = bench_stability.run(args.quick)
    print(f"\nRows against independent references (scipy DOP853 rtol {bench_stability.REF_RTOL:g} with restarts "
          f"at every reversal and saturation; energy conservation for gamma = 0):\nerr/rtol per tolerance, "
          f"pass within {bench_stability.LIMIT:g}x rtol; a wrong reversal count is an infinite error\n")
    print(bench_stability.format_rows(checks))
    t50, tlong = linear_cost(1e-8, n_long, repeats)
    print("\nExact analytics (the reference itself):")
    for line in analytics_timing(repeats, n_amp=100_000 if args.quick else 1_000_000):
        print("  " + line)
    comp = sum(r.compile_seconds for r in rows + stab_rows if r.note == "compiled")
    print(f"\nOne-time JIT compile (gcc, cached on disk): {comp:.1f} s in this run "
          f"(0 when every integrator was already in the cache)")
    print()
    lines = targets(rows, stab, t50, tlong, n_long, ladder, checks)
    for line in lines:
        print(line)
    _write_csv(out / "bench.csv", rows + stab_rows)
    with (out / "stability.txt").open("w") as fh:
        fh.write(format_stability(stab) + "\n\n" + bench_stability.format_rows(checks) + "\n")
    _plot(out / "work_precision.png", [r for r in rows if r.case == HEADLINE.name])
    print(f"\nwrote {out / 'bench.csv'}, {out / 'work_precision.png'}, {out / 'stability.txt'} "
          f"({time.perf_counter() - t_start:.0f} s)")
    return 0 if all("PASS" in line for line in lines if line.startswith("target")) else 1


if __name__ == "__main__":
    sys.exit(main())
