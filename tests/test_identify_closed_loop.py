"""Motion fits of closed-loop records (issue 17, part C): held input, scale, prediction.

References independent of the fitter: the EMPS-like records come from scipy LSODA integrating
each sample interval separately and restarting at every velocity reversal
(prefriction.identify.synthetic_loop), the prediction is checked against the same scipy replay of
the fitted model, the linear hold against a scipy integration written here from the equations.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import identify
from prefriction.identify.motion_predict import predict_motion
from prefriction.identify.synthetic_loop import ClosedLoop, closed_loop_record, replay

LUGRE = pf.LuGre(sigma0=2.0e5, sigma1=300.0, sigma2=203.5, Fc=20.39, Fs=25.0, vs=0.01)
LOOP = ClosedLoop(LUGRE, mass=95.1, offset=-3.16, noise=1e-7)
TRUTH = {"sigma0": 2.0e5, "sigma2": 203.5, "Fc": 20.39, "mass": 95.1, "offset": -3.16}
START = pf.LuGre(sigma0=3.0e5, sigma1=300.0, sigma2=100.0, Fc=10.0, Fs=25.0, vs=0.01)


@pytest.fixture(scope="module")
def fitted() -> identify.FitResult:
    rec = closed_loop_record(LOOP, 1000, np.random.default_rng(1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return identify.fit(START, identify.Motion(rec.t, rec.x, rec.u, None), fixed=["sigma1", "Fs", "vs"],
                            mass0=80.0, offset=True)


@pytest.fixture(scope="module")
def held_out() -> identify.Motion:
    return closed_loop_record(LOOP, 400, np.random.default_rng(7))


def test_hold_is_checked_and_shown():
    t = np.arange(10) * 1e-3
    with pytest.raises(ValueError, match="hold must be one of"):
        identify.Motion(t, np.sin(t), np.ones(10), 1.0, hold="foh")
    assert "hold 'linear'" in repr(identify.Motion(t, np.sin(t), np.ones(10), 1.0, hold="linear"))


def test_closed_loop_fit_with_mass_and_offset_free(fitted):
    assert fitted.success and fitted.statistics.sigma_hat == pytest.approx(1e-7, rel=0.1)
    for name, value in TRUTH.items():
        assert abs(fitted.estimate(name) - value) <= 3.0 * fitted.stderr[fitted.names.index(name)], fitted.report()
    assert "segments of 50 samples" in fitted.message


def test_predict_matches_scipy_replay_of_the_fitted_model(fitted, held_out):
    x_hat = predict_motion(fitted, held_out, v0=0.0, F0=0.0)
    stage = ClosedLoop(fitted.model, mass=fitted.mass, offset=fitted.estimate("offset"))
    x_ref = replay(stage, held_out.t, held_out.u, held_out.x[0], 0.0, 0.0, rtol=1e-11)
    assert np.max(np.abs(x_hat - x_ref)) <= 1e-8 * np.ptp(x_ref)  # 0.1 nm on 13 mm, far below the 1e-7 m noise
    assert np.array_equal(fitted.predict(held_out, v0=0.0, F0=0.0), x_hat)


def test_linear_hold_matches_scipy_with_u_linear_between_samples(fitted, held_out):
    data = identify.Motion(held_out.t, held_out.x, held_out.u, None, hold="linear")
    x_hat = predict_motion(fitted, data, v0=0.0, F0=0.0)
    m, off, L = fitted.mass, fitted.estimate("offset"), fitted.model
    x_ref = [held_out.x[0]]
    y = np.array([held_out.x[0], 0.0, 0.0])
    for k in range(len(data) - 1):
        t0, t1 = data.t[k], data.t[k + 1]

        def rhs(t, yy, k=k, t0=t0, t1=t1):
            u = data.u[k] + (data.u[k + 1] - data.u[k]) * (t - t0) / (t1 - t0)
            v, z = yy[1], yy[2]
            g = L.Fc + (L.Fs - L.Fc) * np.exp(-(v / L.vs) ** 2)
            dz = v - L.sigma0 * abs(v) * z / g
            return [v, (u - L.sigma0 * z - L.sigma1 * dz - L.sigma2 * v - off) / m, dz]

        while True:  # restart at every reversal inside the interval
            s = np.sign(y[1]) or np.sign(rhs(t0, y)[1]) or 1.0
            ev = lambda t, yy: yy[1]  # noqa: E731
            ev.terminal, ev.direction = True, -s
            sol = solve_ivp(rhs, (t0, t1), y, method="LSODA", rtol=1e-11, atol=1e-15, events=ev)
            y = sol.y[:, -1].copy()
            if sol.status != 1:
                break
            t0, y[1] = sol.t[-1], 0.0
        x_ref.append(y[0])
    assert np.max(np.abs(x_hat - np.array(x_ref))) <= 1e-8 * np.ptp(x_ref)
    zoh = predict_motion(fitted, held_out, v0=0.0, F0=0.0)
    assert np.max(np.abs(zoh - x_hat)) > 1e3 * np.max(np.abs(x_hat - np.array(x_ref)))  # the hold matters


@pytest.mark.slow  # six fits (20 s of CPU); the fast suite keeps one closed-loop fit against the truth (above)
def test_intervals_cover_the_truth_over_seeds():
    """Dahl + Viscous (6 records of 800 samples): each parameter inside its 95 % interval in >= 5 of 6."""
    true = pf.Dahl(sigma=1.0e6, Fc=20.39)
    loop = ClosedLoop(true, mass=95.1, b=203.5, offset=-3.16, noise=1e-7)
    truth = {"sigma": 1.0e6, "Fc": 20.39, "b": 203.5, "mass": 95.1, "offset": -3.16}
    inside = dict.fromkeys(truth, 0)
    for seed in range(6):
        rec = closed_loop_record(loop, 800, np.random.default_rng(seed))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", identify.IdentifiabilityWarning)
            res = identify.fit(pf.Dahl(sigma=8e5, Fc=10.0) + pf.Viscous(b=100.0),
                               identify.Motion(rec.t, rec.x, rec.u, None), fixed=["gamma"], mass0=80.0, offset=True)
        for name, value in truth.items():
            lo, hi = res.interval(name)
            inside[name] += lo <= value <= hi
    assert all(c >= 5 for c in inside.values()), inside


def test_free_decay_refuses_an_offset():
    t = np.linspace(0.0, 0.1, 50)
    with pytest.raises(ValueError, match="offset=True needs an applied force"):
        identify.fit(pf.Dahl(1e4, 1.0), identify.Motion(t, np.sin(40 * t) * 1e-4, 0.0, 1.0), fixed=["gamma"],
                     offset=True)


@pytest.mark.slow  # a 600-sample fit (13 s of CPU) for the bench row; the fast suite keeps the fit above
def test_bench_identify_row_and_table():
    from prefriction.cli.bench.identify import format_rows, measure

    row = measure(600)
    assert row["n"] == 600 and row["segments"] == 12 and row["iterations"] > 0
    assert row["z_max"] < 4.0 and row["rss_peak_mb"] >= row["rss_before_mb"] > 0 and row["traced_mb"] > 0
    lines = format_rows([row, dict(row, n=1200, traced_mb=2 * row["traced_mb"])])
    assert any(line.startswith("target traced memory") and line.endswith("PASS") for line in lines)
