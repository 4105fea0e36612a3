"""Closed-loop records fitted the way they are measured (issue 30): inverse model, closed loop, EMPS.

References independent of the code under test: the EMPS look-alike record comes from scipy LSODA
integrating each sample interval of the loop separately and restarting at every reversal
(``prefriction.identify.synthetic_loop``, written from the equations: PD at 1 kHz, a one-sample
delay, the two-tap velocity filter, encoder steps of 5e-8 m); the decimation's gain at zero
frequency is the Chebyshev filter's closed form; the direction-dependent viscous force is
written here by hand. The EMPS check (opt-in: ``PREFRICTION_EMPS_DIR`` names a directory with
``DATA_EMPS.mat`` and ``DATA_EMPS_PULSES.mat``) asserts the published numbers of Janot, Gautier
and Brunot (2019).
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import lfilter

import prefriction as pf
from prefriction import identify
from prefriction.identify.derivatives import decimate, derivatives
from prefriction.identify.synthetic_loop import ClosedLoop, closed_loop_record, reference_moves

TRUE = pf.Dahl(sigma=2.0e6, Fc=20.4)
STAGE = ClosedLoop(TRUE, mass=95.1, b=166.6, b_neg=240.0, offset=-0.26, Kp=1.37e6, Kd=8557.0, taps=(0.5, 0.5),
                   delay=1, quantum=5e-8)
TRUTH = {"sigma": 2.0e6, "Fc": 20.4, "b": 166.6, "b_neg": 240.0, "mass": 95.1, "offset": -0.26}
LOOP = identify.DigitalLoop(1e-3, 1.37e6, 8557.0, taps=(0.5, 0.5), delay=1)
N, SEED = 1000, 0


@pytest.fixture(scope="module")
def record() -> tuple[identify.Motion, np.ndarray]:
    rec = closed_loop_record(STAGE, N, np.random.default_rng(SEED), rtol=1e-11)   # the recorded-force fit resolves 1e-8
    return identify.Motion(rec.t, rec.x, rec.u, None), reference_moves(N, 1e-3, np.random.default_rng(SEED))


def test_decimation_keeps_the_last_sample_and_the_chebyshev_gain():
    y = decimate(np.ones(25), 10)
    assert y.size == 3  # samples 4, 14, 24: MATLAB's decimate ends on the last sample
    # filtfilt of the order-8 Chebyshev I (ripple 0.05 dB) at zero frequency: (10^(-0.05/20))^2
    assert y == pytest.approx(10.0 ** (-0.1 / 20.0), rel=1e-6)


def test_sandwich_gives_the_long_run_spread_of_a_mean_of_ar1_noise():
    from prefriction.identify.hac import sandwich
    from prefriction.identify.statistics import gauss_newton

    rho, n = 0.7, 40_000
    e = np.random.default_rng(5).standard_normal(n)
    r = lfilter([np.sqrt(1.0 - rho ** 2)], [1.0, -rho], e)   # r_k = rho r_k-1 + sqrt(1 - rho^2) e_k: unit variance
    J = np.ones((n, 1))
    r = r - r.mean()                                            # the residuals of fitting the mean
    gn = gauss_newton(J, r, ["mean"], np.array([1.0]), np.array([1.0]))
    hac, lag = sandwich(J, r, gn, np.array([1.0]), np.array([1.0]))
    # the mean of n samples of unit-variance AR(1) noise: variance (1 + rho) / (1 - rho) / n
    assert gn.stderr[0] == pytest.approx(1.0 / np.sqrt(n), rel=0.05)
    assert hac.stderr[0] == pytest.approx(np.sqrt((1.0 + rho) / (1.0 - rho) / n), rel=0.15) and lag > 10


def test_derivatives_of_a_slow_sine_and_the_default_filter():
    t = np.arange(4000) * 1e-3
    d = derivatives(t, 0.1 * np.sin(2.0 * np.pi * t))
    assert (d.cutoff, d.step, d.border, d.order) == (100.0, 10, 49, 4)
    inner = slice(200, -200)
    w = 2.0 * np.pi
    assert np.max(np.abs(d.v[inner] - 0.1 * w * np.cos(w * t[inner]))) < 1e-4 * 0.1 * w
    assert np.max(np.abs(d.a[inner] + 0.1 * w * w * np.sin(w * t[inner]))) < 1e-3 * 0.1 * w * w
    with pytest.raises(ValueError, match="uniformly spaced"):
        derivatives(np.r_[t[:10], t[11:]], np.zeros(t.size - 1))
    with pytest.raises(ValueError, match="cutoff must be below"):
        derivatives(t, np.sin(t), cutoff=600.0)


def test_directional_viscous_force_by_hand():
    t = np.linspace(0.0, 2.0, 401)
    x = 0.01 * np.sin(np.pi * t)
    v = 0.01 * np.pi * np.cos(np.pi * t)
    F = pf.friction_along(pf.DirectionalViscous(b=200.0, b_neg=150.0), t, x, v=v).F
    assert np.allclose(F, np.where(v > 0, 200.0, 150.0) * v, atol=1e-9)
    m = identify.StaticFriction(Fc=20.0, b=200.0, Fc_neg=18.0, b_neg=150.0)
    assert np.allclose(m.force([-0.1, 0.1]), [-18.0 - 15.0, 20.0 + 20.0])
    with pytest.raises(ValueError, match="b_neg"):
        pf.DirectionalViscous(b=1.0, b_neg=-1.0)


def test_closed_loop_simulation_follows_the_scipy_loop(record):
    data, ref = record
    model = TRUE + pf.DirectionalViscous(STAGE.b, STAGE.b_neg)
    x, u = identify.simulate_closed_loop(model, LOOP, data.t, ref, mass=STAGE.mass, offset=STAGE.offset)
    # the record's encoder rounds to 5e-8 m and the loop feeds it back: agreement at that level
    assert np.max(np.abs(x - data.x)) < 4 * STAGE.quantum
    assert np.sqrt(np.mean((u - data.u) ** 2)) < 0.01 * np.std(data.u)


def test_linear_controller_law_and_fit_against_python_control():
    import control

    from prefriction.controllers import pd

    dt, n, m, b, off = 1e-3, 600, 2.0, 40.0, 0.5
    C = pd(4.0e4, 300.0)
    loop = identify.DigitalLoop.from_controller(C, dt)
    Cd = C.c2d(dt)   # python-control's zero-order-hold discretisation, run as a state space here
    A, B, Cm, D = (np.asarray(M, dtype=float) for M in (Cd.A, Cd.B, Cd.C, Cd.D))
    r = reference_moves(n, dt, np.random.default_rng(2), stroke=0.01)
    x, u = np.empty(n), np.empty(n)
    xc, pos, v = np.zeros(A.shape[0]), r[0], 0.0
    a = b / m
    phi, ea = -np.expm1(-a * dt) / a, np.exp(-a * dt)
    for k in range(n):   # the stage m x'' + b x' + off = u in closed form over each held sample
        x[k] = pos
        err = r[k] - pos
        u[k] = float((Cm @ xc)[0] + D[0, 0] * err)
        xc = A @ xc + B[:, 0] * err
        f = (u[k] - off) / m
        pos, v = pos + v * phi + f * (dt - phi) / a, v * ea + f * phi
    assert np.allclose(loop.force(r, x), u, rtol=1e-9, atol=1e-9 * np.abs(u).max())
    assert isinstance(identify.DigitalLoop.from_controller(control.tf([1.0], [1.0, 1.0]), dt), identify.DigitalLoop)
    res = identify.fit_closed_loop(pf.Viscous(20.0), identify.Motion(np.arange(n) * dt, x, u, None), loop, r,
                                   mass0=1.5, offset0=0.0)
    for name, value in {"b": b, "mass": m, "offset": off}.items():
        assert res.estimate(name) == pytest.approx(value, rel=1e-6), res.report()
    with pytest.raises(ValueError, match="sample time"):
        identify.DigitalLoop.from_controller(control.c2d(C.ss(), 2e-3), dt)


def test_closed_loop_route_recovers_the_truth_from_the_inverse_start(record):
    data, ref = record
    start = pf.Dahl(sigma=1.0e6, Fc=10.0) + pf.DirectionalViscous(100.0, 100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", identify.IdentifiabilityWarning)
        model0, mass0, offset0 = identify.inverse_start(start, data, delay=1.5)
        res = identify.fit_closed_loop(model0, data, LOOP, ref, fixed=["gamma"], mass0=mass0, offset0=offset0)
    assert res.success and res.notes[0] == "route: closed-loop output error"
    for name, value in TRUTH.items():
        lo, hi = res.interval(name)
        assert lo <= value <= hi, (name, res.report())
    assert res.estimate("Fc") == pytest.approx(20.4, rel=0.01) and res.estimate("mass") == pytest.approx(95.1, rel=1e-3)


def test_inverse_route_recovers_the_truth(record):
    data, _ = record
    # the loop applies u_k over [t_k+1, t_k+2]: the balance at sample k sees it 1.5 samples late;
    # the look-alike's moves are faster than EMPS's: filter at 200 Hz, decimate by 5
    d = derivatives(data.t, data.x, cutoff=200.0, step=5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", identify.IdentifiabilityWarning)
        res = identify.fit_inverse(pf.Dahl(sigma=2.0e6, Fc=10.0) + pf.DirectionalViscous(100.0, 100.0), data,
                                   fixed=["gamma", "sigma"], delay=1.5, deriv=d)
        rigid = identify.fit_inverse(identify.StaticFriction(Fc=1.0, b=1.0, Fc_neg=1.0, b_neg=1.0), data,
                                     offset=False, delay=1.5, deriv=d)
    for name in ("Fc", "b", "b_neg", "mass", "offset"):
        lo, hi = res.interval(name)
        assert lo <= TRUTH[name] <= hi, (name, res.report())
    assert res.statistics.sigma_hat < rigid.statistics.sigma_hat  # the presliding model explains more
    assert isinstance(res.data, identify.ForceDisplacement) and "Newey-West" in res.notes[-1]
    via_fit = identify.fit(identify.StaticFriction(Fc=1.0, b=1.0), data, offset=True)   # dispatched to the route
    assert via_fit.notes[0] == "route: inverse model" and via_fit.names == ("mass", "Fc", "b", "offset")


def test_recommend_names_the_route(monkeypatch):
    t = np.arange(1000) * 1e-3
    u = 30.0 * np.sin(2.0 * np.pi * t)
    m, b, Fc = 2.0, 5.0, 3.0   # a driven mass with viscous and Coulomb friction, open loop, u held (scipy)
    x, y = [0.0], np.array([0.0, 0.0])
    for k in range(t.size - 1):
        sol = solve_ivp(lambda _t, z, k=k: [z[1], (u[k] - b * z[1] - Fc * np.tanh(z[1] / 1e-6)) / m],
                        (t[k], t[k + 1]), y, method="LSODA", rtol=1e-10, atol=1e-14)
        y = sol.y[:, -1]
        x.append(y[0])
    x = np.array(x)
    open_loop = identify.recommend(identify.Motion(t, x, u, None))
    assert open_loop.route == "motion" and open_loop.horizon > 1000 // 8
    # 20 s of a viscous stage under the EMPS-like PD loop with encoder steps, each sample in closed form
    n, dt, q, Kp, Kd = 20_000, 1e-3, 5e-8, 1.37e6, 8557.0
    r = reference_moves(n, dt, np.random.default_rng(SEED))
    a = b / 95.1
    phi, e = -np.expm1(-a * dt) / a, np.exp(-a * dt)
    xq, uq, pos, v, prev = np.empty(n), np.empty(n), r[0], 0.0, np.round(r[0] / q) * q
    for k in range(n):
        xq[k] = np.round(pos / q) * q
        uq[k] = Kp * (r[k] - xq[k]) - Kd * (xq[k] - prev) / dt
        prev = xq[k]
        pos, v = pos + v * phi + uq[k] / 95.1 * (dt - phi) / a, v * e + uq[k] / 95.1 * phi
    closed = identify.recommend(identify.Motion(np.arange(n) * dt, xq, uq, None), controller_known=True)
    assert closed.route == "closed-loop" and closed.horizon < n // 8 and "fit_closed_loop" in closed.reason
    assert identify.recommend(identify.Motion(np.arange(n) * dt, xq, uq, None)).route == "inverse"
    assert identify.recommend(identify.Motion(t[:100], x[:100], u[:100], None)).route == "motion"
    # the open-loop Motion fit says which route to use when it fails on such a record
    import prefriction.identify.continuation as continuation

    def stalled(*_a, **_k):
        raise pf.SolverError("the segments stopped meeting")

    monkeypatch.setattr(continuation, "fit_motion", stalled)
    with pytest.raises(pf.SolverError, match=r"segments stopped meeting; this record suits another route \(inverse"
                                             r".*identify\.fit_inverse"):
        identify.fit(pf.Dahl(sigma=1e6, Fc=10.0) + pf.Viscous(100.0), identify.Motion(np.arange(n) * dt, xq, uq, None),
                     mass0=90.0, structures="given", fixed=["gamma"])


def test_bad_arguments_are_named(record):
    data, ref = record
    with pytest.raises(ValueError, match="directional=True is for a StaticFriction"):
        identify.fit_inverse(pf.Dahl(sigma=1e6, Fc=10.0), data, directional=True)
    with pytest.raises(ValueError, match="offset=True with a StaticFriction having Fc_neg"):
        identify.fit_inverse(identify.StaticFriction(Fc=1.0, Fc_neg=1.0), data)
    with pytest.raises(ValueError, match="fitted whole in closed form"):
        identify.fit_inverse(identify.StaticFriction(Fc=1.0, b=1.0), data, fixed=["b"])
    with pytest.raises(ValueError, match="free decay"):
        identify.fit_inverse(identify.StaticFriction(Fc=1.0), identify.Motion(data.t, data.x, 0.0 * data.u, None))
    with pytest.raises(ValueError, match="reference must be finite"):
        identify.fit_closed_loop(TRUE, data, LOOP, ref[:-1], mass0=95.0)
    with pytest.raises(ValueError, match="give mass0"):
        identify.fit_closed_loop(TRUE, data, LOOP, ref)
    with pytest.raises(ValueError, match="tol must be in"):
        identify.fit_inverse(identify.StaticFriction(Fc=1.0), data, tol=1.0)
    with pytest.raises(ValueError, match="max_iter"):
        identify.fit_closed_loop(TRUE, data, LOOP, ref, mass0=95.0, max_iter=0)
    with pytest.raises(ValueError, match="taps"):
        identify.DigitalLoop(1e-3, 1.0, 1.0, taps=())
    with pytest.raises(ValueError, match="delay"):
        identify.DigitalLoop(1e-3, 1.0, 1.0, delay=9)


def test_emps_loader_reads_own_files_and_refuses_links(tmp_path):
    from scipy.io import savemat

    from prefriction.identify.emps import load

    n = 50
    mat = {"t": np.arange(n) * 1e-3, "qm": np.zeros(n), "qg": np.zeros(n), "vir": np.ones(n), "gtau": 35.0,
           "kp": 160.0, "kv": 243.0}
    savemat(tmp_path / "DATA_EMPS.mat", mat)
    savemat(tmp_path / "DATA_EMPS_PULSES.mat", mat)
    est, pulses = load(tmp_path)
    assert est.u == pytest.approx(35.0 * np.ones(n)) and pulses.kv == 243.0
    (tmp_path / "other").mkdir()
    os.symlink(tmp_path / "DATA_EMPS.mat", tmp_path / "other" / "DATA_EMPS.mat")
    savemat(tmp_path / "other" / "DATA_EMPS_PULSES.mat", mat)
    with pytest.raises(ValueError, match="not a link"):
        load(tmp_path / "other")
    with pytest.raises(ValueError, match="does not exist"):
        load(tmp_path / "missing")


EMPS_DIR = os.environ.get("PREFRICTION_EMPS_DIR")


@pytest.mark.skipif(not EMPS_DIR, reason="PREFRICTION_EMPS_DIR does not name a directory with the EMPS files")
def test_emps_inverse_model_reproduced_and_dahl_holds_it_from_every_start():
    from prefriction.identify.emps import PUBLISHED, load, open_loop_rmse

    est, pulses = load(EMPS_DIR)
    data = est.motion()
    res = identify.fit_inverse(identify.StaticFriction(Fc=1.0, b=1.0), data)
    for name, value in PUBLISHED.items():  # Script_IDIM_LS.m's numbers, every printed digit
        assert round(res.estimate(name), 4) == pytest.approx(value, abs=1e-12)
    assert identify.recommend(data).route == "inverse"
    P = PUBLISHED
    for f in (1.0, 0.5, 2.0):
        model = pf.Dahl(sigma=f * 5e6, Fc=f * P["Fc"]) + pf.Viscous(f * P["b"])
        fit = identify.fit_inverse(model, data, fixed=["gamma"], mass0=f * P["mass"], offset0=f * P["offset"])
        for name, value in P.items():
            lo, hi = fit.interval(name)
            assert lo <= value <= hi, (f, name, fit.report())
    assert open_loop_rmse(fit, pulses) < open_loop_rmse(res, pulses)


@pytest.mark.slow
@pytest.mark.skipif(not EMPS_DIR, reason="PREFRICTION_EMPS_DIR does not name a directory with the EMPS files")
def test_emps_routes_hold_the_published_values():
    from prefriction.identify.emps import benchmark

    rows = benchmark(EMPS_DIR)
    published = next(r for r in rows if r.route == "published")
    dynamic = [r for r in rows if r.model.startswith("Dahl + Viscous")]
    assert {(r.route, r.start) for r in dynamic} == {(route, f) for route in ("inverse", "closed-loop")
                                                     for f in ("1 x", "0.5 x", "2 x")}
    for r in dynamic:
        assert all(r.holds().values()), r
    assert min(r.rmse for r in dynamic) < published.rmse


def test_recommend_keeps_a_record_with_a_negative_closed_form_mass_from_the_motion_route():
    """The stage workflow's closed-loop record (PID at 5 kHz, 10 nm encoder; scipy LSODA from the
    equations of ``examples/stage_workflow.py``, 1,800 samples): its closed-form inverse model has
    a negative mass, so the open-loop Motion fit is not advised; the reason says so in words."""
    import importlib.util
    import sys

    from _doc_blocks import ROOT

    spec = importlib.util.spec_from_file_location("stage_workflow", ROOT / "examples" / "stage_workflow.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["stage_workflow"] = module
    spec.loader.exec_module(module)
    rec = module.synthetic_record(0.36)
    data = identify.Motion(rec.t, rec.x, rec.u, None)
    from prefriction.identify.derivatives import derivatives
    from prefriction.identify.inverse import static_inverse

    d0 = derivatives(data.t, data.x)
    assert static_inverse(data, derivatives(data.t, data.x, tail=d0.border))["mass"] < 0.0   # the premise
    advice = identify.recommend(data)
    assert advice.route == "inverse" and "not physical" in advice.reason and "fit_inverse" in advice.reason
    known = identify.recommend(data, controller_known=True)
    assert known.route == "closed-loop" and "fit_closed_loop" in known.reason and "mass" in known.reason
