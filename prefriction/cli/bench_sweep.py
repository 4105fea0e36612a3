"""``prefriction bench --sweep``: parameter sweeps with one compiled integrator per structure.

One run measures three sweeps of :func:`prefriction.sweep`, each in fresh subprocesses:

- 20 values of gamma in [1, 3] (unforced Dahl oscillator, 50 reversals; structure gamma >= 1),
- 20 values of gamma in [0.3, 0.9] (unforced, 50 reversals; structure gamma < 1, saturating),
- 20 amplitudes in [0.2, 2] N of a :class:`prefriction.signals.Sine` input at 5 Hz (gamma = 1,
  from rest, 1 s),

all with ``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg (``v0 = 1`` m/s unforced) and the default
``rtol = 1e-8``. Each sweep runs once *cold*, in a new process whose compiled-code cache
(``$PREFRICTION_CACHE``) is a fresh empty directory, and then *warm*, in new processes (minimum of
3) that find the structure in that directory, compiled by the cold process. A compile is a new
``.so`` file in the cache directory; the ``prefriction: compiling`` lines on the child's stderr are
counted too. The child reports the end-to-end time of the :func:`prefriction.sweep` call
(compiling or loading included, ``import prefriction`` excluded and reported separately) and the
maximum relative error of the reversal times, positions and forces, against
:func:`prefriction.exact_reversals` (unforced) or a tight scipy reference (forced; DOP853 at
``rtol = 1e-12`` with restarts at every reversal).

The peer is scipy ``solve_ivp(method="DOP853")`` in normalised units with a restart at every
reversal (and at saturation for gamma < 1), at *matched error*: the loosest ``rtol`` in
1e-7 ... 1e-12 (``atol = rtol / 100``) whose error on the first value of the sweep is at most
``max(1e-8, simulator error)``; the whole sweep is then timed at that ``rtol`` in the parent
process. Ratios are scipy time over simulator time, both from the same run.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np

from prefriction.models import Dahl, Oscillator
from prefriction.signals import Sine
from prefriction.units import Scales

__all__ = ["SweepCase", "SweepRow", "main", "reversal_error", "scipy_reversals", "sweep_cases", "worker"]

SIGMA, FC, MASS = 1e4, 1.0, 1.0  # N/m, N, kg
V0_FREE = 1.0  # initial velocity of the unforced sweeps [m/s]
FREQUENCY = 5.0  # frequency of the Sine input [Hz]
N_REV = 50  # reversals per unforced run
T_END = 1.0  # duration of a forced run [s]
N_VALUES, QUICK_VALUES = 20, 4
LADDER = (1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)  # scipy rtol, loosest first
REF_RTOL = 1e-12  # scipy reference of the forced sweep
TARGET_ERROR = 1e-8
T1_RATIO = 20.0
WARM_REPEATS = 3
SCIPY_BUDGET = 6.0  # stop repeating a scipy sweep once the repeats took this long [s]
COMPILE_LINE = "prefriction: compiling"


# --- cases -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepCase:
    """One sweep: a parameter of one model structure over a set of values.

    Attributes
    ----------
    key : str
        Short identifier (``gamma_ge1``, ``gamma_lt1``, ``sine``).
    label : str
        Row label of the table.
    param : str
        The swept parameter, ``"gamma"`` or ``"amplitude"``.
    values : tuple of float
        The values of ``param``.
    forced : bool
        True for the Sine-forced sweep (``t_end = 1`` s), False for unforced (50 reversals).
    """

    key: str
    label: str
    param: str
    values: tuple[float, ...]
    forced: bool

    def system(self, value: float) -> Oscillator:
        """The oscillator of one value.

        Parameters
        ----------
        value : float
            Value of :attr:`param` (gamma, or the amplitude of the Sine input [N]).

        Returns
        -------
        Oscillator
            Dahl oscillator with ``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg.
        """
        if self.forced:
            return Oscillator(Dahl(SIGMA, FC, 1.0), mass=MASS, u=Sine(value, FREQUENCY))
        return Oscillator(Dahl(SIGMA, FC, value), mass=MASS)

    @property
    def v0(self) -> float:
        """Initial velocity [m/s]: 1 unforced, 0 (from rest) forced."""
        return 0.0 if self.forced else V0_FREE

    def gamma_of(self, value: float) -> float:
        """The gamma of the system of one value.

        Parameters
        ----------
        value : float
            Value of :attr:`param`.

        Returns
        -------
        float
            ``value`` for a gamma sweep, 1 for the forced sweep.
        """
        return 1.0 if self.forced else value

    def simulate_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`prefriction.sweep`: ``t_end`` forced, ``reversals`` unforced.

        Returns
        -------
        dict
            ``{"t_end": 1.0}`` or ``{"reversals": 50}`` (``rtol`` stays at its default 1e-8).
        """
        return {"t_end": T_END} if self.forced else {"reversals": N_REV}


def sweep_cases(n: int) -> list[SweepCase]:
    """The three sweeps of the benchmark with ``n`` values each.

    Parameters
    ----------
    n : int
        Values per sweep (20 in the full run, 4 with ``--quick``).

    Returns
    -------
    list of SweepCase
        gamma in [1, 3], gamma in [0.3, 0.9] (both unforced), Sine amplitude in [0.2, 2] N.
    """
    return [
        SweepCase("gamma_ge1", "gamma in [1, 3]", "gamma", _grid(1.0, 3.0, n), False),
        SweepCase("gamma_lt1", "gamma in [0.3, 0.9]", "gamma", _grid(0.3, 0.9, n), False),
        SweepCase("sine", f"Sine {FREQUENCY:g} Hz, A in [0.2, 2] N", "amplitude", _grid(0.2, 2.0, n), True),
    ]


def _grid(a: float, b: float, n: int) -> tuple[float, ...]:
    """``n`` equally spaced values from ``a`` to ``b`` as Python floats."""
    return tuple(float(v) for v in np.linspace(a, b, n))


# --- error metric ------------------------------------------------------------------------------


def reversal_error(t: np.ndarray, x: np.ndarray, F: np.ndarray, ref_t: np.ndarray, ref_x: np.ndarray,
                   ref_F: np.ndarray, x_scale: float = FC / SIGMA) -> float:
    """Max relative error of reversal times, positions and forces against a reference.

    The definition of ``prefriction bench``: times and forces relative to the reference,
    positions relative to ``max(|x_ref|, x_scale)``; a missing or extra reversal gives ``inf``.

    Parameters
    ----------
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N] to check.
    ref_t, ref_x, ref_F : numpy.ndarray
        The reference reversals, same units.
    x_scale : float, optional
        Least position scale [m], default ``Fc / sigma``.

    Returns
    -------
    float
        The largest relative error, or ``inf`` if the numbers of reversals differ.
    """
    t, x, F = (np.asarray(a, dtype=float) for a in (t, x, F))
    ref_t, ref_x, ref_F = (np.asarray(a, dtype=float) for a in (ref_t, ref_x, ref_F))
    if len(t) != len(ref_t) or len(t) == 0:
        return math.inf
    et = np.abs(t - ref_t) / np.abs(ref_t)
    ex = np.abs(x - ref_x) / np.maximum(np.abs(ref_x), x_scale)
    eF = np.abs(F - ref_F) / np.abs(ref_F)
    err = float(max(et.max(), ex.max(), eF.max()))
    return err if math.isfinite(err) else math.inf


def _exact_tables(case: SweepCase) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Reversals ``(t, x, F)`` of :func:`prefriction.exact_reversals` for every value (unforced)."""
    from prefriction.analysis.exact import exact_reversals

    out = []
    for value in case.values:
        ref = exact_reversals(case.system(value), case.v0, N_REV)
        out.append((ref.t, ref.x, ref.F))
    return out


# --- scipy peer (normalised units) -------------------------------------------------------------


def _branch_rhs(gamma: float, s: float, saturated: bool, u: Optional[Callable[[float], float]]) -> Callable:
    """Right-hand side ``(x~, v~, F~)' `` on a branch of direction ``s`` (``F~' = 0`` once saturated)."""
    if saturated:
        return lambda t, z: [z[1], (u(t) if u else 0.0) - z[2], 0.0]
    return lambda t, z: [z[1], (u(t) if u else 0.0) - z[2], z[1] * max(1.0 - s * z[2], 0.0) ** gamma]


def _branch_events(gamma: float, s: float, saturated: bool) -> list[Callable]:
    """Terminal events of a branch: the reversal ``s v~ = 0`` and, for gamma < 1, saturation.

    Both have ``direction = -1``: after a restart exactly at ``v~ = 0`` (or ``|F~| = 1``) the
    indicator starts at 0 and grows, so the event does not fire at the start of the branch.
    """

    def reversal(t: float, z: np.ndarray) -> float:
        return s * z[1]

    reversal.terminal, reversal.direction = True, -1.0
    events = [reversal]
    if gamma < 1.0 and not saturated:

        def saturation(t: float, z: np.ndarray) -> float:
            return 1.0 - s * z[2]

        saturation.terminal, saturation.direction = True, -1.0
        events.append(saturation)
    return events


def _initial_direction(v0: float, f0: float, u: Optional[Callable[[float], float]]) -> float:
    """Branch direction at the start: ``sign(v0)``, else that of the net force (just after 0)."""
    if v0 != 0.0:
        return math.copysign(1.0, v0)
    if u is None:
        return -math.copysign(1.0, f0) if f0 != 0.0 else 1.0
    for h in (0.0, 1e-9, 1e-6, 1e-3):
        net = u(h) - f0
        if net != 0.0:
            return math.copysign(1.0, net)
    return 1.0


def scipy_reversals(gamma: float, v0: float, rtol: float, *, n: Optional[int] = None,
                    t_end: Optional[float] = None, u: Optional[Callable[[float], float]] = None,
                    f0: float = 0.0) -> np.ndarray:
    """Reversals of the Dahl oscillator by scipy DOP853 with a restart at every event (normalised).

    Integrates ``x~' = v~``, ``v~' = u~(t~) - F~``, ``F~' = v~ (1 - s F~)^gamma`` from
    ``x~ = 0``; ``s`` is the direction of the current branch. Each velocity reversal ends a
    ``solve_ivp`` call; the next starts on the reversed branch at ``v~ = 0`` exactly. For
    ``gamma < 1`` reaching ``|F~| = 1`` is an event too, after which ``F~`` stays at ``s``
    until the next reversal.

    Parameters
    ----------
    gamma : float
        Dahl shape factor, ``>= 0``.
    v0 : float
        Initial normalised velocity ``v~``.
    rtol : float
        Relative tolerance of DOP853; ``atol = rtol / 100``.
    n : int, optional
        Stop after this many reversals.
    t_end : float, optional
        Stop at this normalised time. At least one of ``n`` and ``t_end`` is required.
    u : callable, optional
        Normalised input force ``u~(t~)``; None for the unforced oscillator.
    f0 : float, optional
        Initial normalised friction force, default 0.

    Returns
    -------
    numpy.ndarray
        Shape ``(k, 3)``: normalised time, position and force of each reversal.

    Raises
    ------
    ValueError
        If neither ``n`` nor ``t_end`` is given.
    RuntimeError
        If ``solve_ivp`` fails.
    """
    from scipy.integrate import solve_ivp

    if n is None and t_end is None:
        raise ValueError("give n (reversals) or t_end (normalised end time) or both")
    s, saturated = _initial_direction(v0, f0, u), False
    y, t0, out = np.array([0.0, v0, f0]), 0.0, []
    t_stop = math.inf if t_end is None else t_end
    span = 64.0 + 4.0 * abs(v0) + 2.0 * v0 * v0
    while (n is None or len(out) < n) and t0 < t_stop:
        sol = solve_ivp(_branch_rhs(gamma, s, saturated, u), (t0, min(t0 + span, t_stop)), y,
                        method="DOP853", rtol=rtol, atol=rtol * 1e-2,
                        events=_branch_events(gamma, s, saturated))
        if sol.status == 1 and len(sol.t_events[0]):  # reversal: restart on the reversed branch
            t0, y = float(sol.t_events[0][0]), np.array(sol.y_events[0][0])
            y[1] = 0.0
            out.append((t0, y[0], y[2]))
            s, saturated = -s, False
        elif sol.status == 1:  # saturation |F~| = 1
            t0, y = float(sol.t_events[1][0]), np.array(sol.y_events[1][0])
            y[2], saturated = s, True
        elif sol.status == 0:
            t0, y = float(sol.t[-1]), sol.y[:, -1]
        else:
            raise RuntimeError(f"solve_ivp DOP853 failed at t~ = {t0}: {sol.message}")
    return np.array(out, dtype=float).reshape(-1, 3)


def _scipy_table(case: SweepCase, value: float, rtol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reversals ``(t, x, F)`` [SI] of one value of ``case`` by :func:`scipy_reversals`."""
    system = case.system(value)
    sc = Scales.of(system)
    if case.forced:
        w = 2.0 * math.pi * FREQUENCY * sc.t  # normalised angular frequency
        amp = value / sc.F
        R = scipy_reversals(1.0, case.v0 / sc.v, rtol, t_end=T_END / sc.t, u=lambda t: amp * math.sin(w * t))
    else:
        R = scipy_reversals(case.gamma_of(value), case.v0 / sc.v, rtol, n=N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def _scipy_sweep(case: SweepCase, rtol: float, values: Sequence[float]) -> list[tuple[np.ndarray, ...]]:
    """Reversal tables of :func:`_scipy_table` for every value (warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [_scipy_table(case, v, rtol) for v in values]


def _max_error(tables: Sequence[tuple[np.ndarray, ...]], refs: Sequence[tuple[np.ndarray, ...]]) -> float:
    """Largest :func:`reversal_error` over paired tables."""
    return max(reversal_error(*tab, *ref) for tab, ref in zip(tables, refs))


@dataclass
class ScipyResult:
    """The matched-error scipy DOP853 sweep of one case."""

    rtol: float
    seconds: float
    error: float
    matched: bool
    ladder: list[tuple[float, float]] = field(default_factory=list)


def matched_rtol(case: SweepCase, refs: Sequence[tuple[np.ndarray, ...]], target: float) -> tuple[float, bool, list]:
    """Loosest rtol of :data:`LADDER` whose error on the first value is at most ``target``.

    Parameters
    ----------
    case : SweepCase
        The sweep.
    refs : sequence of (t, x, F)
        Reference reversals per value (only the first is used).
    target : float
        Error to match.

    Returns
    -------
    (float, bool, list)
        The rtol (the tightest of the ladder if none matches), whether it matches, and the
        ``(rtol, error)`` pairs tried, loosest first (the ladder stops at the first match).
    """
    tried = []
    for rtol in LADDER:
        err = _max_error(_scipy_sweep(case, rtol, case.values[:1]), refs[:1])
        tried.append((rtol, err))
        if err <= target:
            return rtol, True, tried
    return LADDER[-1], False, tried


def scipy_peer(case: SweepCase, refs: Sequence[tuple[np.ndarray, ...]], target: float, repeats: int) -> ScipyResult:
    """Time the whole scipy DOP853 sweep at the matched rtol (minimum of ``repeats``).

    Parameters
    ----------
    case : SweepCase
        The sweep.
    refs : sequence of (t, x, F)
        Reference reversals per value.
    target : float
        Error to match (see :func:`matched_rtol`).
    repeats : int
        Most repeats of the timed sweep; fewer once they took :data:`SCIPY_BUDGET` seconds.

    Returns
    -------
    ScipyResult
        rtol, best time [s], max error over the sweep and the ladder tried.
    """
    rtol, matched, tried = matched_rtol(case, refs, target)
    best, spent, tables = math.inf, 0.0, []
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        tables = _scipy_sweep(case, rtol, case.values)
        dt = time.perf_counter() - start
        best, spent = min(best, dt), spent + dt
        if spent > SCIPY_BUDGET:
            break
    return ScipyResult(rtol, best, _max_error(tables, refs), matched, tried)


# --- the child process -------------------------------------------------------------------------


def worker(spec: dict[str, Any], import_seconds: float) -> dict[str, Any]:
    """Run one sweep in this process and measure it (the body of a child process).

    Parameters
    ----------
    spec : dict
        ``{"case": key, "n": values per sweep, "reference": path or None}``; the reference file
        (JSON, forced sweep) holds the lists ``t``, ``x``, ``F`` per value [SI].
    import_seconds : float
        Time the child took to ``import prefriction`` [s], reported back unchanged.

    Returns
    -------
    dict
        ``sweep_s`` (end-to-end time of the :func:`prefriction.sweep` call, compiling or loading
        included), ``per_value_ms``, ``sim_wall_s`` (sum of the runs' integration times),
        ``setup_s``, ``jit`` (modes and their counts), ``failed``, ``errors`` per value and
        ``error`` (their maximum), ``import_s``.
    """
    from prefriction.simulation.sweep import sweep

    case = next(c for c in sweep_cases(int(spec["n"])) if c.key == spec["case"])
    systems = [case.system(v) for v in case.values]
    start = time.perf_counter()
    res = sweep(systems, case.v0, progress=False, **case.simulate_kwargs())
    seconds = time.perf_counter() - start
    if spec.get("reference"):
        data = json.loads(Path(spec["reference"]).read_text())
        refs = list(zip(data["t"], data["x"], data["F"]))
    else:
        refs = _exact_tables(case)
    ok = [r for r in res if not isinstance(r, BaseException)]
    errors = [math.inf if isinstance(r, BaseException) else
              reversal_error(r.reversals.t, r.reversals.x, r.reversals.F, *ref) for r, ref in zip(res, refs)]
    modes: dict[str, int] = {}
    for r in ok:
        modes[r.stats.jit] = modes.get(r.stats.jit, 0) + 1
    return {
        "import_s": import_seconds, "sweep_s": seconds, "per_value_ms": 1e3 * seconds / len(systems),
        "sim_wall_s": sum(r.stats.wall_time for r in ok), "setup_s": sum(r.stats.setup_time for r in ok),
        "jit": modes, "failed": len(res.failed), "errors": [_json_float(e) for e in errors],
        "error": _json_float(max(errors)),
    }


def _json_float(value: float) -> Optional[float]:
    """``value`` for JSON (``None`` for inf or nan)."""
    return value if math.isfinite(value) else None


_CHILD = (
    "import sys, time, json\n"
    "t0 = time.perf_counter()\n"
    "import prefriction\n"
    "ti = time.perf_counter() - t0\n"
    "from prefriction.cli.bench_sweep import worker\n"
    "print(json.dumps(worker(json.loads(sys.argv[1]), ti)))\n"
)


@dataclass
class ChildRun:
    """What one child process measured, and the compiles it caused."""

    report: dict[str, Any]
    new_libraries: int
    compile_lines: int


def run_child(spec: dict[str, Any], cache: Path) -> ChildRun:
    """Run :func:`worker` in a new Python process with ``PREFRICTION_CACHE=cache``.

    Parameters
    ----------
    spec : dict
        The worker's spec (see :func:`worker`).
    cache : pathlib.Path
        Compiled-code cache directory of the child.

    Returns
    -------
    ChildRun
        The child's JSON report, the number of ``.so`` files it added to ``cache`` and the number
        of ``prefriction: compiling`` lines on its stderr.

    Raises
    ------
    RuntimeError
        If the child fails or prints no JSON report.
    """
    before = set(cache.glob("*.so"))
    env = dict(os.environ, PREFRICTION_CACHE=str(cache))
    proc = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(spec)], env=env, capture_output=True,
                          text=True, timeout=900)
    lines = [line for line in proc.stderr.splitlines() if line.startswith(COMPILE_LINE)]
    for line in lines:
        _progress(f"  child: {line}")
    if proc.returncode != 0 or not proc.stdout.strip():
        raise RuntimeError(f"bench --sweep child failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    return ChildRun(report, len(set(cache.glob("*.so")) - before), len(lines))


# --- measurement -------------------------------------------------------------------------------


@dataclass
class SweepRow:
    """One row of the table: a cold or warm sweep of one case and its scipy peer."""

    case: str
    run: str
    n_values: int
    compiles: int
    compile_lines: int
    end_to_end_s: float
    per_value_ms: float
    import_s: float
    setup_s: float
    sim_wall_s: float
    max_rel_error: float
    reference: str
    scipy_rtol: float
    scipy_s: float
    scipy_error: float
    ratio: float
    repeats: int
    jit: str


def _reference(case: SweepCase, work: Path) -> tuple[list[tuple[np.ndarray, ...]], Optional[str]]:
    """Reference reversals of every value, and the path of their JSON file for the children.

    Unforced: :func:`prefriction.exact_reversals` (the children compute it themselves, no file).
    Forced: scipy DOP853 at :data:`REF_RTOL`, written to ``work/ref_<key>.json``.
    """
    if not case.forced:
        return _exact_tables(case), None
    _progress(f"{case.label}: reference, scipy DOP853 at rtol {REF_RTOL:g} with restarts")
    refs = _scipy_sweep(case, REF_RTOL, case.values)
    path = work / f"ref_{case.key}.json"
    path.write_text(json.dumps({k: [list(map(float, tab[i])) for tab in refs] for i, k in enumerate("txF")}))
    return refs, str(path)


def _child_row(case: SweepCase, run: str, children: list[ChildRun], reference: str) -> SweepRow:
    """A table row from one (cold) or several (warm) child runs; times are their minimum."""
    best = min(children, key=lambda c: c.report["sweep_s"])
    rep = best.report
    errors = [c.report["error"] for c in children]
    jit = ",".join(f"{k}:{v}" for k, v in sorted(rep["jit"].items()))
    return SweepRow(
        case=case.label, run=run, n_values=len(case.values),
        compiles=max(c.new_libraries for c in children),
        compile_lines=max(c.compile_lines for c in children),
        end_to_end_s=rep["sweep_s"], per_value_ms=rep["per_value_ms"],
        import_s=min(c.report["import_s"] for c in children), setup_s=rep["setup_s"],
        sim_wall_s=rep["sim_wall_s"],
        max_rel_error=math.inf if None in errors else max(errors), reference=reference,
        scipy_rtol=math.nan, scipy_s=math.nan, scipy_error=math.nan, ratio=math.nan,
        repeats=len(children), jit=jit,
    )


def measure_case(case: SweepCase, work: Path, warm_repeats: int, scipy_repeats: int) -> list[SweepRow]:
    """Cold and warm sweeps of one case in child processes, then its scipy peer here.

    Parameters
    ----------
    case : SweepCase
        The sweep.
    work : pathlib.Path
        Scratch directory: the case's cache directory ``cache_<key>`` and reference file go here.
    warm_repeats : int
        Warm child processes (their minimum time is reported).
    scipy_repeats : int
        Repeats of the timed scipy sweep.

    Returns
    -------
    list of SweepRow
        The cold and the warm row, with the figures of the scipy peer filled in.
    """
    refs, ref_path = _reference(case, work)
    reference = f"scipy DOP853 rtol {REF_RTOL:g}" if case.forced else "exact_reversals"
    cache = work / f"cache_{case.key}"
    cache.mkdir()
    spec = {"case": case.key, "n": len(case.values), "reference": ref_path}
    _progress(f"{case.label}: cold sweep of {len(case.values)} values (new process, empty cache {cache})")
    cold = run_child(spec, cache)
    warm = []
    for k in range(warm_repeats):
        _progress(f"{case.label}: warm sweep [{k + 1}/{warm_repeats}] (new process, cache from the cold run)")
        warm.append(run_child(spec, cache))
    rows = [_child_row(case, "cold", [cold], reference), _child_row(case, "warm", warm, reference)]
    target = max(TARGET_ERROR, cold.report["error"] if cold.report["error"] is not None else 0.0)
    _progress(f"{case.label}: scipy DOP853 + restarts, matching error {target:.1e} on the first value")
    peer = scipy_peer(case, refs, target, scipy_repeats)
    ladder = ", ".join(f"{r:g}: {e:.1e}" for r, e in peer.ladder)
    _progress(f"{case.label}: scipy ladder [{ladder}] -> rtol {peer.rtol:g}; sweep {peer.seconds:.2f} s")
    for row in rows:
        row.scipy_rtol, row.scipy_s, row.scipy_error = peer.rtol, peer.seconds, peer.error
        row.ratio = peer.seconds / row.end_to_end_s
    return rows


# --- report ------------------------------------------------------------------------------------


def format_table(rows: Sequence[SweepRow]) -> str:
    """The compact table: case, cold/warm, compiles, times, errors, scipy time and ratio.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows.

    Returns
    -------
    str
        Printable table.
    """
    head = (f"{'case':<28} {'run':<5} {'compiles':>8} {'end-to-end [s]':>14} {'per value [ms]':>14} "
            f"{'max error':>10} {'import [s]':>10} {'scipy [s]':>9} {'scipy rtol':>10} {'scipy err':>9} "
            f"{'ratio':>7}")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.case:<28} {r.run:<5} {r.compiles:>8d} {r.end_to_end_s:14.3f} {r.per_value_ms:14.2f} "
            f"{r.max_rel_error:10.1e} {r.import_s:10.2f} {r.scipy_s:9.2f} {r.scipy_rtol:10.0e} "
            f"{r.scipy_error:9.1e} {r.ratio:6.1f}x"
        )
    return "\n".join(lines)


def write_csv(path: Path, rows: Sequence[SweepRow]) -> None:
    """Write the rows to ``path`` as CSV, one column per :class:`SweepRow` field.

    Parameters
    ----------
    path : pathlib.Path
        Output file.
    rows : sequence of SweepRow
        Measured rows.
    """
    names = list(SweepRow.__dataclass_fields__)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for r in rows:
            w.writerow([getattr(r, k) for k in names])


def match_notes(rows: Sequence[SweepRow]) -> list[str]:
    """Notes for cases whose scipy sweep error exceeds the error matched on the first value.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows.

    Returns
    -------
    list of str
        One line per such case: its ratio is a lower bound (a tighter rtol would be slower).
    """
    notes = []
    for r in rows:
        target = max(TARGET_ERROR, r.max_rel_error)
        if r.run == "cold" and r.scipy_error > target:
            notes.append(f"note: {r.case}: rtol {r.scipy_rtol:g} matches on the first value, but scipy's error "
                         f"over the sweep is {r.scipy_error:.1e} > {target:.1e}: its ratios are lower bounds")
    return notes


def _find(rows: Sequence[SweepRow], case: SweepCase, run: str) -> SweepRow:
    """The row of ``case`` and ``run`` (``"cold"`` or ``"warm"``)."""
    return next(r for r in rows if r.case == case.label and r.run == run)


def targets(rows: Sequence[SweepRow], cases: Sequence[SweepCase], quick: bool) -> list[str]:
    """The PASS/FAIL lines of targets T1 and T2.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows (a cold and a warm row per case).
    cases : sequence of SweepCase
        The cases; the first is the gamma in [1, 3] sweep of T1.
    quick : bool
        With ``--quick`` the speed part of T1 is reported but not checked (4 values only).

    Returns
    -------
    list of str
        One line per target, starting with ``T1`` or ``T2`` and holding ``PASS`` or ``FAIL``.
    """
    first = cases[0]
    cold, warm = _find(rows, first, "cold"), _find(rows, first, "warm")
    fast = warm.ratio >= T1_RATIO
    ok1 = (warm.max_rel_error <= TARGET_ERROR and cold.compiles == 1 and warm.compiles == 0
           and (fast or quick))
    speed = "speed not checked in --quick, " if quick else ""
    lines = [
        f"T1 ({len(first.values)} gamma values in [1, 3], error <= {TARGET_ERROR:g}, new process with the "
        f"structure cached: >= {T1_RATIO:g}x faster than scipy DOP853 at the same error; empty cache: "
        f"1 compile): {'PASS' if ok1 else 'FAIL'}  ({speed}warm {warm.end_to_end_s * 1e3:.0f} ms end to end, "
        f"error {warm.max_rel_error:.1e}; scipy {warm.scipy_s * 1e3:.0f} ms at rtol {warm.scipy_rtol:g}, "
        f"error {warm.scipy_error:.1e}: ratio {warm.ratio:.1f}x; compiles cold {cold.compiles}, "
        f"warm {warm.compiles})"
    ]
    per = []
    ok2 = True
    for case in cases:
        c, w = _find(rows, case, "cold"), _find(rows, case, "warm")
        ok2 &= c.compiles <= 1 and w.compiles == 0 and c.compile_lines == c.compiles and w.compile_lines == 0
        per.append(f"{case.label}: {c.compiles} cold / {w.compiles} warm")
    lines.append(f"T2 (a sweep of one structure compiles at most once; compiles per sweep of "
                 f"{len(first.values)} values): {'PASS' if ok2 else 'FAIL'}  ({'; '.join(per)})")
    return lines


def out_dir(text: str) -> Path:
    """``--out`` of the bench commands: a directory path (created later if missing).

    Raises
    ------
    argparse.ArgumentTypeError
        If ``text`` is empty or names an existing file that is not a directory.
    """
    path = Path(text)
    if not text.strip():
        raise argparse.ArgumentTypeError("must be a directory path, got an empty string")
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"must be a directory, got {text!r}, an existing file")
    return path


def _progress(message: str) -> None:
    """One progress line on stderr (the table goes to stdout)."""
    print(f"  ... {message}", file=sys.stderr, flush=True)


def main(argv: Optional[list[str]] = None) -> int:
    """Entry point of ``prefriction bench --sweep``; returns 0 if every target passes.

    Parameters
    ----------
    argv : list of str, optional
        Options (default ``sys.argv[1:]``): ``--out DIR`` (default ``bench_out``) and ``--quick``
        (4 values per sweep, one warm process and one scipy repeat; T1's speed is not checked).

    Returns
    -------
    int
        0 if the target lines all say PASS, else 1.
    """
    ap = argparse.ArgumentParser(
        prog="prefriction bench --sweep", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Parameter sweeps with one compiled integrator per structure: 20 values of gamma in\n"
                    "[1, 3], 20 in [0.3, 0.9] and 20 amplitudes of a 5 Hz sine input, each run once in a\n"
                    "new process with an empty compiled-code cache (cold) and then in new processes that\n"
                    "find it cached (warm), against scipy DOP853 with restarts at the same error.\n"
                    "Targets T1 (speed, one compile) and T2 (one compile per structure); docs/bench.md.")
    ap.add_argument("--out", default="bench_out", type=out_dir, metavar="DIR",
                    help="output directory for sweep.csv, created if missing (default: bench_out)")
    ap.add_argument("--quick", action="store_true",
                    help="4 values per sweep, one warm process, one scipy repeat (T1 speed not checked)")
    args = ap.parse_args(argv)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    cases = sweep_cases(QUICK_VALUES if args.quick else N_VALUES)
    warm_repeats = 1 if args.quick else WARM_REPEATS
    scipy_repeats = 1 if args.quick else WARM_REPEATS
    start = time.perf_counter()
    rows: list[SweepRow] = []
    with tempfile.TemporaryDirectory(prefix="prefriction-bench-sweep-") as tmp:
        for case in cases:
            rows.extend(measure_case(case, Path(tmp), warm_repeats, scipy_repeats))
    print(f"Sweeps of prefriction.simulation.sweep, sigma = {SIGMA:g} N/m, Fc = {FC:g} N, m = {MASS:g} kg, rtol 1e-8: "
          f"unforced {N_REV} reversals from v0 = {V0_FREE:g} m/s, forced {T_END:g} s from rest.\n"
          f"cold: new process, empty cache; warm: new process, cache from the cold run (min of "
          f"{warm_repeats}). end-to-end = the sweep call incl. compile/load, import excluded.\n"
          f"max error: reversal t, x, F vs exact_reversals (unforced) or scipy DOP853 rtol {REF_RTOL:g} "
          f"(forced). scipy: DOP853 + restarts at the loosest rtol matching max(1e-8, simulator error) "
          f"on the first value, whole sweep timed; ratio = scipy / end-to-end.\n")
    print(format_table(rows))
    for note in match_notes(rows):
        print(note)
    print()
    lines = targets(rows, cases, args.quick)
    for line in lines:
        print(line)
    write_csv(out / "sweep.csv", rows)
    print(f"\nwrote {out / 'sweep.csv'} ({time.perf_counter() - start:.0f} s)")
    return 0 if all("PASS" in line for line in lines) else 1


if __name__ == "__main__":
    sys.exit(main())
