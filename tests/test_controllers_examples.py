"""Stage examples (Agg), plant_iosys and the benchmark of the controllers package.

Independent references: the pole-placement formulas, the static bound ``Fc/kp``, the final
value theorem on the pre-sliding linearisation, python-control's linear responses, and
scipy's solve_ivp (inside plant_iosys) against the CasADi simulator on the same loop.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import control
import matplotlib
import numpy as np
import pytest

from prefriction import controllers
import prefriction
from prefriction.controllers import benchmark
from prefriction.controllers.example_stage import report

matplotlib.use("Agg")

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
M, SIGMA, FC = 1.0, 1e6, 1.0


def load(name):
    spec = importlib.util.spec_from_file_location(f"controllers_examples_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def check_png(path):
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_stage_pd_example(tmp_path):
    out = load("stage_pd").main(tmp_path)
    check_png(out["path"])
    wn = 2 * np.pi * 300.0
    assert out["kp"] == pytest.approx(M * wn**2 - SIGMA, rel=1e-12)
    assert out["kd"] == pytest.approx(2 * 0.7 * wn * M, rel=1e-12)
    assert out["Ts"] == 1e-4 and out["phase_margin"] > 30.0
    bound = FC / out["kp"]
    for label, s in out["steps"].items():
        assert abs(s["residual_error"]) <= bound and s["bound"] == pytest.approx(bound, rel=1e-12)
        assert np.all(np.isfinite(s["x"])) and len(s["x"]) == len(s["t"]) == len(s["F"]) == len(s["u"])
        np.testing.assert_allclose(s["t"][1:] - s["t"][:-1], 1e-4, rtol=1e-9)
    # 1 um step: friction reaches the nonlinear part of (3.2), still |e| <= Fc/kp with margin
    assert 0.05 * bound < abs(out["steps"]["1 µm"]["residual_error"]) < 0.9 * bound
    # 10 nm step: |F| <= 1.3 % of Fc, nearly the pre-sliding spring: final value theorem of the
    # linearised loop, e = r sigma / (sigma + kp), holds to the hysteresis (about 1 %)
    s = out["steps"]["10 nm"]
    assert np.max(np.abs(s["F"])) < 0.02 * FC
    assert s["residual_error"] == pytest.approx(1e-8 * SIGMA / (SIGMA + out["kp"]), rel=0.03)
    text = report(out)
    assert f"kp = {out['kp']:.4g} N/m" in text and "step 10 nm: residual error" in text


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_stage_pid_example(tmp_path):
    out = load("stage_pid").main(tmp_path)
    check_png(out["path"])
    wn = 2 * np.pi * 150.0
    assert out["ki"] == pytest.approx(M * wn**3, rel=1e-12)
    assert out["kp"] == pytest.approx(M * (1 + 2 * 0.7) * wn**2 - SIGMA, rel=1e-12)
    for label, s in out["steps"].items():
        # final value theorem: integral action, zero static error; far below the PD bound Fc/kp
        assert abs(s["residual_error"]) <= 1e-5 * s["step"]
        assert s["reversals"] >= 1 and len(s["reversal_x"]) == s["reversals"]
    assert "ki = " in report(out)


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_stage_antiwindup_example(tmp_path):
    out = load("stage_antiwindup").main(tmp_path)
    check_png(out["path"])
    aw, clip = out["cases"]["anti-windup"], out["cases"]["clipping only"]
    for c in (aw, clip):
        assert c["peak_force"] == out["u_max"]  # the limit is reached and respected
        assert abs(c["residual_error"]) <= 1e-2 * out["step"]  # integral action still removes the error
    assert 0.0 < aw["overshoot"] < 0.8 * clip["overshoot"]
    # default tracking time sqrt(Ti Td) (Astrom and Hagglund)
    assert out["tracking_time"] == pytest.approx(np.sqrt(out["kp"] / out["ki"] * out["kd"] / out["kp"]), rel=1e-12)


def loop_of(P, C):
    sj = control.summing_junction(inputs=["r", "-x"], output="e")
    return control.interconnect([P, control.ss(C, inputs="e", outputs="u"), sj], inplist=["r"], outlist=["x"])


def test_plant_iosys_linear_regime_matches_linear_loop():
    system = prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=1e8), mass=M)
    pd = controllers.pd(2e6, 2000.0, tau=5e-5)
    P = controllers.plant_iosys(system)
    assert P.state_labels == ["x", "v", "F"] and P.input_labels == ["u"] and P.output_labels == ["x"]
    t = np.linspace(0.0, 0.01, 501)
    resp = control.input_output_response(
        loop_of(P, pd.ss()), t, np.full(t.shape, 1e-6),
        solve_ivp_kwargs={"method": "LSODA", "rtol": 1e-10, "atol": 1e-10 * np.array([1e-6, 1e-3, 1.0, 1e-6])})
    T = control.feedback(control.tf([1.0], [M, 0.0, SIGMA]) * control.tf([2000.0 + 2e6 * 5e-5, 2e6], [5e-5, 1.0]), 1)
    lin = control.forced_response(T, t, np.full(t.shape, 1e-6)).outputs
    assert np.max(np.abs(resp.outputs - lin)) <= 1e-6 * np.max(np.abs(lin))


def test_plant_iosys_sampled_agrees_with_simulate_loop():
    system = prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)
    Cd = controllers.design_pd(system, wn=3000.0).c2d(1e-4)
    ours = controllers.simulate_loop(system, Cd, 1e-6, 0.004)
    Pd = controllers.plant_iosys(system, Ts=1e-4)
    assert Pd.dt == 1e-4
    resp = control.input_output_response(loop_of(Pd, Cd), ours.t, np.full(ours.t.shape, 1e-6))
    assert len(ours.reversals) >= 1  # the loop does cross reversal kinks
    assert np.max(np.abs(resp.outputs - ours.x)) <= 1e-6 * 1e-6


def test_plant_iosys_argument_errors():
    system = prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got 0.0"):
        controllers.plant_iosys(system, Ts=0.0)
    with pytest.raises(TypeError, match="solve_ivp_kwargs is only used with Ts"):
        controllers.plant_iosys(system, solve_ivp_kwargs={"rtol": 1e-9})
    with pytest.raises(TypeError, match="system must be a prefriction.Oscillator"):
        controllers.plant_iosys(prefriction.Dahl(1.0, 1.0))
    with pytest.raises(TypeError, match="unexpected keyword"):
        controllers.plant_iosys(system, ts=1e-4)


def test_benchmark_small_run(capsys):
    timing = benchmark.sampled_timing(t_end=0.003, repeats=1)
    assert timing["n_samples"] == 31 and timing["t_ours"] > 0 and timing["t_python_control"] > 0
    assert timing["speedup"] == pytest.approx(timing["t_python_control"] / timing["t_ours"])
    assert timing["us_ours"] == pytest.approx(1e6 * timing["t_ours"] / 30)
    # against the independent scipy reference: ours within the target, python-control within 1e-6
    assert timing["err_ours"] <= benchmark.TARGET_ERROR and timing["err_python_control"] < 1e-6
    rows = [{"t_end": 0.1, "n_samples": 1001, "us": 2.0, "us_call": 3.0},
            {"t_end": 1.0, "n_samples": 10001, "us": 4.0, "us_call": 4.5}]
    sweep = {"n": 100, "t_end": 0.1, "wall": 9.0, "loop_time": 5.0, "compiles": 1}
    text = benchmark.format_tables(timing, sweep, rows)
    assert "input_output_response" in text and "simulate_loop" in text
    verdicts = [line.split()[-1] for line in text.splitlines()[-5:]]
    assert verdicts[3] == "PASS" and verdicts[4] == "FAIL"  # one compile; 4 / 2 = 2x > 1.5x
    code = benchmark.main(["--t-end", "0.002", "--repeats", "1", "--sweep", "0", "--lengths"])
    out = capsys.readouterr().out
    assert "us/sample" in out and ("PASS" in out or "FAIL" in out)
    assert code == (1 if " FAIL" in out else 0)  # the exit status follows the printed verdicts (timings vary)
