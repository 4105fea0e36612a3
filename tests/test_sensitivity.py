"""Sensitivities: the exact map's derivative against mpmath, the CasADi branch sensitivities against
the closed form (Dahl gamma = 1) and against central differences of prefriction.simulate."""

from __future__ import annotations

import dataclasses

import mpmath
import numpy as np
import pytest

from prefriction import controllers
import prefriction as pf
from prefriction.sensitivity import exact_sensitivities, map_derivative, sensitivities

DAHL = pf.Oscillator(pf.Dahl(1e4, 2.0), mass=0.5)
V0 = 0.03


def _mp_forces(v0, sigma=1e4, Fc=2.0, m=0.5, n=4):
    """Reversal forces by mpmath: H(a0) = c, H(a_{i+1}) = H(-a_i), H(f) = -f - ln(1 - f)."""
    H = lambda f: -f - mpmath.log(1 - f)  # noqa: E731
    c = m * sigma * v0 ** 2 / (2 * Fc ** 2)
    a = [mpmath.findroot(lambda b: H(b) - c, (mpmath.mpf(1e-30), 1 - mpmath.mpf(10) ** -30), solver="anderson")]
    for _ in range(n - 1):
        a.append(mpmath.findroot(lambda b: H(b) - H(-a[-1]), (a[-1] * 0.3, a[-1]), solver="anderson"))
    return [Fc * ai * (-1) ** i for i, ai in enumerate(a)]


def test_map_derivative_against_mpmath():
    mpmath.mp.dps = 40
    H = lambda f: -f - mpmath.log(1 - f)  # noqa: E731
    nxt = lambda a: mpmath.findroot(lambda b: H(b) - H(-a), (a * 0.3, a), solver="anderson")  # noqa: E731
    for a in (1e-6, 0.05, 0.3, 0.9, 1.0 - 1e-9):
        ref = float(mpmath.diff(nxt, mpmath.mpf(a)))
        assert abs(float(map_derivative(a)) - ref) < 1e-12 * ref
    assert map_derivative(0.0) == 1.0


def test_exact_sensitivities_against_mpmath_differentiation():
    mpmath.mp.dps = 40
    out = exact_sensitivities(DAHL, V0, 4)
    np.testing.assert_allclose(out["F"], [float(f) for f in _mp_forces(mpmath.mpf(V0))], rtol=1e-13)
    for j, kw in ((0, "sigma"), (1, "Fc"), (2, "m"), (3, "v0")):
        base = {"sigma": 1e4, "Fc": 2.0, "m": 0.5, "v0": V0}
        def f(p, i, kw=kw):
            args = dict(base, **{kw: p})
            v0 = args.pop("v0")
            return _mp_forces(v0, **args)[i]
        ref = [float(mpmath.diff(lambda p: f(p, i), mpmath.mpf(base[kw]))) for i in range(4)]
        np.testing.assert_allclose(out["dF"][:, j], ref, rtol=1e-11)


def test_branch_sensitivities_match_the_exact_map_and_central_differences_of_the_times():
    names = ("sigma", "Fc", "mass", "v0")
    res = sensitivities(DAHL, V0, reversals=5, parameters=names)
    ex = exact_sensitivities(DAHL, V0, 5)
    np.testing.assert_allclose(res.dF, ex["dF"], rtol=2e-8)
    np.testing.assert_allclose(res.dx, ex["dx"], rtol=2e-8)
    # times: central differences of the exact reference (quadrature to 1e-15)
    h = 1e-5
    for j, name in enumerate(names):
        def t_of(p, name=name):
            k = dict(sigma=1e4, Fc=2.0, mass=0.5, v0=V0, **{})
            k[name] = p
            return pf.exact_reversals(pf.Oscillator(pf.Dahl(k["sigma"], k["Fc"]), k["mass"]), k["v0"], 5).t
        b = res.values[j]
        cd = (t_of(b * (1 + h)) - t_of(b * (1 - h))) / (2 * h * b)
        np.testing.assert_allclose(res.dt[:, j], cd, rtol=1e-7)
    assert "5 reversals" in repr(res) and "dt" in res.summary()


def test_lugre_reversal_sensitivities_against_central_differences_of_simulate():
    lugre = pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3)
    system = pf.Oscillator(lugre, mass=1.0)
    names = ("sigma1", "Fs", "mass")
    res = sensitivities(system, 0.05, reversals=3, parameters=names)
    for j, name in enumerate(names):
        b = res.values[j]
        h = 1e-5 * b

        def table(p, name=name):
            if name == "mass":
                return pf.simulate(pf.Oscillator(lugre, p), 0.05, reversals=3, rtol=1e-12).reversals
            return pf.simulate(pf.Oscillator(dataclasses.replace(lugre, **{name: p}), 1.0), 0.05, reversals=3,
                               rtol=1e-12).reversals
        hi, lo = table(b + h), table(b - h)
        for col, d in (("t", res.dt), ("x", res.dx), ("F", res.dF)):
            cd = (getattr(hi, col) - getattr(lo, col)) / (2 * h)
            scale = np.abs(d[:, j]).max()
            assert np.max(np.abs(cd - d[:, j])) < 1e-4 * scale, (name, col)


def test_loop_residual_error_and_settling_time_against_central_differences():
    lugre = pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3)
    system = pf.Oscillator(lugre, mass=1.0)
    pid = controllers.PID(kp=100.0, ki=300.0, kd=5.0)
    res = sensitivities(system, controller=pid, reference=0.01, t_end=1.0, parameters=("ki", "Fs"))
    assert res.settling_time is not None and 0.0 < res.settling_time < 1.0

    def measures(p, name):
        """Residual error and settling time by prefriction.simulate (rtol 1e-12); the crossing
        |x - x(1)| = 0.02 |x(1)| by the secant method on simulated points."""
        c = dataclasses.replace(pid, ki=p) if name == "ki" else pid
        s = pf.Oscillator(dataclasses.replace(lugre, Fs=p), 1.0) if name == "Fs" else system
        C = c.ss()
        fb = pf.LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, reference=0.01)

        def x(t):
            return pf.simulate(s, 0.0, t_end=t, rtol=1e-12, dense=np.array([0.0, t]), feedback=fb).x[-1]

        xf = x(1.0)
        f = lambda t: abs(x(t) - xf) - 0.02 * abs(xf)  # noqa: E731
        t0, t1 = res.settling_time - 1e-4, res.settling_time + 1e-4
        f0, f1 = f(t0), f(t1)
        for _ in range(12):
            t0, t1, f0 = t1, t1 - f1 * (t1 - t0) / (f1 - f0), f1
            f1 = f(t1)
            if abs(t1 - t0) < 1e-13:
                break
        return 0.01 - xf, t1

    for j, name in enumerate(("ki", "Fs")):
        b = res.values[j]
        h = 1e-5 * b
        (e_hi, ts_hi), (e_lo, ts_lo) = measures(b + h, name), measures(b - h, name)
        cd_e, cd_ts = (e_hi - e_lo) / (2 * h), (ts_hi - ts_lo) / (2 * h)
        assert abs(cd_e - res.d_residual_error[j]) < 2e-5 * abs(cd_e)  # measured 3e-7 (ki), 1e-8 (Fs)
        assert abs(cd_ts - res.d_settling_time[j]) < 2e-5 * abs(cd_ts)  # measured 1e-6 (ki), 3e-8 (Fs)


def test_bad_arguments():
    with pytest.raises(ValueError, match="unknown name 'kp'"):
        sensitivities(DAHL, V0, reversals=2, parameters=("kp",))
    with pytest.raises(ValueError, match="without flags or events"):
        sensitivities(pf.Oscillator(pf.Dahl(1e4, 2.0, 0.5)), V0, reversals=2)
    with pytest.raises(ValueError, match="reversals must be <= 2000"):
        sensitivities(DAHL, V0, reversals=10 ** 6)
    with pytest.raises(ValueError, match="gamma = 1"):
        exact_sensitivities(pf.Oscillator(pf.Dahl(1e4, 2.0, 2.0)), V0, 3)
    with pytest.raises(TypeError, match="controllers.PID"):
        sensitivities(DAHL, controller=object(), reference=0.01, t_end=1.0)
