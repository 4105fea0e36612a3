"""Parametric signals of prefriction.signals.

References are closed forms written here with numpy (and ``np.interp`` for samples). The central
property is the one the simulator relies on: an expression built on CasADi symbols from one
instance, compiled once, gives the value of *every* instance with the same key when fed that
instance's numbers.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from prefriction.signals import (
    MAX_SAMPLES,
    Chirp,
    Constant,
    Ramp,
    Samples,
    Signal,
    Sine,
    Step,
    Sum,
    Traced,
    as_signal,
)

T = np.linspace(0.0, 5.0, 1001)
_COMPILED: dict = {}


def compiled(sig: Signal) -> ca.Function:
    """One ca.Function per key, built from the first instance seen (never from its numbers)."""
    if sig.key not in _COMPILED:
        t = ca.SX.sym("t")
        theta = ca.SX.sym("theta", sig.n_params)
        piece = ca.SX.sym("piece", sig.n_piece)
        _COMPILED[sig.key] = ca.Function("sig", [t, theta, piece], [sig.expr(t, theta, piece)])
    return _COMPILED[sig.key]


def compiled_values(f: ca.Function, sig: Signal, t_end: float = 5.0, n: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of ``f`` fed with ``sig``'s numbers, interval by interval between breaks."""
    edges = np.unique(np.concatenate([[0.0, t_end], sig.breaks()[(sig.breaks() > 0) & (sig.breaks() < t_end)]]))
    ts, vs = [], []
    for ta, tb in zip(edges[:-1], edges[1:]):
        piece = sig.piece(ta, tb)
        for ti in np.linspace(ta, tb, n):
            ts.append(ti)
            vs.append(float(f(ti, sig.params(), piece)))
    return np.array(ts), np.array(vs)


# ----------------------------------------------------------------------------------------------
# numeric values against closed forms


def test_constant_step_ramp_sine_values():
    np.testing.assert_array_equal(Constant(-2.5)(T), np.full_like(T, -2.5))
    np.testing.assert_array_equal(Step(1.0, 0.5, -0.25)(T), np.where(T < 1.0, 0.5, -0.25))
    assert Step(1.0, 0.5, -0.25)(1.0) == -0.25  # after from the step time on
    np.testing.assert_allclose(Ramp(2.0, 3.0, offset=1.0)(T), np.where(T < 2.0, 1.0, 1.0 + 3.0 * (T - 2.0)), rtol=0, atol=1e-15)
    np.testing.assert_allclose(Sine(0.5, 2.0, phase=0.3, offset=-1.0)(T), -1.0 + 0.5 * np.sin(4.0 * np.pi * T + 0.3), rtol=0, atol=1e-15)


def _chirp_cycles(t, f0, f1, d):
    """Phase / (2 pi) of a linear sweep, continued at f1 after d."""
    return np.where(t <= d, f0 * t + (f1 - f0) * t**2 / (2 * d), f0 * d + (f1 - f0) * d / 2 + f1 * (t - d))


@pytest.mark.parametrize(("f0", "f1", "d"), [(0.5, 3.0, 2.0), (4.0, 0.0, 1.5), (1.0, 1.0, 3.0)])
def test_chirp_is_a_linear_sweep_with_continuous_phase(f0, f1, d):
    sig = Chirp(0.7, f0, f1, d)
    np.testing.assert_allclose(sig(T), 0.7 * np.sin(2 * np.pi * _chirp_cycles(T, f0, f1, d)), rtol=0, atol=1e-12)
    # the phase's derivative is 2 pi times the instantaneous frequency: f0 -> f1 linearly, then f1
    h = 1e-6
    tm = T[(np.abs(T - d) > 2 * h)]
    rate = 2 * np.pi * (_chirp_cycles(tm + h, f0, f1, d) - _chirp_cycles(tm - h, f0, f1, d)) / (2 * h)
    f_inst = np.where(tm < d, f0 + (f1 - f0) * tm / d, f1)
    np.testing.assert_allclose(rate, 2 * np.pi * f_inst, rtol=1e-7, atol=1e-6)
    assert abs(sig(d + 1e-9) - sig(d - 1e-9)) < 1e-6  # continuous at the end of the sweep


def test_samples_interpolate_like_numpy_and_hold_outside():
    ts, us = np.array([0.5, 1.0, 2.5, 4.0]), np.array([1.0, -2.0, 0.5, 3.0])
    sig = Samples(ts, us)
    tt = np.concatenate([T, ts, [-1.0, 10.0]])
    np.testing.assert_array_equal(sig(tt), np.interp(tt, ts, us))
    assert sig(-1.0) == 1.0 and sig(10.0) == 3.0 and isinstance(sig(1.7), float)


def test_samples_piece_is_the_linear_piece_of_the_interval():
    ts, us = np.array([0.5, 1.0, 2.5, 4.0]), np.array([1.0, -2.0, 0.5, 3.0])
    sig = Samples(ts, us)
    for ta, tb in [(0.0, 0.5), (0.5, 1.0), (1.0, 2.5), (1.2, 1.3), (2.5, 4.0), (4.0, 6.0), (1.0, 1.0)]:
        tl, a, b = sig.piece(ta, tb)
        tt = np.linspace(ta, tb, 11)
        np.testing.assert_allclose(a + b * (tt - tl), np.interp(tt, ts, us), rtol=0, atol=1e-13)
    assert sig.piece(4.0, 6.0)[2] == 0.0 and sig.piece(-1.0, 0.5)[2] == 0.0  # held outside
    assert sig.piece(1.0, 2.5)[2] == pytest.approx(2.5 / 1.5)  # ta exactly a sample time: the right piece


def test_traced_evaluates_the_function():
    sig = Traced(lambda t: 2.0 * np.sin(t) + ca.if_else(t > 1.0, 1.0, 0.0))
    np.testing.assert_allclose(sig(T), 2.0 * np.sin(T) + (T > 1.0), rtol=0, atol=1e-14)
    assert sig.n_params == 0 and sig.breaks().size == 0


def test_scalar_in_scalar_out_and_shape_preserved():
    for sig in (Sine(1.0, 1.0), Constant(2.0), Samples([0, 1], [0, 1]), Traced(np.cos), Sine(1, 1) + 2.0):
        assert isinstance(sig(0.25), float)
        assert sig(np.zeros((2, 3))).shape == (2, 3)


# ----------------------------------------------------------------------------------------------
# one compiled expression for all numbers

PAIRS = [
    (Constant(1.0), Constant(-3.0)),
    (Step(1.0, 0.0, 1.0), Step(2.5, -1.0, 0.5)),
    (Ramp(0.5, 1.0), Ramp(3.0, -2.0, offset=0.7)),
    (Sine(1.0, 1.0), Sine(0.3, 2.7, phase=1.1, offset=-0.2)),
    (Chirp(1.0, 0.0, 2.0, 1.0), Chirp(0.4, 3.0, 0.5, 2.2)),
    (Samples([0.0, 1.0], [0.0, 1.0]), Samples([0.3, 0.9, 1.4, 2.0, 4.2], [1.0, -1.0, 2.0, 0.0, 0.5])),
    (Sine(1.0, 1.0) + Step(1.0, 0.0, 1.0) + Samples([0, 1], [0, 1]),
     Sine(-2.0, 0.4) + Step(3.0, 1.0, 0.0) + Samples([1.0, 2.0, 3.0], [2.0, 0.0, 1.0])),
    (Samples([0, 1], [0, 1]) + Samples([0, 1], [1, 0]), Samples([1, 2], [5, 1]) + Samples([0.5, 3], [-1, 1])),
]


@pytest.mark.parametrize(("a", "b"), PAIRS, ids=[repr(a.key) for a, _ in PAIRS])
def test_expression_built_from_one_instance_serves_another(a, b):
    assert a.key == b.key and a.n_params == b.n_params and a.n_piece == b.n_piece
    f = compiled(a)
    ts, vs = compiled_values(f, b)
    np.testing.assert_allclose(vs, b(ts), rtol=1e-12, atol=1e-12)


def test_traced_expression_compiles_the_function():
    fun = lambda t: t * t - ca.fmax(t - 1.0, 0.0)  # noqa: E731
    sig = Traced(fun)
    ts, vs = compiled_values(compiled(sig), sig)
    np.testing.assert_allclose(vs, ts**2 - np.maximum(ts - 1.0, 0.0), rtol=1e-14)


@settings(max_examples=40, deadline=None)
@given(
    amp=st.floats(-1e3, 1e3), freq=st.floats(1e-3, 1e2), phase=st.floats(-10, 10),
    time=st.floats(0, 10), before=st.floats(-1e3, 1e3), after=st.floats(-1e3, 1e3),
    slope=st.floats(-1e3, 1e3),
)
def test_one_compiled_sum_for_all_numbers(amp, freq, phase, time, before, after, slope):
    sig = Sine(amp, freq, phase=phase) + Step(time, before, after) + Ramp(time, slope)
    f = compiled(Sine(1.0, 1.0) + Step(0.0, 0.0, 0.0) + Ramp(0.0, 0.0))
    ts, vs = compiled_values(f, sig, t_end=12.0, n=5)
    np.testing.assert_allclose(vs, sig(ts), rtol=1e-12, atol=1e-12 * (1 + abs(amp) + abs(before) + abs(after) + 12 * abs(slope)))


def test_expr_with_numbers_matches_call():
    sig = Sine(0.5, 1.5) + Step(1.0, 0.0, 2.0) + Samples([0.0, 2.0, 3.0], [1.0, 0.0, 4.0])
    piece = sig.piece(2.0, 3.0)
    tt = np.linspace(2.0, 3.0, 9)
    np.testing.assert_allclose(sig.expr(tt, sig.params(), piece), sig(tt), rtol=1e-14)
    assert isinstance(sig.expr(2.5, list(sig.params()), list(piece)), float)
    # mixed: symbolic time with numeric parameters gives a casadi expression
    t = ca.SX.sym("t")
    e = sig.expr(t, sig.params(), piece)
    assert float(ca.Function("e", [t], [e])(2.5)) == pytest.approx(sig(2.5), rel=1e-14)
    with pytest.raises(ValueError, match="theta"):
        sig.expr(1.0, np.zeros(2), piece)


# ----------------------------------------------------------------------------------------------
# keys, breaks, sums, bounds


def test_keys_are_structure_only():
    assert Sine(1, 2).key == Sine(3, 4, phase=1.0, offset=2.0).key == ("Sine",)
    kinds = [Constant(1), Step(0, 0, 1), Ramp(0, 1), Sine(1, 1), Chirp(1, 0, 1, 1), Samples([0, 1], [0, 1])]
    assert len({s.key for s in kinds}) == len(kinds)
    assert (Sine(1, 1) + Step(0, 0, 1)).key == ("Sum", ("Sine",), ("Step",))
    assert (Sine(1, 1) + Step(0, 0, 1)).key != (Sine(1, 1) + Ramp(0, 1)).key
    assert (Sine(1, 1) + Step(0, 0, 1)).key != (Step(0, 0, 1) + Sine(1, 1)).key
    f = np.sin
    assert Traced(f).key == Traced(f).key == ("Traced", f)
    assert Traced(lambda t: t).key != Traced(lambda t: t).key  # each function object compiles once
    hash(sum([Sine(1, 1), Samples([0, 1], [0, 1]), Traced(f)]).key)


def test_breaks():
    assert Sine(1, 1).breaks().size == 0 and Constant(1).breaks().size == 0
    np.testing.assert_array_equal(Step(1.5, 0, 1).breaks(), [1.5])
    np.testing.assert_array_equal(Ramp(0.5, 1).breaks(), [0.5])
    np.testing.assert_array_equal(Chirp(1, 0, 1, 2.0).breaks(), [2.0])
    np.testing.assert_array_equal(Samples([0, 1, 3], [0, 1, 0]).breaks(), [0, 1, 3])
    s = Step(3.0, 0, 1) + Samples([0, 1, 3], [0, 1, 0]) + Ramp(0.5, 1) + Sine(1, 1)
    np.testing.assert_array_equal(s.breaks(), [0, 0.5, 1, 3])


def test_sums():
    a, b, c = Sine(0.5, 2.0), Step(1.0, 0.0, 1.0), Samples([0.0, 4.0], [0.0, 2.0])
    np.testing.assert_allclose((a + b)(T), 0.5 * np.sin(4 * np.pi * T) + np.where(T < 1.0, 0.0, 1.0), atol=1e-15)
    s = sum([a, b, c])
    assert isinstance(s, Sum) and s.terms == (a, b, c) and s.key == (a + b + c).key == ((a + b) + c).key
    assert (a + (b + c)).terms == (a, b, c)  # nested sums flatten
    np.testing.assert_allclose(s(T), a(T) + b(T) + c(T), rtol=1e-15)
    np.testing.assert_array_equal(s.params(), np.concatenate([a.params(), b.params()]))
    assert s.n_piece == 3 and s.piece(1.0, 2.0).size == 3
    for r in (2.0 + a, a + 2, np.float64(2.0) + a):
        assert r.key == ("Sum", ("Constant",), ("Sine",)) or r.key == ("Sum", ("Sine",), ("Constant",))
        np.testing.assert_allclose(r(T), a(T) + 2.0, rtol=1e-15)
    with pytest.raises(TypeError):
        a + "x"
    with pytest.raises(TypeError, match="terms"):
        Sum(a, 1.0)


def test_bounds_cover_the_values():
    sigs = [Constant(-2.0), Step(1.0, 0.5, -3.0), Step(9.0, 0.5, -3.0), Ramp(1.0, -2.0, offset=0.5), Sine(2.0, 1.3, offset=-1.0),
            Chirp(1.5, 0.0, 3.0, 2.0), Samples([-1.0, 2.0, 8.0], [4.0, -1.0, 9.0]), Traced(np.sin),
            Sine(1.0, 1.0) + Step(1.0, 0.0, 2.0)]
    for s in sigs:
        assert s.bound(5.0) >= np.max(np.abs(s(T))) - 1e-12, s
    assert Step(9.0, 0.5, -3.0).bound(5.0) == 0.5
    assert Samples([-1.0, 2.0, 8.0], [4.0, -1.0, 9.0]).bound(5.0) == pytest.approx(np.max(np.abs(np.interp(T, [-1, 2, 8], [4, -1, 9]))))
    with pytest.raises(ValueError, match="t_end"):
        Sine(1, 1).bound(-1.0)


def test_repr_and_immutability():
    assert repr(Sine(0.5, 2.0)) == "Sine(amplitude=0.5, frequency=2.0, phase=0.0, offset=0.0)"
    assert repr(Step(1, 0, 1) + 2.0) == "Sum(Step(time=1.0, before=0.0, after=1.0), Constant(value=2.0))"
    assert repr(Samples([0, 1], [2, 3])) == "Samples(n=2, t=[0.0 .. 1.0], u=[2.0 .. 3.0])"
    s = Sine(1, 1)
    with pytest.raises(AttributeError):
        s.amplitude = 2.0
    samp = Samples([0, 1], [2, 3])
    with pytest.raises(ValueError):
        samp.t[0] = 5.0


# ----------------------------------------------------------------------------------------------
# validation

NAN, INF = float("nan"), float("inf")
BAD = [
    (lambda: Constant(NAN), ValueError, "value"),
    (lambda: Constant(None), TypeError, "value"),
    (lambda: Constant("1"), TypeError, "value"),
    (lambda: Constant(1j), TypeError, "value"),
    (lambda: Constant(True), TypeError, "value"),
    (lambda: Step(-1.0, 0, 1), ValueError, "time"),
    (lambda: Step(0.0, INF, 1), ValueError, "before"),
    (lambda: Step(0.0, 0, None), TypeError, "after"),
    (lambda: Ramp(NAN, 1.0), ValueError, "time"),
    (lambda: Ramp(0.0, -INF), ValueError, "slope"),
    (lambda: Ramp(0.0, 1.0, offset=False), TypeError, "offset"),
    (lambda: Sine(1.0, -1.0), ValueError, "frequency"),
    (lambda: Sine(1.0, 0.0), ValueError, "frequency"),
    (lambda: Sine(NAN, 1.0), ValueError, "amplitude"),
    (lambda: Sine(1.0, 1.0, phase=INF), ValueError, "phase"),
    (lambda: Sine(1.0, 1.0, offset="0"), TypeError, "offset"),
    (lambda: Chirp(1.0, -1.0, 1.0, 1.0), ValueError, "f0"),
    (lambda: Chirp(1.0, 1.0, NAN, 1.0), ValueError, "f1"),
    (lambda: Chirp(1.0, 0.0, 0.0, 1.0), ValueError, "f0 and f1"),
    (lambda: Chirp(1.0, 0.0, 1.0, 0.0), ValueError, "duration"),
    (lambda: Chirp(1j, 0.0, 1.0, 1.0), TypeError, "amplitude"),
    (lambda: Samples([0.0, 2.0, 1.0], [0, 1, 2]), ValueError, "t"),
    (lambda: Samples([0.0, 1.0, 1.0], [0, 1, 2]), ValueError, "strictly increasing"),
    (lambda: Samples([0.0, 1.0], [0, 1, 2]), ValueError, "same length"),
    (lambda: Samples([0.0], [1.0]), ValueError, "at least 2"),
    (lambda: Samples([0.0, NAN], [0, 1]), ValueError, "t must be finite"),
    (lambda: Samples([0.0, 1.0], [0, INF]), ValueError, "u must be finite"),
    (lambda: Samples([[0.0, 1.0]], [[0, 1]]), ValueError, "1-D"),
    (lambda: Samples([0.0, 1.0], [1j, 0]), TypeError, "u"),
    (lambda: Samples(None, [0, 1]), TypeError, "t"),
    (lambda: Samples(["a", "b"], [0, 1]), TypeError, "t"),
    (lambda: Samples([True, False], [0, 1]), TypeError, "t"),
    (lambda: Samples(np.broadcast_to(0.0, (MAX_SAMPLES + 1,)), [0, 1]), ValueError, str(MAX_SAMPLES)),
    (lambda: Samples([0, 1], [0, 1]).piece(1.0, 0.5), ValueError, "tb"),
    (lambda: Traced(lambda t: math.sin(t)), TypeError, "does not trace"),
    (lambda: Traced(lambda t: t if t > 0 else -t), TypeError, "CasADi symbol"),
    (lambda: Traced(lambda t: ca.vertcat(t, t)), TypeError, "scalar"),
    (lambda: Traced(3.0), TypeError, "callable"),
    (lambda: Sum(), ValueError, "terms"),
]


@pytest.mark.parametrize(("make", "exc", "text"), BAD, ids=[f"{i}-{t}" for i, (_, _, t) in enumerate(BAD)])
def test_validation_errors_name_the_argument(make, exc, text):
    with pytest.raises(exc, match=text) as info:
        make()
    assert "got" in str(info.value)  # the offending value or size


def test_messages_give_value_and_range():
    with pytest.raises(ValueError) as info:
        Sine(1.0, -1.0)
    assert str(info.value) == "frequency must be a finite real number > 0 [Hz], got -1.0"
    with pytest.raises(TypeError, match="np.sin.*Samples"):
        Traced(lambda t: math.exp(t))


# ----------------------------------------------------------------------------------------------
# as_signal


def test_as_signal_conversions():
    assert as_signal(None, "u", "N") is None
    s = Sine(1, 1)
    assert as_signal(s, "u", "N") is s
    c = as_signal(np.float32(2.5), "u", "N")
    assert isinstance(c, Constant) and c.value == 2.5
    assert isinstance(as_signal(3, "u", "N"), Constant)
    samp = as_signal(([0.0, 1.0], [2.0, 3.0]), "reference", "m")
    assert isinstance(samp, Samples) and samp(0.5) == 2.5
    assert isinstance(as_signal(np.sin, "u", "N"), Traced)


@pytest.mark.parametrize(
    ("value", "exc"),
    [(NAN, ValueError), (INF, ValueError), (True, TypeError), ("1", TypeError), (1j, TypeError), ([0.0, 1.0], TypeError),
     (np.zeros(3), TypeError), (([0.0, 1.0], [1.0]), ValueError), (([1.0, 0.0], [1.0, 2.0]), ValueError),
     (([0.0, 1.0], [1.0, 2.0], [3.0]), ValueError), (lambda t: math.sin(t), TypeError)],
)
def test_as_signal_errors_name_the_argument(value, exc):
    with pytest.raises(exc, match="reference"):
        as_signal(value, "reference", "m")


def test_signals_pickle_for_process_pools():
    import pickle

    from prefriction.signals import Chirp, Ramp, Samples, Sine, Step

    for sig in (Sine(0.5, 2.0, 0.1), Step(0.1, 0.0, 1.0) + Ramp(0.2, 3.0), Chirp(1.0, 1.0, 2.0, 3.0),
                Samples(np.array([0.0, 1.0, 2.0]), np.array([1.0, -2.0, 0.5]))):
        back = pickle.loads(pickle.dumps(sig))
        t = np.linspace(0.0, 2.5, 11)
        assert back.key == sig.key and type(back) is type(sig)
        np.testing.assert_array_equal(back(t), sig(t))


def test_compiled_form_shares_one_structure_for_piecewise_linear_kinds():
    """Constants, steps, ramps, samples and their sums compile as ``("PiecewiseLinear",)``: one
    expression on symbols, fed each interval's ``piece``, gives the closed-form value; other
    kinds compile as they are."""
    from prefriction.signals import compiled_form

    ts, us = np.array([0.0, 0.7, 1.5, 3.0]), np.array([1.0, -2.0, 0.5, 0.5])
    cases = [
        (Constant(2.5), lambda t: np.full_like(t, 2.5)),
        (Step(1.0, -1.0, 3.0) + Ramp(2.0, 0.5, 0.25), lambda t: np.where(t >= 1.0, 3.0, -1.0)
         + 0.25 + 0.5 * np.maximum(t - 2.0, 0.0)),
        (Samples(ts, us) + 1.5, lambda t: np.interp(t, ts, us) + 1.5),
    ]
    t_sym, piece_sym = ca.SX.sym("t"), ca.SX.sym("piece", 3)
    for sig, closed in cases:
        form = compiled_form(sig)
        assert form.key == ("PiecewiseLinear",) and (form.n_params, form.n_piece) == (0, 3)
        assert compiled_form(form) is form
        f = ca.Function("u", [t_sym, piece_sym], [form.expr(t_sym, ca.SX(0, 1), piece_sym)])
        edges = np.unique(np.concatenate(([0.0, 4.0], sig.breaks())))
        for ta, tb in zip(edges[:-1], edges[1:]):
            t = np.linspace(ta, tb, 7, endpoint=False)  # a step jumps at tb
            got = np.array([float(f(x, form.piece(ta, tb))) for x in t])
            np.testing.assert_allclose(got, closed(t), rtol=1e-14, atol=1e-14)
        np.testing.assert_array_equal(form(T), closed(T))
    sine = Sine(1.0, 2.0)
    assert compiled_form(sine) is sine and compiled_form(None) is None
