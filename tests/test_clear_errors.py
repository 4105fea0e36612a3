"""Bad input gives an error that names the argument; results travel through pickle."""

from __future__ import annotations

import pickle
from dataclasses import dataclass

import numpy as np
import pytest

import prefriction as pf
from prefriction import controllers
from test_protocol import ElasticPlastic  # the protocol test's worked example


def test_sensitivities_parameters_and_band() -> None:
    system = pf.Oscillator(pf.Dahl(1e4, 1.0))
    with pytest.raises(ValueError, match="parameters must name at least one"):
        pf.sensitivities(system, 1.0, reversals=3, parameters=())
    with pytest.raises(TypeError, match="parameters must be a sequence of names"):
        pf.sensitivities(system, 1.0, reversals=3, parameters="sigma")
    with pytest.raises(ValueError, match=r"band must lie in \(0, 1\]"):
        pf.sensitivities(system, 1.0, reversals=3, band=0.0)


@dataclass(frozen=True)
class ListKey(ElasticPlastic):
    @property
    def structure_key(self):
        return ["ListKey", 1]


def test_unhashable_structure_key_is_named() -> None:
    with pytest.raises(TypeError, match="ListKey.structure_key must be hashable"):
        pf.simulate(pf.Oscillator(ListKey(1e4, 1.0)), 1.0, reversals=2)


def test_loop_result_pickles() -> None:
    stage = pf.Oscillator(pf.Dahl(sigma=1e6, Fc=1.0))
    C = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7)
    for controller in (C, C.c2d(1e-4)):
        res = controllers.simulate_loop(stage, controller, 1e-6, 0.005)
        back = pickle.loads(pickle.dumps(res))
        assert np.array_equal(back.x, res.x) and back.Ts == res.Ts
        assert np.array_equal(back.controller.A, res.controller.A) and back.controller.dt == res.controller.dt
        assert back.summary() == res.summary()


def test_fit_plot_into_a_missing_directory_names_the_path(tmp_path) -> None:
    from prefriction import identify
    from prefriction.identify.synthetic import dahl_loops

    true = pf.Dahl(sigma=2.0e4, Fc=1.5, gamma=1.5)
    t = np.linspace(0.0, 3.0, 121)
    x = 3.0 * true.Fc / true.sigma * np.sin(2 * np.pi * t) * (0.3 + 0.7 * t / 3.0)
    res = identify.fit(pf.Dahl(1.4e4, 1.1, 1.2), dahl_loops(true, t, x, 0.005, np.random.default_rng(1)))
    with pytest.raises(ValueError, match="path must be in an existing directory"):
        res.plot(tmp_path / "missing" / "fit.png")


def test_sweep_with_a_lambda_input_on_a_process_pool_is_refused_up_front() -> None:
    from concurrent.futures import ProcessPoolExecutor

    systems = [pf.Oscillator(pf.Dahl(1e4, 1.0), u=lambda t: 0.5 * np.sin(t)) for _ in range(3)]
    with ProcessPoolExecutor(max_workers=1) as pool:
        with pytest.raises(TypeError, match=r"systems\[0\]\.u \(input u\) cannot be sent.*prefriction\.signals"):
            pf.sweep(systems, 0.0, t_end=1.0, executor=pool)


@pytest.mark.parametrize("u", [1j, True])
def test_motion_constant_input_must_be_real(u) -> None:
    from prefriction import identify

    t = np.linspace(0.0, 1.0, 50)
    with pytest.raises(TypeError, match="u must be a real number"):
        identify.Motion(t, np.sin(t), u=u)


LUGRE = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)


def test_sensitivities_of_a_pd_loop_leave_out_ki() -> None:
    """A PD has no integrator: ki is not among its parameters (central differences at ki = 0
    used to build an invalid PID with ki < 0)."""
    res = pf.sensitivities(LUGRE, controller=controllers.pd(100, 5), reference=0.01, t_end=0.2)
    assert "ki" not in res.parameters and "kp" in res.parameters
    with pytest.raises(ValueError, match="'ki' needs a controller with an integrator"):
        pf.sensitivities(LUGRE, controller=controllers.pd(100, 5), reference=0.01, t_end=0.2, parameters=("ki",))


def test_sensitivities_through_a_stick_say_so() -> None:
    with pytest.raises(pf.SolverError, match=r"is a stick .* end t_end before it"):
        pf.sensitivities(LUGRE, controller=controllers.pd(100, 5), reference=0.01, t_end=0.5)
