"""prefriction.export.controller_source with plant_source: the sampled positioning loop in C.

The exported controller and the exported plant, compiled together with ``gcc -std=c99 -Wall
-Werror`` (``-O0``: a quick compile, the same numbers), run the loop of :func:`prefriction.controllers.simulate_loop` (its compiled sampled
loop: one Function with controller and plant) and must give its samples: a reference the
python-control discretisation of the same PID, the same plant, computed in another program.
"""

from __future__ import annotations

import numpy as np
import pytest

import prefriction as pf
from prefriction import controllers, export
from prefriction.controllers._reference import reference_velocity
from prefriction.signals import Sine

needs_gcc = pytest.mark.skipif(export.gcc() is None, reason="gcc is not on the PATH: the exported C cannot be compiled")
TS, T_END, RTOL = 1e-4, 0.05, 1e-10  # the plant of test_export_plant.py: compiled once per process
STAGE = pf.Oscillator(pf.Dahl(1e5, 1.0, 1.0), mass=0.5)


def reference(t):
    return 1e-5 * np.sin(2 * np.pi * 20 * t)


def _compare(run, res):
    """The exported plant is the native driver (step size carried over), ``simulate_loop(jit=False)``
    CasADi's erk restarted each period: equal to the tolerance RTOL, the force to 10 RTOL (the PID's
    derivative term)."""
    assert np.all(run.status == 0)
    assert np.max(np.abs(run.x - res.x)) <= RTOL * np.max(np.abs(res.x))
    assert np.max(np.abs(run.F - res.F)) <= RTOL * STAGE.friction.Fc
    assert np.max(np.abs(run.u - res.u)) <= 10 * RTOL * np.max(np.abs(res.u))


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    if export.gcc() is None:
        pytest.skip("gcc is not on the PATH: the exported C cannot be compiled")
    return export.plant_source(STAGE, "stage", tmp_path_factory.mktemp("loop"), Ts=TS, rtol=RTOL)


@needs_gcc
@pytest.mark.parametrize("pid", [controllers.PID(kp=4e5, ki=2e7, kd=600.0),
                                 controllers.PID(kp=4e5, ki=2e7, kd=600.0, u_max=0.5)], ids=["linear", "limited"])
def test_c_loop_gives_the_samples_of_simulate_loop(plant, tmp_path, pid):
    res = controllers.simulate_loop(STAGE, pid, reference, T_END, Ts=TS, rtol=RTOL, jit=False)
    ctl = export.controller_source(pid, "pid", tmp_path, Ts=TS)
    run = export.run_loop_c(ctl, plant, reference(np.arange(res.t.size) * TS), optimize=False)
    assert np.count_nonzero(np.diff(np.sign(run.v[run.v != 0.0]))) >= 2  # the stage reverses
    _compare(run, res)
    if pid.u_max is not None:
        assert np.max(np.abs(run.u)) == pytest.approx(0.5, rel=1e-15)  # the limit binds


LUGRE_STAGE = pf.Oscillator(pf.LuGre(1e5, 300.0, 0.4, 1.0, 1.3, 1e-3), mass=0.5)
COMPENSATED = {
    "dahl-feedforward": (STAGE, lambda m: controllers.Feedforward(m), 1e-10, 1e-9),
    "dahl-disturbance-observer": (STAGE, lambda m: controllers.DisturbanceObserver(bandwidth=2000.0), 1e-10, 1e-9),
    "lugre-lugre-observer": (LUGRE_STAGE, lambda m: controllers.LuGreObserver(m, 1e3), 1e-10, 1e-9),
    "lugre-friction-observer": (LUGRE_STAGE, lambda m: controllers.FrictionObserver(m, pole=500.0), 1e-10, 1e-9),
}


@needs_gcc
@pytest.mark.parametrize("case", list(COMPENSATED))
def test_c_compensated_loop_gives_the_samples_of_simulate_loop(tmp_path, case):
    """Compensated loops (issue 18's compensators) in C against simulate_loop(compensator=...):
    the stiff LuGre loops and the disturbance observer's inverse plant (m w^2 on the measured
    position) amplify the rounding of the two programs' different operation orders; the last
    sample's force is left out (simulate_loop has no next reference sample there)."""
    stage, make, tol_x, tol_u = COMPENSATED[case]
    comp = make(stage.friction)
    pid = controllers.PID(kp=4e5, ki=2e7, kd=600.0)
    ref = Sine(1e-5, 20.0)
    res = controllers.simulate_loop(stage, pid, ref, T_END, Ts=TS, rtol=RTOL, compensator=comp, jit=False)
    tk = np.arange(res.t.size) * TS
    r = np.asarray(res.reference)
    plant = export.plant_source(stage, "stage", tmp_path, Ts=TS, rtol=RTOL)
    ctl = export.controller_source(pid, "ctl", tmp_path, Ts=TS, compensator=comp, mass=stage.mass)
    run = export.run_loop_c(ctl, plant, r, reference_velocity(ref, tk, r, TS), optimize=False)
    assert np.all(run.status == 0) and np.max(np.abs(res.compensation)) > 0.05 * stage.friction.Fc
    assert np.max(np.abs(run.x - res.x)) <= tol_x * np.max(np.abs(res.x))
    assert np.max(np.abs(run.u[:-1] - res.u[:-1])) <= tol_u * np.max(np.abs(res.u))


@needs_gcc
def test_controller_header_and_function(tmp_path):
    pid = controllers.PID(kp=4e5, ki=2e7, kd=600.0)
    ctl = export.controller_source(pid, "pid", tmp_path, Ts=TS)
    h = ctl.header.read_text()
    assert "double pid_update(pid_state *s, double y, double r, double r_next, double v_ref, double v_ref_next);" in h
    assert "void pid_reset(pid_state *s);" in h
    w0 = export.controller_initial_state(pid, Ts=TS)
    w1, u = ctl.function(w0, 0.0, [1e-6, 1e-6, 0.0, 0.0])
    assert float(u) > 0.0 and repr(ctl).startswith("CSource('pid', controller: PID(")


def test_controller_arguments_are_checked(tmp_path):
    pid = controllers.PID(kp=1e5)
    with pytest.raises(ValueError, match="Ts must be finite and > 0"):
        export.controller_source(pid, "c", tmp_path, Ts=-1.0)
    with pytest.raises(ValueError, match="discretization must be a control.c2d method"):
        export.controller_source(pid, "c", tmp_path, Ts=TS, discretization="nope")
    with pytest.raises(TypeError, match="controller must be a controllers.PID"):
        export.controller_source("pid", "c", tmp_path, Ts=TS)
    with pytest.raises(TypeError, match="compensator must be a controllers compensator"):
        export.controller_source(pid, "c", tmp_path, Ts=TS, compensator=3.0, mass=1.0)
