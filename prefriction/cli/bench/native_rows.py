"""``prefriction bench --native``: every run kind of the native driver against its own references.

Each row times :func:`prefriction.simulate` (end to end, warm) and a reference written from the
equations, in interleaved rounds, process CPU time, the least of each (robust to a loaded
machine), and prints the ratio (``docs/bench.md#native``):

- the unforced headline (Dahl, 50 reversals) at ``rtol`` 1e-8 and 1e-4 against the plain-C
  reference (:mod:`prefriction.cli.bench.plain_c`: the same Runge-Kutta 5(4), states and scaling);
- forced Dahl and LuGre under a sine force, Dahl under a :class:`~prefriction.signals.Samples`
  force at 1 kHz, and forced Dahl with 1,000 dense samples against the numba references of
  :mod:`prefriction.cli.bench.numba_refs` (when numba is installed), **at matched error**: the
  reference runs at the loosest tolerance of a ladder whose reversal error is no larger than
  that of ``simulate``, both errors measured against the reference at ``rtol = 1e-13``.

Targets: unforced headline <= 2x, forced sine rows <= 2x, Samples and dense rows
<= 3x, loose-tolerance headline <= 3x, 10 kHz PID loops (``controllers.simulate_loop`` and a
sampled ``simulate(..., feedback=)``) <= 3x, the exported C loop (``prefriction.export``, the same
native driver) <= 2x the numba loop.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

__all__ = ["NativeRow", "main", "run"]

_LADDER = (1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 1e-12)
SIGMA, FC, MASS, AMP, FREQ = 1e4, 1.0, 1.0, 2.0, 5.0  # N/m, N, kg, N, Hz
LUGRE = (1e5, 300.0, 0.4, 1.0, 1.5, 1e-3)


@dataclass
class NativeRow:
    """One row: the two minima [s], the errors and the target."""

    name: str
    reference: str
    sim_s: float
    ref_s: float
    sim_error: float
    ref_error: float
    target: float
    same_rtol_s: float = math.nan  # the reference at simulate's rtol (less accurate), for comparison
    erk_s: float = math.nan  # the CasADi path (method="erk", the CasADi block Function), same run

    @property
    def ratio(self) -> float:
        """simulate over the reference."""
        return self.sim_s / self.ref_s

    def line(self) -> str:
        ok = "PASS" if self.ratio <= self.target else "FAIL"
        text = (f"  {self.name:<44s} {_t(self.sim_s)}  {self.reference:<12s} {_t(self.ref_s)}  ratio {self.ratio:5.2f}  "
                f"(target <= {self.target:g}x: {ok})  errors {self.sim_error:.1e} / {self.ref_error:.1e}")
        if not math.isnan(self.erk_s):
            text += f"; CasADi path {_t(self.erk_s)} (ratio {self.erk_s / self.ref_s:.1f})"
        if not math.isnan(self.same_rtol_s):
            text += f"; reference at rtol 1e-8 {_t(self.same_rtol_s)}"
        return text


def _t(seconds: float) -> str:
    """A time in ms, us or ns."""
    if seconds >= 1e-3:
        return f"{seconds * 1e3:8.3f} ms"
    return f"{seconds * 1e6:8.3f} us" if seconds >= 1e-6 else f"{seconds * 1e9:8.1f} ns"


def _interleaved(a: Callable[[], object], b: Callable[[], object], rounds: int) -> tuple[float, float]:
    """Least process CPU time of ``a`` and of ``b`` over interleaved rounds."""
    best_a = best_b = math.inf
    for _ in range(rounds):
        t0 = time.process_time()
        a()
        t1 = time.process_time()
        b()
        t2 = time.process_time()
        best_a, best_b = min(best_a, t1 - t0), min(best_b, t2 - t1)
    return best_a, best_b


def _error(t: np.ndarray, x: np.ndarray, F: np.ndarray, ref: np.ndarray) -> float:
    """Largest error of reversal times (relative to the run's length), positions (to the largest
    |x|) and forces (to Fc) against the reference rows ``ref``; inf if the counts differ."""
    if len(t) != ref.shape[1]:
        return math.inf
    if not len(t):
        return 0.0
    return max(float(np.max(np.abs(t - ref[0]))), float(np.max(np.abs(x - ref[1]))) / max(float(np.max(np.abs(ref[1]))), 1e-300),
               float(np.max(np.abs(F - ref[2]))) / FC)


def _forced_rows(rounds: int) -> list[NativeRow]:
    import prefriction as pf
    from prefriction.cli.bench import numba_refs as nr
    from prefriction.signals import Samples, Sine

    ts = np.linspace(0.0, 1.0, 1001)
    us = AMP * np.sin(2 * np.pi * FREQ * ts)
    td = np.linspace(0.0, 1.0, 1000)
    dahl = pf.Dahl(SIGMA, FC)
    lugre = pf.LuGre(*LUGRE)
    w = 2 * np.pi * FREQ
    cases = [
        ("forced Dahl, sine force", pf.Oscillator(dahl, MASS, Sine(AMP, FREQ)), None, nr.DAHL, nr.SINE, 2.0),
        ("forced LuGre, sine force", pf.Oscillator(lugre, MASS, Sine(AMP, FREQ)), None, nr.LUGRE, nr.SINE, 2.0),
        ("Dahl, Samples force at 1 kHz, 1 s", pf.Oscillator(dahl, MASS, Samples(ts, us)), None, nr.DAHL, nr.SAMPLES, 3.0),
        ("forced Dahl, 1,000 dense samples", pf.Oscillator(dahl, MASS, Sine(AMP, FREQ)), td, nr.DAHL, nr.SINE, 3.0),
    ]
    rows = []
    for name, system, dense, model, kind, target in cases:
        mp = np.array([SIGMA, FC, MASS]) if model == nr.DAHL else np.array([*LUGRE[:3], *LUGRE[3:], MASS])
        scale = np.array([FC / SIGMA, FC / math.sqrt(SIGMA * MASS), FC if model == nr.DAHL else FC / LUGRE[0]])
        up = np.array([AMP, w])
        tds = np.zeros(0) if dense is None else dense

        def reference(rtol: float, tds: np.ndarray = tds, mp: np.ndarray = mp, model: int = model,
                      kind: int = kind, scale: np.ndarray = scale, up: np.ndarray = up) -> tuple:
            return nr.forced_run(model, mp, kind, up, ts, us, np.zeros(3), 1.0, 1.0, rtol, rtol * scale, tds)

        kw = {} if dense is None else {"dense": dense}

        def sim(method: str = "native", system: Any = system, kw: dict = kw) -> Any:
            return pf.simulate(system, 0.0, t_end=1.0, rtol=1e-8, method=method, **kw)

        rows.append(_matched_row(name, sim, reference, target, rounds))
    return rows


def _matched_row(name: str, sim: Callable[..., Any], reference: Callable[[float], tuple], target: float,
                 rounds: int) -> NativeRow:
    """The row of a simulate run ``sim(method)`` against the numba ``reference(rtol)`` at matched error:
    the loosest reference rtol of :data:`_LADDER` whose reversals are at least as accurate as
    simulate's against the reference at rtol 1e-13; also the reference at simulate's own rtol 1e-8
    and CasADi's path (``method="erk"``)."""
    exact = reference(1e-13)[0]
    res = sim()
    sim_err = _error(res.reversals.t, res.reversals.x, res.reversals.F, exact)
    chosen, ref_err = _LADDER[-1], math.inf
    for rtol in _LADDER:  # the loosest reference at least as accurate as simulate
        rev = reference(rtol)[0]
        err = _error(rev[0], rev[1], rev[2], exact)
        if err <= sim_err:
            chosen, ref_err = rtol, err
            break
    sim_s, ref_s = _interleaved(sim, lambda: reference(chosen), rounds)
    _, same_s = _interleaved(lambda: None, lambda: reference(1e-8), rounds)
    erk_s, _ = _interleaved(lambda: sim("erk"), lambda: None, max(2, rounds // 5))
    return NativeRow(name, f"numba({chosen:.0e})", sim_s, ref_s, sim_err, ref_err, target, same_s, erk_s)


def _feedback_rows(rounds: int) -> list[NativeRow]:
    """``simulate(..., feedback=)`` with a continuous PID loop around Dahl (a sine reference, 1 s)
    against the numba integrator of the same closed loop at matched error (reversals against the
    numba loop at rtol 1e-13)."""
    import prefriction as pf
    from prefriction.cli.bench import numba_refs as nr
    from prefriction.signals import Sine

    kp, ki, kd, tau, r_amp = 300.0, 3000.0, 5.0, 1e-3, 2e-3  # N/m, N/(m s), N s/m, s, m
    fb = pf.LinearFeedback([[0.0, 0.0], [0.0, -1.0 / tau]], [[1.0], [1.0 / tau]], [[ki, -kd / tau]],
                           [[kp + kd / tau]], reference=Sine(r_amp, FREQ))
    system = pf.Oscillator(pf.Dahl(SIGMA, FC), MASS)
    mp = np.array([SIGMA, FC, MASS])
    up = np.array([r_amp, 2 * np.pi * FREQ, kp, ki, kd / tau, 1.0 / tau])
    scale = np.array([FC / SIGMA, FC / math.sqrt(SIGMA * MASS), FC, FC / ki, FC / (kd / tau)])
    none = np.zeros(1)

    def reference(rtol: float) -> tuple:
        return nr.forced_run(nr.DAHL, mp, nr.PID, up, none, none, np.zeros(5), 1.0, 1.0, rtol, rtol * scale,
                             np.zeros(0))

    def sim(method: str = "native") -> Any:
        return pf.simulate(system, 0.0, t_end=1.0, rtol=1e-8, feedback=fb, method=method)

    return [_matched_row("Dahl in a continuous PID loop, sine reference", sim, reference, 2.0, rounds)]


def _loop_rows(rounds: int) -> list[NativeRow]:
    """10 kHz PID loops (1 s, a 5 um sine reference) around Dahl and LuGre stages: time per sample
    of ``controllers.simulate_loop`` against the numba loop at the loosest tolerance that matches
    the trajectory to 1e-8 of the stroke (both against the numba loop at rtol 1e-13)."""
    import prefriction as pf
    from prefriction import controllers
    from prefriction.cli.bench import numba_refs as nr
    from prefriction.signals import Sine

    Ts, t_end, stroke = 1e-4, 1.0, 5e-6
    ref = Sine(0.5 * stroke, 5.0, phase=-math.pi / 2, offset=0.5 * stroke)
    tk = Ts * np.arange(int(round(t_end / Ts)) + 1)
    r = np.asarray(ref(tk), dtype=float)
    lugre = (1e6, 300.0, 0.4, 1.0, 1.5, 1e-3)
    cases = [("10 kHz PID loop around Dahl", pf.Dahl(1e6, 1.0), nr.DAHL, np.array([1e6, 1.0, MASS])),
             ("10 kHz PID loop around LuGre", pf.LuGre(*lugre), nr.LUGRE, np.array([*lugre, MASS]))]
    rows = []
    for name, model, kind, mp in cases:
        stage = pf.Oscillator(model, MASS)
        Cd = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7).c2d(Ts)
        scale = np.array([stroke, stroke * 1e3, 1.0])

        def reference(rtol: float, mp: np.ndarray = mp, kind: int = kind, Cd=Cd, scale=scale) -> tuple:
            return nr.pid_loop(kind, mp, Cd.A, Cd.B, Cd.C, float(Cd.D[0, 0]), Ts, r, rtol, rtol * scale)

        exact = reference(1e-13)[0]

        def sim(stage=stage, Cd=Cd):
            return controllers.simulate_loop(stage, Cd, ref, t_end, rtol=1e-8)

        res = sim()
        sim_err = float(np.max(np.abs(res.x - exact))) / stroke
        chosen, ref_err = _LADDER[-1], math.inf
        for rtol in _LADDER:
            err = float(np.max(np.abs(reference(rtol)[0] - exact))) / stroke
            if err <= 1e-8:
                chosen, ref_err = rtol, err
                break
        sim_s, ref_s = _interleaved(sim, lambda: reference(chosen), max(3, rounds // 5))
        erk_s, _ = _interleaved(lambda: _casadi_loop(sim), lambda: None, 2)
        n = len(tk) - 1
        rows.append(NativeRow(name + " (per sample)", f"numba({chosen:.0e})", sim_s / n, ref_s / n, sim_err, ref_err,
                              3.0, erk_s=erk_s / n))
        if kind == nr.DAHL:
            rows.append(_sampled_feedback_row(stage, Cd, ref, t_end, stroke, exact, chosen, ref_err, reference, rounds))
            rows.append(_exported_row(stage, r, Ts, stroke, exact, chosen, ref_err, reference, rounds))
    return rows


def _sampled_feedback_row(stage: Any, Cd: Any, ref: Any, t_end: float, stroke: float, exact: np.ndarray,
                          chosen: float, ref_err: float, reference: Callable, rounds: int) -> NativeRow:
    """``simulate(..., feedback=LinearFeedback(..., Ts=))``: the same discrete PID loop as the
    row before it (the native sampled loop), per sample, next to the same numba loop; the CasADi
    path (``method="erk"``, one CasADi call per period) is timed too."""
    import prefriction as pf

    fb = pf.LinearFeedback(A=Cd.A, B=Cd.B, C=Cd.C, D=Cd.D, Ts=Cd.dt, reference=ref)

    def sim(method: str = "native") -> Any:
        return pf.simulate(stage, 0.0, t_end=t_end, rtol=1e-8, feedback=fb, method=method)

    err = float(np.max(np.abs(sim().x - exact))) / stroke
    sim_s, ref_s = _interleaved(sim, lambda: reference(chosen), max(3, rounds // 5))
    erk_s, _ = _interleaved(lambda: sim("erk"), lambda: None, 2)
    n = exact.size - 1
    return NativeRow("sampled feedback= around Dahl (per sample)", f"numba({chosen:.0e})", sim_s / n,
                     ref_s / n, err, ref_err, 3.0, erk_s=erk_s / n)


def _exported_row(stage: Any, r: np.ndarray, Ts: float, stroke: float, exact: np.ndarray, chosen: float,
                  ref_err: float, reference: Callable, rounds: int) -> NativeRow:
    """The exported C loop (``controller_source`` + ``plant_source``, ``-O2``, timed in C over its
    passes, process CPU time) next to the numba loop of the same row, timed in the same run."""
    import tempfile

    from prefriction import controllers, export

    pid = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7)
    n = r.size - 1
    with tempfile.TemporaryDirectory(prefix="prefriction-bench-") as tmp:
        ctl = export.controller_source(pid, "ctl", tmp, Ts=Ts)
        plant = export.plant_source(stage, "stage", tmp, Ts=Ts, rtol=1e-8)
        c_s, ref_s = math.inf, math.inf
        for _ in range(3):  # interleaved: a C run of several passes, then the reference
            run = export.run_loop_c(ctl, plant, r, rounds=max(2, rounds // 6))
            c_s = min(c_s, run.ns_per_sample * 1e-9)
            _, ref_t = _interleaved(lambda: None, lambda: reference(chosen), 2)
            ref_s = min(ref_s, ref_t / n)
    err = float(np.max(np.abs(run.x - exact[: run.x.size]))) / stroke
    return NativeRow("exported C loop around Dahl (per sample)", f"numba({chosen:.0e})", c_s, ref_s, err, ref_err, 2.0)


def _along_rows(rounds: int) -> list[NativeRow]:
    """``friction_along`` of a Maxwell-slip model of 3 elements over 1e6 samples against the
    numba elastoplastic update (per sample); error: the largest force difference over the slip
    force sum. The CasADi block loop (without a compiler) is timed too."""
    import prefriction as pf
    import prefriction.along.run as along_run
    from prefriction.cli.bench import numba_refs as nr

    k, f = np.array([6e4, 3e4, 1e4]), np.array([0.3, 0.4, 0.3])
    model = pf.MaxwellSlip(k, f)
    t = np.linspace(0.0, 10.0, 1_000_001)
    x = 2e-5 * np.sin(2 * np.pi * 3.0 * t) + 1e-6 * np.sin(2 * np.pi * 37.0 * t)
    res = pf.friction_along(model, t, x)
    ref = nr.maxwell_slip_along(x, k, f)
    err = float(np.max(np.abs(res.F - ref))) / float(f.sum())
    sim_s, ref_s = _interleaved(lambda: pf.friction_along(model, t, x), lambda: nr.maxwell_slip_along(x, k, f),
                                max(3, rounds // 5))
    saved = along_run.along_driver
    along_run.along_driver = lambda model, substeps: None
    try:
        erk_s, _ = _interleaved(lambda: pf.friction_along(model, t, x), lambda: None, 2)
    finally:
        along_run.along_driver = saved
    n = t.size
    return [NativeRow("friction_along Maxwell-slip(3), 1e6 samples (per sample)", "numba", sim_s / n, ref_s / n, err,
                      0.0, 3.0, erk_s=erk_s / n)]


def _casadi_loop(sim: Callable[[], object]) -> object:
    """``sim()`` with the sampled loop on the CasADi block Function (the path without a C compiler)."""
    from prefriction.simulation.loops import runner

    saved = runner.loop_driver
    runner.loop_driver = lambda spec: (None, 0.0)
    try:
        return sim()
    finally:
        runner.loop_driver = saved


def _headline_rows(rounds: int) -> list[NativeRow]:
    import prefriction as pf
    from prefriction.cli.bench.cases import HEADLINE, N_REV, reversal_error
    from prefriction.cli.bench.plain_c import c_reversals

    case = HEADLINE
    ref = pf.exact_reversals(case.system, case.v0, N_REV, F0=case.F0)
    rows = []
    for rtol, target in ((1e-8, 2.0), (1e-4, 3.0)):
        res = pf.simulate(case.system, case.v0, F0=case.F0, reversals=N_REV, rtol=rtol)
        t, x, F, _ = c_reversals(case.system, case.v0, N_REV, rtol, case.F0)
        sim_s, ref_s = _interleaved(lambda: pf.simulate(case.system, case.v0, F0=case.F0, reversals=N_REV, rtol=rtol),
                                    lambda: c_reversals(case.system, case.v0, N_REV, rtol, case.F0), rounds)
        tab = res.reversals
        rows.append(NativeRow(f"unforced Dahl, {N_REV} reversals, rtol {rtol:g}", "C", sim_s, ref_s,
                              reversal_error(case, tab.t, tab.x, tab.F, ref), reversal_error(case, t, x, F, ref), target))
    return rows


def run(quick: bool = False) -> list[NativeRow]:
    """The rows (plain-C rows need a C compiler, numba rows numba)."""
    from prefriction.cli.bench import numba_refs
    from prefriction.cli.bench.plain_c import c_available

    rounds = 5 if quick else 30
    rows: list[NativeRow] = []
    if c_available():
        rows += _headline_rows(rounds)
    if numba_refs.available():
        rows += _forced_rows(rounds)
        rows += _feedback_rows(rounds)
        rows += _loop_rows(rounds)
        rows += _along_rows(rounds)
    return rows


def main(quick: bool = False, rows: Optional[list[NativeRow]] = None) -> int:
    """Print the table; 0 if every row meets its target."""
    rows = run(quick) if rows is None else rows
    print("Native driver against references written from the equations (process CPU time, least of "
          "interleaved rounds; errors: simulate / reference):")
    for row in rows:
        print(row.line())
    if not rows:
        print("  no reference available (no C compiler, numba not installed)")
    return 0 if rows and all(r.ratio <= r.target for r in rows) else 1
