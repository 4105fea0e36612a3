"""Every public function of ``prefriction.energy`` refuses bad input with ``TypeError`` or
``ValueError`` naming the argument (issue 10): ``None``, strings, complex numbers, NaN, inf,
negative energies, empty arrays, mismatched lengths and unsorted times, at any position."""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import prefriction as pf
from prefriction import energy

DAHL = pf.Dahl(1.0, 1.0)
SYSTEM = pf.Oscillator(DAHL, mass=1.0)
LUGRE = pf.Oscillator(pf.LuGre(1e5, 316.0, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
N = 40
T = np.linspace(0.0, 2.0 * math.pi, N)
X = 0.5 * np.sin(T)
V = 0.5 * np.cos(T)
F = 0.5 * np.sin(T)  # |F| < Fc: a valid (if not physical) sample set with reversals
E_P = np.array([0.3, 0.2, 0.1, 0.05])
TABLE = pf.exact_reversals(SYSTEM, 1.0, 4)


def valid_calls():
    """Function name -> (callable, valid keyword arguments, kind of each argument)."""
    samples = {"t": "times", "v": "array", "F": "array"}
    return {
        "find_reversals": (energy.find_reversals, dict(t=T, v=V, x=X, F=F), {"t": "times", "v": "array", "x": "array", "F": "array"}),
        "kinetic_energy": (energy.kinetic_energy, dict(v=V, mass=1.0), {"v": "array", "mass": "positive"}),
        "integrated_power": (energy.integrated_power, dict(t=T, v=V, F=F), samples),
        "work_integral": (energy.work_integral, dict(x=X, F=F), {"x": "array", "F": "array"}),
        "loop_integral": (energy.loop_integral, dict(x=np.append(X, X[0]), F=np.append(F, F[0]), closure_tol=1e-6),
                          {"x": "array", "F": "array", "closure_tol": "nonnegative"}),
        "branch_energy": (energy.branch_energy, dict(F=F, direction=1.0, friction=DAHL), {"F": "array", "direction": "array"}),
        "total_energy": (energy.total_energy, dict(t=T, v=V, F=F, system=SYSTEM), samples),
        "dissipation": (energy.dissipation, dict(E_p=E_P, input_work=np.zeros(3)), {"E_p": "energies", "input_work": "array"}),
        "series": (energy.series, dict(E_p=E_P, E_d=np.diff(-E_P)), {"E_p": "energies", "E_d": "array"}),
        "bound_check": (energy.bound_check, dict(E_p=E_P, friction=DAHL, E_0=0.4), {"E_p": "energies", "E_0": "nonnegative"}),
        "analyze_samples": (energy.analyze_samples, dict(t=T, x=X, v=V, F=F, system=SYSTEM),
                            {"t": "times", "x": "array", "v": "array", "F": "array"}),
        "analyze_samples(u)": (energy.analyze_samples, dict(t=T, x=X, v=V, F=F, system=SYSTEM, u=0.1 * F),
                               {"u": "array"}),
        "analyze_samples(LuGre)": (energy.analyze_samples, dict(t=T, x=1e-5 * X, v=1e-3 * V, F=F, system=LUGRE),
                                   {"t": "times", "x": "array", "v": "array", "F": "array"}),
        "bristle_deflection": (energy.bristle_deflection, dict(t=T, v=1e-3 * V, F=F, friction=LUGRE.friction), samples),
        "analyze_table(LuGre)": (energy.analyze_table, dict(table=TABLE, system=LUGRE, F0=0.0, work_input=np.zeros(len(TABLE))),
                                 {"F0": "finite", "work_input": "array"}),
    }


CALLS = valid_calls()
PAIRS = [(fn, arg) for fn, (_, _, kinds) in CALLS.items() for arg in kinds]
OPTIONAL = {("analyze_table(LuGre)", "work_input"), ("analyze_samples(u)", "u"), ("dissipation", "input_work"), ("bound_check", "E_0"),
            ("find_reversals", "x"), ("find_reversals", "F")}  # None means "not given" there
SCALAR_BAD = [None, "abc", 1j, math.nan, math.inf, -math.inf, [1.0, 2.0]]
ARRAY_BAD = ["None", "string", "complex", "nan", "inf", "-inf", "empty", "short", "strings inside"]


def bad_array(good: np.ndarray, kind: str, pos: int):
    arr = np.array(good, dtype=float)
    i = pos % max(arr.size, 1)
    if kind == "None":
        return None
    if kind == "string":
        return "0.1, 0.2"
    if kind == "complex":
        return arr.astype(complex) + 1j
    if kind in ("nan", "inf", "-inf"):
        arr[i] = float(kind)
        return arr
    if kind == "empty":
        return np.zeros(0)
    if kind == "short":
        return arr[:-1]
    return [str(a) for a in arr[:-1]] + ["x"]


def test_every_public_function_is_covered():
    public = {name for name in energy.__all__ if callable(getattr(energy, name)) and name[0].islower()}
    covered = {fn.split("(")[0] for fn in CALLS} | {"analyze_result"}  # its own test below
    assert public == covered


def loop_like(**fields):
    """An object with the fields of ``controllers.LoopResult`` that ``analyze_result`` reads."""
    base = dict(t=T, x=X, v=V, F=F, u=0.1 * F, system=SYSTEM, Ts=None)
    return types.SimpleNamespace(**{**base, **fields})


@pytest.mark.parametrize("kwargs,error,message", [
    (dict(result=None), TypeError, r"result must be a prefriction.SimulationResult .* got NoneType"),
    (dict(result="abc"), TypeError, r"result must be .* got str"),
    (dict(result=RuntimeError("a failed sweep run")), TypeError, r"result must be .* got RuntimeError"),
    (dict(result=loop_like(), system=pf.Oscillator(DAHL, mass=2.0)), TypeError, r"system must be None or the loop's own"),
    (dict(result=loop_like(), zoh="yes"), TypeError, r"zoh must be True or False, got 'yes'"),
    (dict(result=loop_like(), method="euler"), ValueError, r"method must be one of \('trapezoid', 'simpson'\), got 'euler'"),
    (dict(result=loop_like(u=F[:-1])), ValueError, r"u has length 39 but t has length 40"),
    (dict(result=loop_like(u=np.where(T > 1.0, math.nan, F))), ValueError, r"u must be finite, got u\[7\] = nan"),
    (dict(result=loop_like(u=None, Ts=0.1)), ValueError, r"zoh=True needs the held force samples u"),
    (dict(result=loop_like(), extra=1), TypeError, r"unexpected keyword argument 'extra'"),
])
def test_analyze_result_refuses_bad_input(kwargs, error, message):
    with pytest.raises(error, match=message):
        energy.analyze_result(**kwargs)


def test_analyze_result_needs_samples_and_the_system():
    run = pf.exact_reversals(SYSTEM, 1.0, 2)  # not a run: a table
    with pytest.raises(TypeError, match="result must be"):
        energy.analyze_result(run, system=SYSTEM)
    res = pf.simulate(SYSTEM, 1.0, reversals=2)  # no samples
    with pytest.raises(TypeError, match="system is required with a SimulationResult"):
        energy.analyze_result(res)
    with pytest.raises(ValueError, match=r"result holds no samples \(result.t is None\): simulate with dense="):
        energy.analyze_result(res, system=SYSTEM)


@pytest.mark.parametrize("fn", list(CALLS))
def test_valid_calls_pass(fn):
    func, kwargs, _ = CALLS[fn]
    func(**kwargs)


@settings(max_examples=150, deadline=None)
@given(pair=st.sampled_from(PAIRS), kind=st.sampled_from(ARRAY_BAD), scalar=st.sampled_from(SCALAR_BAD),
       pos=st.integers(0, 10_000))
def test_bad_values_are_named(pair, kind, scalar, pos):
    fn, arg = pair
    func, kwargs, kinds = CALLS[fn]
    kwargs = dict(kwargs)
    role = kinds[arg]
    if role in ("positive", "nonnegative", "finite"):
        kwargs[arg] = scalar if not isinstance(scalar, list) else -1.0
        if role == "finite" and isinstance(scalar, list):
            kwargs[arg] = math.nan
    else:
        good = np.atleast_1d(kwargs[arg])
        kwargs[arg] = bad_array(good, kind, pos)
        if kind == "short" and good.size == 1:
            kwargs[arg] = np.zeros(0)  # a broadcast scalar: empty is its bad size
        if kind == "short" and fn in ("branch_energy", "kinetic_energy", "dissipation", "bound_check") and arg != "input_work":
            kwargs[arg] = -np.abs(good) - 1.0 if role == "energies" else np.array([math.nan])  # no length rule: negative / NaN
    if kwargs[arg] is None and (fn, arg) in OPTIONAL:
        kwargs[arg] = "abc"
    with pytest.raises((TypeError, ValueError)) as info:
        func(**kwargs)
    assert arg in str(info.value), f"{fn}({arg}=...): message does not name {arg}: {info.value}"


@pytest.mark.parametrize("fn,arg", [(fn, a) for fn, a in PAIRS if CALLS[fn][2][a] == "times"])
def test_unsorted_times_are_refused(fn, arg):
    func, kwargs, _ = CALLS[fn]
    t = np.array(kwargs[arg], dtype=float)
    t[[5, 6]] = t[[6, 5]]
    with pytest.raises(ValueError, match=r"t must be strictly increasing, got t\[6\] = .* <= t\[5\]"):
        func(**{**kwargs, arg: t})


@pytest.mark.parametrize("fn,arg", [(fn, a) for fn, a in PAIRS if CALLS[fn][2][a] == "energies"])
def test_negative_energies_are_refused(fn, arg):
    func, kwargs, _ = CALLS[fn]
    with pytest.raises(ValueError, match=rf"{arg} must be >= 0 .*got {arg}\[2\] = -0.1"):
        func(**{**kwargs, arg: np.array([0.3, 0.2, -0.1, 0.05])})


@pytest.mark.parametrize("E_0", [-1.0, math.nan, math.inf])
def test_bound_check_refuses_bad_initial_energy(E_0):
    with pytest.raises(ValueError, match=rf"E_0 must be finite and >= 0, got {E_0!r} \(allowed range: 0 <= E_0 < inf\)"):
        energy.bound_check(E_P, friction=DAHL, E_0=E_0)


def test_total_energy_at_the_rounded_saturation_force_is_refused():
    # deep gross sliding in the first excursion rounds F to Fc: the Dahl energy is unbounded there
    F_sat = F.copy()
    F_sat[:3] = DAHL.Fc
    with pytest.raises(ValueError, match=r"branch energy is infinite at F\[0\] = 1.0 N in direction \+1"):
        energy.total_energy(T, V, F_sat, system=SYSTEM)


def test_unknown_keywords_raise():
    with pytest.raises(TypeError):
        energy.kinetic_energy(V, mass=1.0, masss=2.0)
    with pytest.raises(TypeError, match="reset_at_reversals must be True or False, got 'yes'"):
        energy.integrated_power(T, V, F, reset_at_reversals="yes")
