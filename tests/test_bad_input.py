"""Every public function and command-line subcommand rejects bad input with a clear error.

Table-driven property test: each row is (callable, valid baseline arguments, one argument name,
a hypothesis strategy of bad values for it). The bad value replaces the argument and the call
must raise ``ValueError`` or ``TypeError`` whose message names the argument (for the command
line: exit code 2 and a message naming the option). Any other exception, a result (NaN or not:
the value is invalid), or a run longer than the time guard fails the row.

The reference is the documented domain of each argument, not the code's output. No row
compiles a plant: the simulator's compile entry point and the heavy command-line work are
replaced by a sentinel that fails the row if a bad value gets that far.

Rows of functions in modules maintained elsewhere that still fail are marked
``xfail(strict=True)`` with the owning file: when the owner fixes the function, the row passes,
strict xfail turns that into a failure and the mark must go.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
import signal
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import prefriction as pf
from prefriction import dahl, signals, testing
from prefriction.analysis import maxwell_slip_exact as mse
from prefriction.analysis.exact import MAX_REVERSALS
from prefriction.units import Scales

NAN, INF = math.nan, math.inf
GUARD_SECONDS = 3.0  # a bad value must be refused well within this (a hang fails the row)


class ReachedWork(Exception):
    """Raised by the sentinels: a bad value got as far as compiling or running heavy work."""


@pytest.fixture(scope="module", autouse=True)
def _no_heavy_work():
    """Replace the compile entry point and the command line's heavy work by sentinels."""
    import prefriction.cli.bench as bench
    import prefriction.cli.bench.sweep as bench_sweep
    import prefriction.cli.bench_loops as bench_loops
    import prefriction.cli.paper as paper
    import prefriction.simulation.build as build

    def sentinel(*_a: Any, **_k: Any) -> Any:
        raise ReachedWork("a bad value reached the compile / the heavy work")

    import importlib

    patches = [(build, "integrator"), (build, "native_driver"), (build, "forced_driver"), (bench, "headline"), (bench, "_models_main"), (bench_sweep, "main"),
               (bench_loops, "run"), (paper, "run_all")]
    for module, name in [("prefriction.simulation.integrator", "build_integrator"),
                         ("prefriction.simulation.loops.compiled_loop", "build_integrator"),
                         ("prefriction.simulation.loops.runner", "compiled")]:
        try:
            mod = importlib.import_module(module)
        except ImportError:
            continue
        if hasattr(mod, name):
            patches.append((mod, name))
    saved = [(mod, name, getattr(mod, name)) for mod, name in patches]
    for mod, name in patches:
        setattr(mod, name, sentinel)
    yield
    for mod, name, value in saved:
        setattr(mod, name, value)


class Hang(Exception):
    """The call did not return within the guard time."""


@contextlib.contextmanager
def time_guard(seconds: float = GUARD_SECONDS):
    def handler(_sig: int, _frame: Any) -> None:
        raise Hang(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def names_argument(message: str, name: str) -> bool:
    """True if ``message`` names ``name`` as an argument (``v0 must``, ``--rows:``, ``stiffness[2] =``,
    ``system.friction must``, ``ReversalTable.x has``), not merely as a letter inside other words."""
    pattern = (rf"(?:^|[\s(`'\"\-,.]){re.escape(name)}(?:\[[^\]]*\]|\.\w+)?['\"`]?"
               rf"(?=\s*(?:must|=|has|is|holds|samples?|:|\(|and|or|,|\[|<|>|lies|gives|needs|exceeds|of))")
    return re.search(pattern, message) is not None


# --------------------------------------------------------------------------------------------
# bad values


class _Opaque:
    def __repr__(self) -> str:
        return "<opaque object>"


NOT_REAL = [None, "1.0", "fast", 1 + 2j, [1.0], (), {}, b"1", _Opaque(), True, np.array([1.0, 2.0])]
NON_FINITE = [NAN, INF, -INF]
bad_real = st.sampled_from(NOT_REAL + NON_FINITE)
bad_positive = bad_real | st.sampled_from([0.0, -0.0, -1.0, -1e-300, -1e300]) | st.floats(max_value=0.0)
bad_nonneg = bad_real | st.sampled_from([-1.0, -1e-300, -1e300]) | st.floats(max_value=-1e-300)
bad_bool = st.sampled_from(["yes", "False", None, 1, 0, 1.0, NAN, [True]])
bad_str = st.sampled_from([None, 3, 1.5, b"erk", ["erk"], "no such method"])


def bad_count(minimum: int = 1, limit: Optional[int] = None) -> st.SearchStrategy:
    """Non-integers, integers below ``minimum`` and (if given) above ``limit``."""
    values = [None, "3", 2.5, 3.0, NAN, INF, 1 + 2j, True, [3], minimum - 1, -1, -(10**18)]
    strat = st.sampled_from(values) | st.integers(max_value=minimum - 1)
    if limit is not None:
        strat = strat | st.sampled_from([limit + 1, 10**12, 10**18, 10**30])
    return strat


BAD_ARRAYS = [None, "1.0", "fast", {}, _Opaque(), [1.0, NAN], [INF], [-INF, 0.0], [1 + 1j], np.array([1 + 0j]),
              [[1.0, 2.0], [3.0]], ["1.0"], [None], np.array(["a"]), np.array([True])]
bad_array = st.sampled_from(BAD_ARRAYS) | st.lists(st.sampled_from([NAN, INF, -INF]), min_size=1, max_size=4)


def bad_array_outside(lo: float, hi: float) -> st.SearchStrategy:
    """Bad arrays, and arrays with an entry outside [lo, hi]."""
    outside = st.floats(allow_nan=False, allow_infinity=False).filter(lambda v: not lo <= v <= hi)
    return bad_array | st.lists(outside, min_size=1, max_size=3)


# --------------------------------------------------------------------------------------------
# systems

DAHL = pf.Dahl(sigma=1e4, Fc=1.0)
SYSTEM = pf.Oscillator(DAHL, mass=1.0)
MS = pf.MaxwellSlip([6e3, 3e3, 1e3], [0.5, 0.3, 0.2])
MS_SYSTEM = pf.Oscillator(MS, mass=1.0)
LUGRE = pf.LuGre(sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3)
FORCED = pf.Oscillator(DAHL, mass=1.0, u=pf.signals.Sine(0.5, 10.0))
bad_system = st.sampled_from([None, 3, "dahl", DAHL, (SYSTEM,), pf.Oscillator(LUGRE, mass=1.0), FORCED])
bad_ms_system = st.sampled_from([None, 3, "ms", MS, SYSTEM, pf.Oscillator(MS, mass=1.0, u=1.0)])
bad_model = st.sampled_from([None, 3, "dahl", SYSTEM, [DAHL]])
bad_system_any = st.sampled_from([None, 3, "dahl", DAHL, [SYSTEM]])
bad_ms_model = st.sampled_from([None, 3, "ms", DAHL, MS_SYSTEM])


# --------------------------------------------------------------------------------------------
# rows


@dataclass
class Row:
    """One argument of one callable: the callable, valid baseline keywords, the argument, bad values."""

    id: str
    fn: Callable[..., Any]
    base: dict
    arg: str
    bad: st.SearchStrategy
    owner: Optional[str] = None  # file maintained elsewhere whose fix this row waits for
    examples: int = 10
    names: Optional[str] = None  # the name the message must give, if not ``arg``
    marks: list = field(default_factory=list)

    def param(self) -> Any:
        marks = list(self.marks)
        if self.owner:
            marks.append(pytest.mark.xfail(strict=True, reason=f"owner: {self.owner}"))
        return pytest.param(self, id=self.id, marks=marks)


def rows_for(prefix: str, fn: Callable[..., Any], base: dict, bad: dict, owner: Optional[dict] = None) -> list[Row]:
    owner = owner or {}
    return [Row(f"{prefix}-{arg}", fn, base, arg, strat, owner.get(arg)) for arg, strat in bad.items()]


X3 = np.array([0.0, 1e-5, 2e-4])
SF = dict(sigma=1e4, Fc=1.0)
SF_BAD = dict(sigma=bad_positive, Fc=bad_positive)

ROWS: list[Row] = []

# prefriction.dahl ---------------------------------------------------------------------------
ROWS += rows_for("dahl.branch_force", dahl.branch_force, dict(x=X3, x_i=0.0, F_i=-0.5, **SF, direction=1), dict(
    x=bad_array | st.sampled_from([[-1.0], -1e-3]),  # behind the reversal: not on the branch
    x_i=bad_array | st.sampled_from([np.zeros(2), 1.0]),
    F_i=bad_array_outside(-1.0, 1.0) | st.sampled_from([np.zeros(2)]),
    direction=st.sampled_from([0, 2, -2, None, "1", 1.5, NAN, True, [1]]), **SF_BAD))
ROWS += rows_for("dahl.zero_crossing", dahl.zero_crossing, dict(x_i=X3, F_i=[-0.5, 0.2, 0.0], **SF, direction=1), dict(
    x_i=bad_array | st.sampled_from([np.zeros(2)]),
    F_i=bad_array_outside(-1.0, 1.0) | st.sampled_from([1.0, [0.0, 1.0, 0.0], np.zeros(2)]),  # Fc: no crossing
    direction=st.sampled_from([0, 2, None, "1", 1.5, NAN, True]), **SF_BAD))
ROWS += rows_for("dahl.reversal_abscissa", dahl.reversal_abscissa, dict(F_i=-0.5, **SF), dict(
    F_i=bad_array_outside(-1.0, 1.0) | st.sampled_from([1.0]), **SF_BAD))
ROWS += rows_for("dahl.branch_energy", dahl.branch_energy, dict(x=X3, **SF), dict(
    x=bad_array | st.sampled_from([-1.0, 1e306, [0.0, -1e10]]), **SF_BAD))
ROWS += rows_for("dahl.potential_energy", dahl.potential_energy, dict(F=[-0.5, 0.3], **SF), dict(
    F=bad_array_outside(-1.0, 1.0), **SF_BAD))
ROWS += rows_for("dahl.max_potential_energy", dahl.max_potential_energy, dict(**SF), dict(**SF_BAD))
ROWS += [Row("dahl.max_potential_energy-overflow", dahl.max_potential_energy, dict(sigma=1e-300), "Fc",
             st.sampled_from([1e200, 1e300]))]
ROWS += rows_for("dahl.next_amplitude", dahl.next_amplitude, dict(a=[0.1, 0.9]), dict(a=bad_array_outside(0.0, 1.0)))
ROWS += rows_for("dahl.next_amplitude_paper", dahl.next_amplitude_paper, dict(a=[0.1, 0.9]), dict(
    a=bad_array_outside(0.0, 1.0), sigma_over_Fc=bad_positive.filter(lambda v: v is not None)))
ROWS += rows_for("dahl.next_reversal_position_paper", dahl.next_reversal_position_paper,
                 dict(F_i=-0.5, **SF, printed=False), dict(
    F_i=bad_array_outside(-1.0, 0.0), printed=bad_bool, **SF_BAD))
ROWS += rows_for("dahl.omega", dahl.omega, dict(x=X3, **SF), dict(
    x=bad_array | st.sampled_from([-1.0, [1e306], -1e308]), **SF_BAD))
ROWS += rows_for("dahl.omega_star", dahl.omega_star, dict(x=X3, F_i=-0.5, **SF), dict(
    x=bad_array | st.sampled_from([1e306, -1e308]),
    F_i=bad_array_outside(-1.0, 0.0) | st.sampled_from([np.zeros(2)]), **SF_BAD))
ROWS += rows_for("dahl.amplitude_sequence", dahl.amplitude_sequence, dict(a0=0.5, n=10), dict(
    a0=bad_real | st.sampled_from([-0.1, 1.5, 1e300]), n=bad_count(0, dahl.MAX_STEPS)))
ROWS += rows_for("dahl.asymptotic_amplitude", dahl.asymptotic_amplitude, dict(n=[1, 10], a0=1.0), dict(
    n=bad_array | st.sampled_from([-1, [-2.0]]), a0=bad_real | st.sampled_from([0.0, -0.5, 1.5])))

# exact references ---------------------------------------------------------------------------
EXACT_BAD = dict(system=bad_system, v0=bad_real | st.sampled_from([1e300, -1e200, 1e160]),
                 n=bad_count(1, MAX_REVERSALS), x0=bad_real, F0=bad_real | st.sampled_from([1.5, -2.0, 1e300]))
ROWS += rows_for("exact_reversals", pf.exact_reversals, dict(system=SYSTEM, v0=0.01, n=5, x0=0.0, F0=0.0), EXACT_BAD)
ROWS += [Row("exact_reversals-v0-rest", pf.exact_reversals, dict(system=SYSTEM, n=5, F0=0.0), "v0",
             st.sampled_from([0.0, -0.0, 1e-320]))]
MS_BAD = dict(EXACT_BAD, system=bad_ms_system, n=bad_count(1, mse.MAX_REVERSALS))
ROWS += rows_for("maxwell_slip_reversals", mse.maxwell_slip_reversals,
                 dict(system=MS_SYSTEM, v0=1.0, n=5, x0=0.0, F0=0.0), MS_BAD)
ROWS += rows_for("maxwell_slip_trajectory", mse.maxwell_slip_trajectory,
                 dict(system=MS_SYSTEM, v0=1.0, n=5, x0=0.0, F0=0.0), MS_BAD)
ROWS += rows_for("exact_reversals-ms", pf.exact_reversals, dict(system=MS_SYSTEM, v0=1.0, n=5),
                 dict(v0=MS_BAD["v0"], n=MS_BAD["n"], F0=MS_BAD["F0"]))
ROWS += rows_for("masing_amplitudes", mse.masing_amplitudes, dict(model=MS, a1=0.5, n=5), dict(
    model=bad_ms_model, a1=bad_real | st.sampled_from([-0.1, 1.5]), n=bad_count(1, mse.MAX_REVERSALS)))
ROWS += rows_for("masing_next", mse.masing_next, dict(model=MS, a=[0.2, 0.5]), dict(
    model=bad_ms_model, a=bad_array_outside(0.0, 1.0)))
ROWS += rows_for("first_reversal", mse.first_reversal, dict(model=MS, E0=0.3), dict(
    model=bad_ms_model, E0=bad_nonneg))
ROWS += rows_for("dissipation_limit", mse.dissipation_limit, dict(model=MS), dict(model=bad_ms_model))
ROWS += rows_for("Scales.of", Scales.of, dict(system=SYSTEM), dict(system=st.sampled_from([None, 3, "dahl", DAHL])))
ROWS += [Row("Scales.of-range", lambda sigma, Fc, mass: Scales.of(pf.Oscillator(pf.Dahl(sigma, Fc), mass=mass)),
             dict(sigma=1e308, mass=1.0), "Fc", st.sampled_from([1e-308, 5e-324]))]
ROWS += rows_for("Scales", Scales, dict(x=1e-4, F=1.0, t=1e-2, v=1e-2, E=1e-4), dict(
    x=bad_positive, F=bad_positive, t=bad_positive, v=bad_positive, E=bad_positive))

# models -------------------------------------------------------------------------------------
ROWS += rows_for("Dahl", pf.Dahl, dict(sigma=1e4, Fc=1.0, gamma=1.0), dict(
    sigma=bad_positive, Fc=bad_positive, gamma=bad_nonneg))
MS_ARRAY_BAD = bad_array | st.sampled_from([[], [1.0, 2.0], [1.0] * 65, [[1.0, 2.0, 3.0]], [1.0, -1.0, 2.0],
                                             [1.0, 0.0, 2.0]])
ROWS += rows_for("MaxwellSlip", pf.MaxwellSlip, dict(stiffness=[6e3, 3e3, 1e3], slip_force=[0.5, 0.3, 0.2]), dict(
    stiffness=MS_ARRAY_BAD, slip_force=MS_ARRAY_BAD))
GMS_BASE = dict(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=2e3, sigma2=0.0,
                damping=None, delta=2.0)
ROWS += rows_for("GMS", pf.GMS, GMS_BASE, dict(
    k=MS_ARRAY_BAD, alpha=MS_ARRAY_BAD | st.sampled_from([[0.2, 0.3, 0.6]]), Fc=bad_positive,
    Fs=bad_positive | st.sampled_from([0.5]), vs=bad_positive, C=bad_positive, sigma2=bad_nonneg,
    damping=bad_array.filter(lambda v: v is not None) | st.sampled_from([[1.0, 2.0], [-1.0, 0.0, 0.0], "1"]),
    delta=bad_positive))
ROWS += rows_for("LuGre", pf.LuGre, dict(sigma0=1e5, sigma1=300.0, sigma2=0.4, Fc=1.0, Fs=1.5, vs=1e-3), dict(
    sigma0=bad_positive, sigma1=bad_nonneg, sigma2=bad_nonneg, Fc=bad_positive,
    Fs=bad_positive | st.sampled_from([0.5]), vs=bad_positive))
BAD_SAMPLES = st.sampled_from([([0.0, 1.0, 0.5], [0.0, 1.0, 2.0]), ([0.0, 1.0], [0.0, 1.0, 2.0]),
                               ([0.0, NAN], [1.0, 2.0]), ([0.0, 1.0], [1.0, INF]), ([0.0], [1.0]), ([], []),
                               ([0.0, 1.0, 2.0],), ("ab", "cd"), ([0.0, 0.0], [1.0, 2.0])])
ROWS += rows_for("Oscillator", pf.Oscillator, dict(friction=DAHL, mass=1.0, u=None), dict(
    friction=st.sampled_from([None, 3, "dahl", SYSTEM, pf.Dahl]), mass=bad_positive,
    u=BAD_SAMPLES | st.sampled_from([NAN, INF, "fast", 1 + 1j, [1.0, 2.0], np.zeros(3), {}, True])))

# signals ------------------------------------------------------------------------------------
ROWS += rows_for("signals.Constant", signals.Constant, dict(value=1.0), dict(value=bad_real))
ROWS += rows_for("signals.Step", signals.Step, dict(time=0.1, before=0.0, after=1.0), dict(
    time=bad_real, before=bad_real, after=bad_real))
ROWS += rows_for("signals.Ramp", signals.Ramp, dict(time=0.1, slope=1.0, offset=0.0), dict(
    time=bad_real, slope=bad_real, offset=bad_real))
ROWS += rows_for("signals.Sine", signals.Sine, dict(amplitude=1.0, frequency=2.0, phase=0.0, offset=0.0), dict(
    amplitude=bad_real, frequency=bad_real, phase=bad_real, offset=bad_real))
ROWS += rows_for("signals.Chirp", signals.Chirp, dict(amplitude=1.0, f0=1.0, f1=10.0, duration=1.0), dict(
    amplitude=bad_real, f0=bad_real, f1=bad_real, duration=bad_positive))
ROWS += rows_for("signals.Samples", signals.Samples, dict(t=[0.0, 1.0, 2.0], u=[0.0, 1.0, 0.5]), dict(
    t=bad_array | st.sampled_from([[0.0, 2.0, 1.0], [0.0, 1.0], [], [0.0, 0.0, 1.0]]),
    u=bad_array | st.sampled_from([[0.0, 1.0], []])))
ROWS += rows_for("signals.Traced", signals.Traced, dict(fun=math.sin), dict(fun=st.sampled_from([None, 3, "sin"])))
ROWS += [Row("signals.as_signal-value", signals.as_signal, dict(name="u", unit="N"), "value",
             BAD_SAMPLES | st.sampled_from([NAN, "fast", 1 + 1j, [1.0], {}]), names="u")]
ROWS += rows_for("Signal.__call__", lambda t: signals.Sine(1.0, 2.0)(t), dict(t=0.5), dict(
    t=bad_array | st.sampled_from([NAN, INF, "fast", None, 1 + 1j])))

# prefriction.testing ------------------------------------------------------------------------
ROWS += rows_for("testing.reference_reversals", testing.reference_reversals,
                 dict(model=DAHL, v0=1.5, n=3, rtol=1e-10, method="DOP853"), dict(
    model=bad_model, v0=bad_real | st.sampled_from([0.0, 1e300]), n=bad_count(1, MAX_REVERSALS),
    rtol=bad_positive | st.sampled_from([1.0, 1e-20]), method=bad_str))
ROWS += rows_for("testing.check_model", testing.check_model,
                 dict(model=DAHL, v0=1.5, reversals=3, rtol=1e-8, tol_factor=20.0, seed=0), dict(
    model=bad_model, v0=bad_real | st.sampled_from([0.0, 1e300]), reversals=bad_count(1, MAX_REVERSALS),
    rtol=bad_positive | st.sampled_from([1.0, 1e-20]), tol_factor=bad_positive, seed=bad_count(0)))

# simulation ---------------------------------------------------------------------------------
SIM_BASE = dict(system=SYSTEM, v0=0.01, x0=0.0, F0=0.0, reversals=5, t_end=None, rtol=1e-8, atol=None, method="erk",
                dense=False, feedback=None, jit=True)
ROWS += rows_for("simulate", pf.simulate, SIM_BASE, dict(
    system=st.sampled_from([None, 3, "dahl", DAHL, [SYSTEM]]),
    v0=bad_real | st.sampled_from([1e300, -1e200]),
    x0=bad_real, F0=bad_real | st.sampled_from([1.5, -2.0]),
    reversals=bad_count(1, 10**9),
    t_end=bad_positive.filter(lambda v: v is not None),
    rtol=bad_positive | st.sampled_from([1.0, 1e-20]), atol=bad_positive.filter(lambda v: v is not None),
    method=bad_str, dense=st.sampled_from(["yes", 3, NAN, [0.2, 0.1], [NAN], np.array([[0.1]])]),
    feedback=st.sampled_from([3, "pid", SYSTEM]), jit=bad_bool))
ROWS += [Row("simulate-overflowing-units", pf.simulate, dict(SIM_BASE, system=pf.Oscillator(pf.Dahl(1e308, 1e-300))),
             "v0", st.sampled_from([0.01]), names="sigma"),
         Row("simulate-dense-unsorted", pf.simulate, dict(SIM_BASE, reversals=None, t_end=1.0), "dense",
             st.sampled_from([[0.0, 0.5, 0.2], [0.0, 2.0], [NAN], "fast"])),
         Row("simulate-sampled-Ts", lambda Ts: pf.simulate(SYSTEM, 0.01, t_end=1.0, feedback=pf.LinearFeedback(
             D=1e3, Ts=Ts)), dict(), "Ts", bad_positive.filter(lambda v: v is not None) | st.sampled_from([1e-300, 1e-12, 1e-9]))]
FB_BASE = dict(A=[[0.0]], B=[[1.0]], C=[[1.0]], D=1.0, Ts=None, reference=0.0, xc0=None)
ROWS += rows_for("LinearFeedback", pf.LinearFeedback, FB_BASE, dict(
    A=bad_array | st.sampled_from([np.zeros((2, 2)), [[1.0, 2.0]]]), B=bad_array, C=bad_array, D=bad_array,
    Ts=bad_positive.filter(lambda v: v is not None), reference=BAD_SAMPLES | st.sampled_from([NAN, "fast", 1 + 1j]),
    xc0=bad_array.filter(lambda v: v is not None) | st.sampled_from([[0.0, 0.0]])))
SWEEP = "prefriction/simulation/sweep.py"
ROWS += rows_for("sweep", pf.sweep, dict(systems=[SYSTEM, SYSTEM], v0=0.01, reversals=5, progress=False), dict(
    systems=st.sampled_from([None, 3, "ab", SYSTEM, [], [SYSTEM, 3], [DAHL], iter([])]),
    v0=bad_real.filter(lambda v: not isinstance(v, np.ndarray)) | st.sampled_from([[0.1], [0.1, NAN], [0.1, "x"], [0.1, 0.2, 0.3]]),
    executor=st.sampled_from([3, "pool", SYSTEM]), progress=bad_bool.filter(lambda v: v is not None),
    reversals=bad_count(1).filter(lambda v: v is not None), rtol=bad_positive, method=bad_str, jit=bad_bool,
    x0=bad_real, F0=bad_real))
ROWS += [Row("sweep-unknown-keyword", lambda **kw: pf.sweep([SYSTEM], 0.01, reversals=5, **kw), dict(), "revs",
             st.sampled_from([3, None]))]
ROWS += rows_for("ReversalTable", pf.ReversalTable,
                 dict(t=[1.0, 2.0], x=[0.1, -0.1], F=[0.5, -0.4], E_p=[0.1, 0.05], E_d=[0.1, 0.05], E_0=0.3),
                 dict(t=st.sampled_from([[2.0, 1.0], [1.0, NAN], [1.0], "ab", None]),
                      x=st.sampled_from([[0.1], [NAN, 0.0], None]), E_0=bad_real | st.sampled_from([-1.0])))

# energy analysis ----------------------------------------------------------------------------
T = np.linspace(0.0, 1.0, 201)
V = 0.01 * np.cos(2 * np.pi * T)
XS = 0.01 / (2 * np.pi) * np.sin(2 * np.pi * T)
FS = 0.5 * np.sin(2 * np.pi * T)
TABLE = pf.exact_reversals(SYSTEM, 0.01, 5)
en = pf.energy
bad_samples = bad_array | st.sampled_from([T[:-1], np.zeros((2, 3)), []])
bad_times = bad_samples | st.sampled_from([np.concatenate([T[:100], T[99:200]])])
ROWS += rows_for("energy.find_reversals", en.find_reversals, dict(t=T, v=V, x=XS, F=FS), dict(
    t=bad_times, v=bad_samples, x=bad_samples.filter(lambda v: v is not None), F=bad_samples.filter(lambda v: v is not None)))
ROWS += rows_for("energy.analyze_samples", en.analyze_samples, dict(t=T, x=XS, v=V, F=FS, system=SYSTEM, method="trapezoid"),
                 dict(t=bad_times, x=bad_samples, v=bad_samples, F=bad_samples | st.sampled_from([3 * FS]),
                      system=bad_system_any, method=bad_str))
ROWS += rows_for("energy.analyze_table", en.analyze_table, dict(table=TABLE, system=SYSTEM), dict(
    table=st.sampled_from([None, 3, "t", SYSTEM]), system=bad_system_any))
ROWS += rows_for("energy.bound_check", en.bound_check, dict(E_p=TABLE.E_p, friction=DAHL, E_0=TABLE.E_0), dict(
    E_p=bad_array | st.sampled_from([[-1.0]]), friction=bad_model,
    E_0=bad_real.filter(lambda v: v is not None) | st.sampled_from([-1.0, -1e-300])))
ROWS += rows_for("energy.branch_energy", en.branch_energy, dict(F=[0.5, -0.3], direction=[1, -1], friction=DAHL), dict(
    F=bad_array | st.sampled_from([[2.0, 0.0]]), direction=bad_array | st.sampled_from([[0, 1], [2, 1], [1, 1, 1]]),
    friction=bad_model))
ROWS += rows_for("energy.dissipation", en.dissipation, dict(E_p=TABLE.E_p, input_work=None), dict(
    E_p=bad_array, input_work=bad_array.filter(lambda v: v is not None) | st.sampled_from([[0.0]])))
ROWS += rows_for("energy.series", en.series, dict(E_p=TABLE.E_p, E_d=TABLE.E_d), dict(
    E_p=bad_array, E_d=bad_array | st.sampled_from([[0.0]])))
ROWS += rows_for("energy.integrated_power", en.integrated_power,
                 dict(t=T, v=V, F=FS, method="trapezoid", reset_at_reversals=False), dict(
    t=bad_times, v=bad_samples, F=bad_samples, method=bad_str, reset_at_reversals=bad_bool))
ROWS += rows_for("energy.kinetic_energy", en.kinetic_energy, dict(v=V, mass=1.0), dict(v=bad_array, mass=bad_positive))
ROWS += rows_for("energy.loop_integral", en.loop_integral, dict(x=XS, F=FS, closure_tol=1e-6), dict(
    x=bad_samples, F=bad_samples, closure_tol=bad_nonneg))
ROWS += rows_for("energy.total_energy", en.total_energy, dict(t=T, v=V, F=FS, system=SYSTEM), dict(
    t=bad_times, v=bad_samples, F=bad_samples, system=bad_system_any))
ROWS += rows_for("energy.work_integral", en.work_integral, dict(x=XS, F=FS), dict(x=bad_samples, F=bad_samples))

# controllers --------------------------------------------------------------------------------
from prefriction import controllers as ctl  # noqa: E402

PIDC = ctl.pd(1e5, 300.0, tau=1e-4)
STAGE = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0), mass=1.0)
ROWS += rows_for("controllers.PID", ctl.PID, dict(kp=1e5, ki=0.0, kd=300.0, tau=1e-4, N=10.0, u_max=None, t_track=None),
                 dict(kp=bad_nonneg, ki=bad_nonneg, kd=bad_nonneg, tau=bad_positive.filter(lambda v: v is not None),
                      N=bad_positive, u_max=bad_positive.filter(lambda v: v is not None),
                      t_track=bad_positive.filter(lambda v: v is not None)))
ROWS += rows_for("controllers.pd", ctl.pd, dict(kp=1e5, kd=300.0, tau=1e-4, N=10.0), dict(
    kp=bad_nonneg, kd=bad_nonneg, tau=bad_positive.filter(lambda v: v is not None), N=bad_positive))
ROWS += rows_for("controllers.pid", ctl.pid, dict(kp=1e5, ki=1e6, kd=300.0, tau=1e-4), dict(
    kp=bad_nonneg, ki=bad_nonneg, kd=bad_nonneg))
ROWS += rows_for("controllers.design_pd", ctl.design_pd, dict(system=STAGE, wn=300.0, zeta=0.7, regime="presliding", N=10.0),
                 dict(system=bad_system_any, wn=bad_positive, zeta=bad_real | st.sampled_from([-0.1, 11.0]),
                      regime=bad_str, N=bad_positive))
ROWS += rows_for("controllers.design_pid", ctl.design_pid, dict(system=STAGE, wn=300.0), dict(
    system=bad_system_any, wn=bad_positive, alpha=bad_positive, u_max=bad_positive.filter(lambda v: v is not None)))
ROWS += rows_for("controllers.linear_plant", ctl.linear_plant, dict(system=STAGE, regime="presliding", Ts=None), dict(
    system=bad_system_any, regime=bad_str, Ts=bad_positive.filter(lambda v: v is not None)))
ROWS += rows_for("controllers.closed_loop", ctl.closed_loop, dict(system=STAGE, controller=PIDC, regime="presliding", warn=True),
                 dict(system=bad_system_any, controller=st.sampled_from([None, 3, "pid", STAGE]), regime=bad_str, warn=bad_bool))
ROWS += rows_for("controllers.margins", ctl.margins, dict(system=STAGE, controller=PIDC, regime="presliding"), dict(
    system=bad_system_any, controller=st.sampled_from([None, 3, "pid", STAGE]), regime=bad_str))
ROWS += rows_for("controllers.plant_iosys", ctl.plant_iosys, dict(system=STAGE, Ts=None, solve_ivp_kwargs=None), dict(
    system=bad_system_any, Ts=bad_positive.filter(lambda v: v is not None), solve_ivp_kwargs=st.sampled_from([3, "rk", [1]])))
ROWS += rows_for("controllers.simulate_loop", ctl.simulate_loop,
                 dict(system=STAGE, controller=PIDC, reference=1e-5, t_end=0.01, Ts=None, discretization="zoh",
                      x0=0.0, v0=0.0, F0=0.0, xc0=None, t_out=None, rtol=1e-8, jit=True), dict(
    system=bad_system_any, controller=st.sampled_from([None, 3, "pid", STAGE]),
    reference=BAD_SAMPLES | st.sampled_from([NAN, "fast", 1 + 1j]), t_end=bad_positive,
    Ts=bad_positive.filter(lambda v: v is not None) | st.sampled_from([1e-300, 1e-12]), discretization=bad_str,
    x0=bad_real, v0=bad_real, F0=bad_real | st.sampled_from([2.0]), xc0=bad_array.filter(lambda v: v is not None),
    t_out=bad_times.filter(lambda v: v is not None), rtol=bad_positive, jit=bad_bool))

# command line -------------------------------------------------------------------------------
TABLE_BAD = {
    "--sigma": ["nan", "-1", "0", "abc", "inf", "1e-320"], "--Fc": ["nan", "-1", "0", "x"], "--mass": ["0", "-2", "inf"],
    "--gamma": ["-1", "nan", "inf"], "--v0": ["nan", "1e300", "inf", "x"], "--F0": ["2", "-1.5", "nan"],
    "--x0": ["nan", "inf"], "--n": ["0", "-1", "1000000000", "2.5", "x"], "--rows": ["-1", "0", "x"],
}
CLI_BAD = [("table", opt, vals, None) for opt, vals in TABLE_BAD.items()] + [
    ("bench", "--repeats", ["0", "-1", "x", "1000000000"], None),
    ("bench", "--out", ["/proc/no/such/dir", "/dev/null/x"], None),
    ("paper", "--out", ["/proc/no/such/dir", "/dev/null/x"], None),
]


def run_cli(argv: list[str]) -> tuple[int, str]:
    """``prefriction.cli.main(argv)``: exit code (return value or ``SystemExit``) and all output."""
    from prefriction.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    return code, out.getvalue() + err.getvalue()


@pytest.mark.parametrize("command, option, values", [
    pytest.param(c, o, v, id=f"{c}{o}", marks=[pytest.mark.xfail(strict=True, reason=f"owner: {w}")] if w else [])
    for c, o, v, w in CLI_BAD])
def test_command_line_refuses_bad_option(command: str, option: str, values: list[str]) -> None:
    for value in values:
        with time_guard():
            code, text = run_cli([command, option, value])
        assert code == 2, f"prefriction {command} {option} {value}: exit code {code}, output {text[-300:]!r}"
        assert names_argument(text, option.lstrip("-")) or option in text, (
            f"prefriction {command} {option} {value}: the message does not name {option}: {text[-300:]!r}")
        assert "Traceback" not in text


@pytest.mark.parametrize("row", [r.param() for r in ROWS])
def test_bad_value_is_refused_naming_the_argument(row: Row) -> None:
    @settings(max_examples=row.examples, deadline=None, database=None, derandomize=True, report_multiple_bugs=False,
              phases=[Phase.explicit, Phase.generate],  # no shrinking: the bad value is already small
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
    @given(bad=row.bad)
    def check(bad: Any) -> None:
        kwargs = dict(row.base, **{row.arg: bad})
        try:
            with time_guard():
                out = row.fn(**kwargs)
        except (ValueError, TypeError) as exc:
            name = row.names or row.arg
            if not names_argument(str(exc), name):
                pytest.fail(f"{row.id}: {row.arg}={bad!r}: {type(exc).__name__} does not name {name!r}: {exc}",
                            pytrace=False)
            return
        except Exception as exc:  # noqa: BLE001 -- any other exception fails the row
            pytest.fail(f"{row.id}: {row.arg}={bad!r} raised {type(exc).__name__}: {exc}", pytrace=False)
        pytest.fail(f"{row.id}: {row.arg}={bad!r} accepted, returned {_short(out)}", pytrace=False)

    check()


def _short(value: Any) -> str:
    try:
        text = repr(value)
    except Exception as exc:  # noqa: BLE001 -- a broken repr is reported, not raised
        text = f"<{type(value).__name__} whose repr raised {type(exc).__name__}: {exc}>"
    return text if len(text) < 200 else text[:197] + "..."
