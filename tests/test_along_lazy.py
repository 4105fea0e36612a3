"""friction_along's states made on first access: the C pass writes only the forces, and the
states, flags and events per sample come from the same pass run again. Checked against the
Maxwell-slip stop operator (closed form, written in tests/_stop_operator.py) and against the CasADi block path, which
computes them with the run."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import prefriction as pf
import prefriction.along.run as along_run
from prefriction.simulation.compiled import jit_available

from _stop_operator import K, W, element_forces, two_tone

pytestmark = pytest.mark.skipif(not jit_available(), reason="the C pass needs a C compiler")


def _motion() -> tuple[np.ndarray, np.ndarray]:
    """Reversals of several sizes, a pause, uneven sample times: 600 samples."""
    t, x = two_tone(11, 600, (2.5e-5, 6e-6), (2.3, 13.0))
    x[300:330] = x[300]
    return t, x


def test_states_on_access_match_closed_form_and_eager_path(monkeypatch: pytest.MonkeyPatch) -> None:
    t, x = _motion()
    model = pf.MaxwellSlip(K, W)
    lazy = pf.friction_along(model, t, x)
    Fi = element_forces(x)
    np.testing.assert_allclose(lazy.F, Fi.sum(axis=1), rtol=0, atol=1e-12 * W.sum())
    # z_i = k_i d_i / Fc; the retrace guard is zero on every branch
    np.testing.assert_allclose(lazy.states[:, :3], Fi / W.sum(), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(lazy.states[:, 3], 0.0)
    slipping = np.abs(Fi) >= W * (1.0 - 1e-9)  # an element slips exactly while it sits on its limit
    np.testing.assert_array_equal(lazy.flags, slipping.astype(float))
    rev = np.zeros(t.size, dtype=bool)
    rev[lazy.reversals + 1] = True  # the interval into sample k + 1 starts with a reversal (flags cleared)
    kept = slipping[:-1] & ~rev[1:, None]
    started = (slipping[1:] & ~kept).sum(axis=1)
    np.testing.assert_array_equal(lazy.events, np.concatenate(([0], started)))
    assert lazy.n_events == int(started.sum()) > 0
    v = np.diff(x) / np.diff(t)
    np.testing.assert_array_equal(lazy.v, np.concatenate((v[:1], v)))

    monkeypatch.setattr(along_run, "along_driver", lambda model, substeps: None)
    eager = pf.friction_along(model, t, x)  # the CasADi block path: states with the run
    np.testing.assert_allclose(lazy.F, eager.F, rtol=0, atol=1e-13 * W.sum())
    np.testing.assert_allclose(lazy.states, eager.states, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(lazy.flags, eager.flags)
    np.testing.assert_array_equal(lazy.events, eager.events)
    np.testing.assert_array_equal(lazy.v, eager.v)
    assert lazy.n_events == eager.n_events


def test_states_made_once_from_the_result_motion() -> None:
    """Threads asking at once get one array; the motion the states follow cannot be changed."""
    t, x = _motion()
    res = pf.friction_along(pf.MaxwellSlip(K, W) + pf.Viscous(1.5), t, x, v=np.cos(t))
    got: list[np.ndarray] = []
    threads = [threading.Thread(target=lambda: got.append(res.states)) for _ in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert all(a is got[0] for a in got) and got[0].shape[0] == t.size and res.states is got[0]
    with pytest.raises(ValueError):
        res.x[0] = 1.0
    np.testing.assert_array_equal(res.v, np.cos(t))


def test_generated_step_without_straight_line_form(monkeypatch: pytest.MonkeyPatch) -> None:
    """An operation without a straight-line C form: the pass calls CasADi's generated step
    instead, with the same forces and states (closed form)."""
    import prefriction.along.native as native

    def refuse(*args: object, **kwargs: object) -> str:
        raise NotImplementedError("test")

    monkeypatch.setattr(native, "straight_line", refuse)
    monkeypatch.setattr(native, "_CACHE", {})
    t, x = _motion()
    res = pf.friction_along(pf.MaxwellSlip(K, W), t, x)
    assert native._CACHE and all(lib is not None for lib in native._CACHE.values())  # the C pass ran
    Fi = element_forces(x)
    np.testing.assert_allclose(res.F, Fi.sum(axis=1), rtol=0, atol=1e-12 * W.sum())
    np.testing.assert_allclose(res.states[:, :3], Fi / W.sum(), rtol=0, atol=1e-12)


def test_pass_with_states_computes_the_same_forces() -> None:
    """The pass run again for the states gives the forces of the run bit for bit (docs/along.md)."""
    from prefriction.along import native
    from prefriction.along.engine import Units
    from prefriction.along.run import initial_state

    t, x = _motion()
    for model in (pf.MaxwellSlip(K, W), pf.Dahl(1e5, 1.0) + pf.Viscous(2.0)):
        lib = native.along_driver(model, None)
        _F0, X0 = initial_state(model, 0.0, 1.0)
        q = model.runtime_params()
        plain = native.run_native(lib, X0, 0.0, t, x, None, 1.0, q, Units.of(model))
        full = native.run_native(lib, X0, 0.0, t, x, None, 1.0, q, Units.of(model), states=True)
        np.testing.assert_array_equal(plain.F, full.F)
        assert plain.X is None and full.X is not None and full.X.shape == (t.size, X0.size)
        assert plain.n_events == full.n_events == int(full.events.sum())
        np.testing.assert_array_equal(plain.reversals, full.reversals)


def test_straight_line_c_matches_casadi(tmp_path) -> None:
    """The straight-line C of an expression with truth values, their sums and quotients, picks,
    sign, min and transcendental functions gives CasADi's numbers."""
    import ctypes
    import shutil
    import subprocess

    import casadi as ca

    from prefriction.along.emit import straight_line

    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    outs = [ca.if_else(a < b, ca.exp(a), ca.sin(b)), ((a < b) + (b > 0.0)) / ((a > -1.0) + (b < 5.0)),
            ca.sign(a) * ca.fmin(a, b) + ca.log1p(b * b), ca.logic_and(a < 0.5, b > 0.5) + ca.atan2(a, b)]
    fun = ca.Function("f", [a, b], [ca.vertcat(*outs)])
    body = straight_line(fun, [lambda j: "p[0]", lambda j: "p[1]"], [lambda j: f"r[{j}]"], "w")
    src = tmp_path / "f.c"
    src.write_text(f"#include <math.h>\nvoid f(const double* p, double* r) {{\n{body}\n}}\n")
    lib_path = tmp_path / "f.so"
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(lib_path), str(src), "-lm"], check=True)
    lib = ctypes.CDLL(str(lib_path))
    for p in ([0.3, 0.7], [0.9, -0.2], [-1.5, 2.0], [-0.5, -0.2], [0.0, 0.0]):  # [-0.5, -0.2]: 1 / 2
        got = np.zeros(4)
        lib.f(np.array(p).ctypes.data_as(ctypes.c_void_p), got.ctypes.data_as(ctypes.c_void_p))
        np.testing.assert_allclose(got, np.array(fun(*p)).ravel(), rtol=1e-15, atol=0)


def test_result_pickles_with_its_states() -> None:
    import pickle

    t, x = _motion()
    res = pf.friction_along(pf.MaxwellSlip(K, W), t, x)
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.F, res.F)
    np.testing.assert_allclose(back.states[:, :3], element_forces(x) / W.sum(), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(back.flags, res.flags)
    np.testing.assert_array_equal(back.events, res.events)
    assert back.n_events == res.n_events and repr(back) == repr(res)
