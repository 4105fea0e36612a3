"""simulate(): input validation, solver failures, JIT cache and the no-compiler fallback."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import re
import textwrap
import time

import numpy as np
import pytest

import prefriction as pf
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.compiled import compiled

SYS = pf.Oscillator(pf.Dahl(1e4, 1.0))


def test_unknown_keyword_raises_type_error() -> None:
    with pytest.raises(TypeError):
        pf.simulate(SYS, 1.0, reversals=3, tolerance=1e-6)  # type: ignore[call-arg]


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        ({}, ValueError, "reversals .* t_end"),
        ({"reversals": 0}, ValueError, "reversals must be an integer >= 1"),
        ({"reversals": 2.5}, TypeError, "reversals must be an integer"),
        ({"t_end": -1.0}, ValueError, "t_end must be finite and > 0"),
        ({"reversals": 3, "rtol": 1e-1}, ValueError, r"rtol must lie in \[1e-13, 1e-2\]"),
        ({"reversals": 3, "rtol": 0.0}, ValueError, "rtol must be finite and > 0"),
        ({"reversals": 3, "atol": 1.0}, ValueError, "atol must lie in"),
        ({"reversals": 3, "method": "cvodes"}, ValueError, "method must be one of"),
        ({"reversals": 3, "F0": 1.5}, ValueError, r"F0 must lie in \[-1.0, 1.0\] N \(the model.s max_hysteretic_force, Dahl\), got 1.5"),
        ({"reversals": 3, "F0": 1.0}, ValueError, "reaches only asymptotically"),
        ({"reversals": 3, "x0": float("nan")}, ValueError, "x0 must be finite"),
        ({"reversals": 3, "feedback": "pid"}, TypeError, "feedback must be"),
        ({"reversals": 3, "jit": 1}, TypeError, "jit must be True or False"),
        ({"t_end": 1.0, "dense": [0.0, 2.0]}, ValueError, "dense sample times"),
        ({"t_end": 1.0, "dense": [[0.0]]}, ValueError, "dense must be"),
    ],
)
def test_invalid_arguments(kwargs: dict, exc: type, match: str) -> None:
    with pytest.raises(exc, match=match):
        pf.simulate(SYS, 1.0, **kwargs)


def test_invalid_system_and_v0() -> None:
    with pytest.raises(TypeError, match="Oscillator"):
        pf.simulate(pf.Dahl(1.0, 1.0), 1.0, reversals=2)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="v0 must be a real number"):
        pf.simulate(SYS, "fast", reversals=2)  # type: ignore[arg-type]
    # a denormal v0 (reversal times were 12 % wrong) or one whose scaled states leave the double range
    for v0 in (5e-324, 1e-300, -1e-200):
        with pytest.raises(ValueError, match=rf"v0 = {v0!r} m/s .* must be 0 or >= 1e-150, that is \|v0\| >= 1e-152 m/s"):
            pf.simulate(SYS, v0, reversals=2)


def test_forced_needs_t_end_and_rest_needs_t_end() -> None:
    with pytest.raises(ValueError, match="t_end is required"):
        pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), u=lambda t: 0.1 + 0 * t), 0.0, reversals=3)
    with pytest.raises(ValueError, match="rests"):
        pf.simulate(SYS, 0.0, reversals=3)
    with pytest.raises(ValueError, match="sampled controller"):
        pf.simulate(SYS, 0.0, t_end=1.0, dense=True, feedback=LinearFeedback(D=1.0, Ts=0.1))


def test_feedback_validation() -> None:
    with pytest.raises(ValueError, match=r"B must have shape \(1, 1\)"):
        LinearFeedback(A=[[0.0]], B=[[1.0, 2.0]], C=[[1.0]], D=0.0)
    with pytest.raises(ValueError, match="Ts must be finite and > 0"):
        LinearFeedback(D=1.0, Ts=0.0)
    with pytest.raises(ValueError, match="strictly increasing"):
        LinearFeedback(D=1.0, reference=(np.array([0.0, 0.0]), np.array([1.0, 2.0])))


def test_solver_failure_raises_solver_error_naming_time_and_state() -> None:
    """An input that becomes NaN at t = 0.01 s makes the integrator fail: SolverError, no NaN result.

    Deliberately a plain Python callable (no parametric signal becomes NaN), traced into the plant
    (prefriction.signals.Traced); interpreted (jit=False), so that it costs the suite no compile."""
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0), u=lambda t: 0.5 * np.sqrt(0.01 - t))
    with pytest.raises(pf.SolverError) as info, np.errstate(invalid="ignore"):
        pf.simulate(sys_, 0.1, t_end=0.05, jit=False)
    msg = str(info.value)
    assert "t = " in msg and "x = " in msg and "v = " in msg and "F = " in msg and "Try" in msg


def test_no_compiler_fallback_gives_the_same_table(monkeypatch: pytest.MonkeyPatch) -> None:
    """PREFRICTION_NO_JIT=1: the interpreted integrator, same reversal table to round-off."""
    ref = pf.simulate(SYS, 1.0, reversals=20, rtol=3e-9)
    monkeypatch.setenv("PREFRICTION_NO_JIT", "1")
    res = pf.simulate(SYS, 1.0, reversals=20, rtol=3.0000001e-9)
    assert res.stats.jit == "interpreted" and res.stats.steps is not None and res.stats.steps > 0
    np.testing.assert_allclose(res.reversals.F, ref.reversals.F, rtol=1e-7)
    np.testing.assert_allclose(res.reversals.t, ref.reversals.t, rtol=1e-9)


def test_missing_compiler_falls_back(monkeypatch: pytest.MonkeyPatch) -> None:
    import casadi as ca

    monkeypatch.setenv("CC", "/nonexistent/cc")
    x = ca.SX.sym("x")
    fun = ca.Function("f_nocc", [x], [2 * x])
    out, info = compiled(fun)
    assert out is fun and info.mode == "interpreted" and "compiler" in info.reason


SCRIPT = textwrap.dedent(
    """
    import json, sys, time
    import prefriction as pf
    sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0, 2.0))
    r = pf.simulate(sys_, 1.0, reversals=5, rtol=2.5e-7)
    print(json.dumps({"jit": r.stats.jit, "setup": r.stats.setup_time, "F": list(r.reversals.F)}))
    """
)


def test_second_process_reuses_compiled_code(tmp_path) -> None:
    """The compiled library is cached on disk: a second process loads it instead of compiling."""
    env = {**os.environ, "PREFRICTION_CACHE": str(tmp_path)}
    env.pop("PREFRICTION_NO_JIT", None)
    runs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True,
                             timeout=300, check=True)
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    assert runs[0]["jit"] == "compiled"
    assert runs[1]["jit"] == "cached"
    assert runs[1]["setup"] < runs[0]["setup"]
    assert len(list(tmp_path.glob("*.so"))) == 1
    assert runs[0]["F"] == runs[1]["F"]


def test_sizes_and_amplitudes_beyond_the_limits_are_refused_before_any_work() -> None:
    """A huge ``v0``, more reversals than :data:`MAX_REVERSALS`, a sampled controller with more
    than :data:`MAX_PERIODS` periods and an unconvertible ``dense`` are refused with the limit."""
    from prefriction.simulation.simulate import MAX_AMPLITUDE, MAX_PERIODS, MAX_REVERSALS

    system = pf.Oscillator(pf.Dahl(1e4, 1.0), 1.0)
    v_max = MAX_AMPLITUDE * pf.Scales.of(system).v
    with pytest.raises(ValueError, match=re.escape(f"v0 must satisfy |v0| <= {v_max:.3g} m/s") + r".*got -1e\+200"):
        pf.simulate(system, -1e200, reversals=2)
    with pytest.raises(ValueError, match=rf"reversals must be an integer <= {MAX_REVERSALS:_}.*held in memory"):
        pf.simulate(system, 0.01, reversals=MAX_REVERSALS + 1)
    with pytest.raises(ValueError, match=r"Ts = 1e-09 s .* 1e\+09 sample periods; allowed at most 10_000_000"):
        pf.simulate(system, 0.01, t_end=1.0, feedback=pf.LinearFeedback(D=1e3, Ts=1e-9))
    assert MAX_PERIODS == 10**7
    with pytest.raises(TypeError, match="dense must be True, False or a 1-D array of sample times"):
        pf.simulate(system, 0.01, t_end=1.0, dense="fast")


def test_one_size_budget_for_runs_that_grow(monkeypatch) -> None:
    """A t_end run that a fast input would fill beyond the table's budget is refused up front; one
    that reaches the budget anyway (unforced Dahl keeps reversing) stops there with the time reached."""
    import prefriction as pf
    from prefriction.simulation import simulate as sim_module

    start = time.perf_counter()
    allowed = f"{sim_module.MAX_REVERSALS / 2e9:g}".replace(".", r"\.")  # two reversals per period of 1 GHz
    with pytest.raises(ValueError, match=rf"allows about 2e\+09 reversals.*t_end <= {allowed} s"):
        pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), u=pf.signals.Sine(1.0, 1e9)), 0.0, t_end=1.0)
    with pytest.raises(ValueError, match="allows about"):
        pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), u=pf.signals.Sine(0.5, 1.0) + pf.signals.Sine(0.1, 1e8)),
                    0.0, t_end=1.0)
    assert time.perf_counter() - start < 5.0
    monkeypatch.setattr(sim_module, "MAX_REVERSALS", 300)
    with pytest.raises(ValueError, match=r"t_end = 1e\+09 s needs more than 300 reversals.*reached 300 at t = "):
        pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0, 2.0)), 1.0, t_end=1e9)


def test_motion_that_dies_out_says_so_and_asks_for_t_end() -> None:
    """An overdamped LuGre oscillator creeps to rest after one reversal: the second never comes.

    Independent reference: scipy Radau (rtol 1e-12) from the equations. After the reversal at
    0.7678 s the velocity decays ten-fold about every 0.23 s and changes sign again only at the
    level of its absolute tolerance (|v| ~ 1e-22 m/s near 4.5 s): no reversal. The old CasADi
    loop reported one there (F = 2.7e-17 N); a reversal at 1e-8 of the branch's amplitude is
    now taken as the mass at rest.
    """
    import prefriction as pf
    from scipy.integrate import solve_ivp

    s0, s1, s2, Fc, Fs, vs = 1e5, 1e4, 0.4, 1.0, 1.5, 1e-3

    def rhs(t: float, y: np.ndarray) -> list:
        v, z = y[1], y[2]
        g = (Fc + (Fs - Fc) * np.exp(-(v / vs) ** 2)) / s0
        dz = v - abs(v) * z / g
        return [v, -(s0 * z + s1 * dz + s2 * v), dz]

    ref = solve_ivp(rhs, [0.0, 3.0], [0.0, 1.0, 0.0], method="Radau", rtol=1e-12, atol=1e-18, dense_output=True)
    t = np.linspace(0.5, 3.0, 250_001)
    v = ref.sol(t)[1]
    crossings = t[np.flatnonzero(np.diff(np.sign(v)) != 0)]
    assert crossings.size == 1 and np.all(np.abs(v[t > 2.0]) < 1e-9)  # one reversal, then the creep

    system = pf.Oscillator(pf.LuGre(s0, s1, s2, Fc, Fs, vs))
    with pytest.raises(pf.SolverError, match=r"died out after 1 reversal \(.*Give t_end"):
        pf.simulate(system, 1.0, reversals=5)
    res = pf.simulate(system, 1.0, t_end=100.0)
    assert res.status == 0 and len(res.reversals) == 1
    assert res.reversals.t[0] == pytest.approx(crossings[0], abs=2e-5)
