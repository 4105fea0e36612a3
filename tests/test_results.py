"""Results behave alike (compact print, labelled figures, per-field sweep arrays), loop metrics
against the reference, reference velocities of every signal, the frequency-unit guard.

References: python-control's ``step_info`` on the linear loop (friction so strong it stays a
spring), closed-form derivatives of the signals and central differences of their values, a
longer run of the same loop for the last sample's force."""

from __future__ import annotations

import math

import control
import matplotlib.figure
import numpy as np
import pytest

import prefriction as pf
from prefriction import controllers
from prefriction.signals import Chirp, PointToPoint, Ramp, Samples, Sine, Step, Traced, ZeroOrderHold


@pytest.fixture
def figures(monkeypatch):
    """The figures the results save, captured (their axes are checked for labels)."""
    saved = []
    original = matplotlib.figure.Figure.savefig

    def capture(fig, path, *args, **kwargs):
        saved.append(fig)
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", capture)
    return saved


def _check_figure(fig) -> None:
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert axes
    for ax in axes:
        assert ax.get_ylabel().strip(), "an axis without a y label"
        assert "[" in ax.get_ylabel() or ax.get_yscale() == "log" or "|" in ax.get_ylabel()
    assert all(ax.get_xlabel().strip() for ax in axes if ax.get_subplotspec().is_last_row())


def _result(kind: str):
    stage = pf.Oscillator(pf.Dahl(sigma=1e5, Fc=1.0), mass=1.0)
    t = np.linspace(0.0, 0.2, 2001)
    x = 1e-5 * np.sin(2 * np.pi * 10 * t)
    if kind == "simulation":
        return pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), 1.0), 1.0, reversals=10, dense=True)
    if kind == "simulation without samples":
        return pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0), 1.0), 1.0, reversals=10)
    if kind == "sweep":
        return pf.sweep([pf.Oscillator(pf.Dahl(1e4, 1.0, g)) for g in (1.0, 2.0)], 1.0, reversals=10)
    if kind == "loop":
        pid = controllers.design_pid(stage, wn=2 * math.pi * 100.0)
        return controllers.simulate_loop(stage, pid, PointToPoint(1e-5, v_max=1e-3, a_max=0.5), 0.05, Ts=1e-4)
    if kind == "along":
        return pf.friction_along(pf.Dahl(2e5, 1.0), t, x)
    if kind == "move":
        return pf.optimal.point_to_point(stage, 1e-4, u_max=3.0)
    F = pf.friction_along(pf.Dahl(2e5, 1.0), t, x).F + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    fit = pf.identify.fit(pf.Dahl(1e5, 0.8, 1.0), pf.identify.ForceDisplacement(t, x, F), fixed=["gamma"])
    return fit if kind == "fit" else fit.validate(pf.identify.ForceDisplacement(t, x, F))


@pytest.mark.parametrize("kind", ["simulation", "simulation without samples", "sweep", "loop", "along", "fit",
                                  "validation", "move"])
def test_every_result_prints_compactly_and_plots_a_labelled_figure(kind, tmp_path, figures):
    res = _result(kind)
    line = repr(res)
    assert "\n" not in line and len(line) < 300 and "array(" not in line, line
    assert res.summary().strip()
    path = res.plot(tmp_path / "result.png")
    assert path.is_file() and path.stat().st_size > 10_000
    _check_figure(figures[-1])


def test_sweep_gives_per_field_arrays_equal_to_each_runs_table():
    systems = [pf.Oscillator(pf.Dahl(1e4, 1.0, g)) for g in (1.0, 2.0, 3.0)]
    runs = pf.sweep(systems, 1.0, reversals=7)
    F = runs.reversal_array("F")
    assert F.shape == (3, 7) and list(runs.n_reversals) == [7, 7, 7]
    for i, system in enumerate(systems):  # the exact reference of each run, to the tolerance
        exact = pf.exact_reversals(system, 1.0, 7)
        np.testing.assert_allclose(F[i], exact.F, rtol=1e-6)
        np.testing.assert_allclose(runs.reversal_array("t")[i], exact.t, rtol=1e-6)
    with pytest.raises(ValueError, match="field must be one of"):
        runs.reversal_array("speed")
    with pytest.raises(ValueError, match="dense=True"):
        runs.sample_array("x")
    dense = pf.sweep(systems[:2], 1.0, t_end=0.01, dense=np.linspace(0.0, 0.01, 11))
    assert dense.sample_array("x").shape == (2, 11)


def test_settling_time_equals_python_controls_step_info_on_the_linear_loop():
    """Fc so large that Dahl's force stays the spring sigma x: the loop is linear, and with the
    PID's integrator the final value is the reference, where step_info measures its band."""
    m, sigma = 1.0, 1e4
    stage = pf.Oscillator(pf.Dahl(sigma=sigma, Fc=1e7), mass=m)
    pid = controllers.design_pid(stage, wn=300.0, zeta=0.5)
    t = np.linspace(0.0, 0.1, 5001)
    loop = controllers.simulate_loop(stage, pid, 1e-6, 0.1, t_out=t, rtol=1e-10)
    closed = control.feedback(control.tf([1.0], [m, 0.0, sigma]) * pid.tf(), 1)
    info = control.step_info(closed, T=t, SettlingTimeThreshold=0.02)
    assert abs(loop.settling_time - info["SettlingTime"]) <= 2 * (t[1] - t[0])


def test_a_pd_loop_stopped_short_by_friction_has_not_settled():
    stage = pf.Oscillator(pf.Dahl(sigma=1e6, Fc=1.0), mass=1.0)
    pd = controllers.design_pd(stage, wn=2 * math.pi * 300.0, zeta=0.7)
    loop = controllers.simulate_loop(stage, pd.c2d(1e-4), 1e-6, 0.05)
    assert abs(loop.residual_error) > 0.02 * 1e-6  # stopped short by more than the band
    assert loop.settling_time == math.inf
    assert loop.settling_time_within(0.5) < 0.05


def test_the_last_samples_force_is_the_controllers_output_there():
    """With a feedforward the force needs the next reference sample: the last one of a run equals
    the same sample of a longer run (the reference is not frozen at the end)."""
    stage = pf.Oscillator(pf.Dahl(sigma=1e6, Fc=1.0), mass=1.0)
    pid = controllers.design_pid(stage, wn=2 * math.pi * 150.0)
    ref = Sine(5e-6, 1.0, phase=-math.pi / 2, offset=5e-6)
    ff = controllers.Feedforward(stage.friction)
    short = controllers.simulate_loop(stage, pid, ref, 0.1, Ts=1e-4, compensator=ff)
    longer = controllers.simulate_loop(stage, pid, ref, 0.2, Ts=1e-4, compensator=ff)
    k = len(short.t) - 1
    assert short.t[k] == pytest.approx(longer.t[k])
    assert short.u[-1] == pytest.approx(longer.u[k], rel=1e-9)


T = np.array([0.0, 0.013, 0.25, 0.4, 0.77, 1.3])


@pytest.mark.parametrize("signal, derivative", [
    (Sine(2e-6, 3.0, phase=0.4, offset=1e-6), lambda t: 2e-6 * 2 * np.pi * 3.0 * np.cos(2 * np.pi * 3.0 * t + 0.4)),
    (Chirp(1.0, 1.0, 5.0, 1.0), lambda t: np.where(
        t <= 1.0, np.cos(2 * np.pi * (t + 2.0 * t ** 2)) * 2 * np.pi * (1.0 + 4.0 * t),
        np.cos(2 * np.pi * (3.0 + 5.0 * (t - 1.0))) * 2 * np.pi * 5.0)),
    (Ramp(0.2, 3.0, offset=1.0), lambda t: np.where(t >= 0.2, 3.0, 0.0)),
    (Step(0.1, 1.0, 2.0), lambda t: np.zeros_like(t)),
    (Samples([0.0, 0.5, 1.0], [0.0, 1.0, 0.0]), lambda t: np.where(t < 0.5, 2.0, np.where(t < 1.0, -2.0, 0.0))),
    (ZeroOrderHold([0.0, 0.5, 1.0], [1.0, 2.0, 3.0]), lambda t: np.zeros_like(t)),
    (Traced(np.square), lambda t: 2.0 * t),
    (Sine(1.0, 2.0) + Ramp(0.0, 0.5), lambda t: 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t) + 0.5),
])
def test_every_signal_has_its_exact_velocity(signal, derivative):
    np.testing.assert_allclose(signal.velocity(T), derivative(T), rtol=1e-12, atol=1e-12)
    assert isinstance(signal.velocity(0.25), float)


def test_a_sum_of_moves_has_the_velocity_of_its_positions():
    moves = sum(PointToPoint((-1.0) ** k * 2e-5, v_max=2e-3, a_max=0.5, j_max=500.0, start=0.05 * k)
                for k in range(4))
    t = np.linspace(0.001, 0.199, 397)
    h = 1e-7
    central = (moves(t + h) - moves(t - h)) / (2 * h)
    np.testing.assert_allclose(moves.velocity(t), central, atol=1e-7 * 2e-3)


def test_a_frequency_in_rad_per_s_passed_as_hz_is_refused():
    with pytest.raises(ValueError, match=r"frequency=942.47.* Hz is 2 pi x 150.*rad/s"):
        Sine(1e-6, 2 * math.pi * 150.0)
    with pytest.raises(ValueError, match=r"f1=.*rad/s"):
        Chirp(1.0, 1.0, 2 * math.pi * 10.0, 1.0)
    assert Sine(1e-6, 150.0).frequency == 150.0
    assert Sine(1e-6, 1000.0 / (2 * math.pi)).frequency == pytest.approx(159.15494309)


def test_design_pid_below_the_presliding_limit_names_the_sliding_design():
    stage = pf.Oscillator(pf.Dahl(sigma=2e6, Fc=3.0), mass=2.5)
    with pytest.raises(ValueError, match=r'577.35 rad/s.*got wn=200.0.*rad/s.*regime="sliding"'):
        controllers.design_pid(stage, wn=200.0)
