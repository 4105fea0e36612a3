"""The friction-model protocol: a model written through it alone, and the reusable checks.

``ElasticPlastic`` below is an elastic-perfectly-plastic element (a Prandtl/Jenkin element,
stiffness ``k``, slip force ``Fy``) written only against :class:`prefriction.FrictionModel`,
independently of the Dahl code. Its unforced oscillator has a closed form (normalised units,
``x~ = x k / Fy``, ``t~ = t sqrt(k / m)``, from ``x = 0``, ``F = 0`` at speed ``v0 > 1``):
elastic ``z = v0 sin t`` up to ``t1 = asin(1 / v0)``, then sliding at ``F = Fy`` with
deceleration 1 to the first reversal at ``t1 + sqrt(v0^2 - 1)``, ``x = (v0^2 + 1) / 2``; after it
an undamped elastic oscillation between ``F = +Fy`` and ``F = -Fy`` with half-period ``pi``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np
import pytest

import prefriction as pf
from prefriction import FrictionModel, Parameter
from prefriction.testing import check_model


@dataclass(frozen=True)
class ElasticPlastic(FrictionModel):
    """Elastic-perfectly-plastic element: ``F = k d`` while ``|F| < Fy``, sliding at ``s Fy``."""

    k: float
    Fy: float

    parameters = (Parameter("k", "N/m", 0.0, math.inf, low_open=True),
                  Parameter("Fy", "N", 0.0, math.inf, low_open=True))
    n_states = 1
    n_flags = 1

    def initial_state(self, f0, s):
        return [f0], [1.0 if s * f0 >= 1.0 else 0.0]

    def rate(self, z, m, v, s, q):
        return [v * (1.0 - m[0])]

    def force(self, z, m, v, s, q):
        return z[0]

    def events(self, z, m, v, s, q):
        ind = 1.0 - s * z[0]
        if isinstance(ind, ca.SX):
            return [ca.if_else(m[0] > 0.5, 1.0, ind)]
        return [1.0 if m[0] > 0.5 else ind]

    def on_event(self, k, z, m, s, q):
        return [s * 1.0], [1.0]

    def branch_energy_of_force(self, F, s):
        return 0.5 * np.asarray(F, dtype=float) ** 2


def test_model_written_through_the_protocol_matches_its_closed_form():
    k, Fy, m, v0n = 2e5, 0.5, 0.3, 3.0  # v0n: normalised initial speed > 1 (it slides first)
    system = pf.Oscillator(ElasticPlastic(k, Fy), mass=m)
    sc = pf.Scales.of(system)
    res = pf.simulate(system, v0n * sc.v, reversals=7, rtol=1e-10)
    t1 = math.asin(1.0 / v0n)
    tr = t1 + math.sqrt(v0n ** 2 - 1.0) + math.pi * np.arange(7)
    xr = (v0n ** 2 + 1.0) / 2.0 - 2.0 * (np.arange(7) % 2)
    Fr = (-1.0) ** np.arange(7)
    np.testing.assert_allclose(res.reversals.t / sc.t, tr, rtol=2e-9)
    np.testing.assert_allclose(res.reversals.x / sc.x, xr, rtol=2e-9)
    np.testing.assert_allclose(res.reversals.F / sc.F, Fr, rtol=2e-9)
    # no dissipation after the first reversal: E_p stays Fy^2 / (2 k)
    np.testing.assert_allclose(res.reversals.E_p, 0.5 * Fy ** 2 / k, rtol=1e-8)


def test_protocol_model_passes_the_reusable_checks():
    out = check_model(ElasticPlastic(1e3, 2.0), v0=0.8, reversals=10)  # stays elastic: harmonic
    assert out.n_reversals == 10 and out.max_error < 20e-8


@pytest.mark.parametrize("gamma", [0.0, 0.5, 1.0, 2.5])
def test_dahl_passes_the_reusable_checks(gamma):
    out = check_model(pf.Dahl(1e4, 1.0, gamma), v0=1.5, reversals=12)
    assert out.n_reversals == 12


def test_one_structure_for_every_gamma_and_tolerance():
    from prefriction.simulation.integrator import _CACHE

    before = len(_CACHE)
    for gamma in (1.0, 1.7, 3.0):
        for rtol in (1e-6, 1e-9):
            sys_ = pf.Oscillator(pf.Dahl(1e4, 1.0, gamma))
            res = pf.simulate(sys_, 1.0, reversals=5, rtol=rtol)
            ref = pf.exact_reversals(sys_, 1.0, 5)
            np.testing.assert_allclose(res.reversals.F, ref.F, rtol=5 * rtol)
    assert len(_CACHE) - before <= 1


def test_dahl_only_functions_say_so():
    system = pf.Oscillator(ElasticPlastic(1.0, 1.0))
    with pytest.raises(TypeError, match="exact_reversals has an exact reference for Dahl and MaxwellSlip only"):
        pf.exact_reversals(system, 0.1, 3)


def test_loops_and_sweeps_run_any_protocol_model():
    """controllers.simulate_loop and sweep with the elastic-plastic element: in its elastic
    range it is a spring k, so the PD loop is python-control's linear closed loop."""
    import control

    from prefriction import controllers

    k, m, kp, kd, tau, r0 = 1e6, 1.0, 2e6, 2000.0, 5e-5, 1e-6
    stage = pf.Oscillator(ElasticPlastic(k, 1e8), mass=m)  # never slips: F = k x
    res = controllers.simulate_loop(stage, controllers.pd(kp, kd, tau=tau), r0, 0.02)
    C = control.tf([kd + kp * tau, kp], [tau, 1.0])
    T = control.feedback(control.tf([1.0], [m, 0.0, k]) * C, 1)
    lin = control.forced_response(T, res.t, np.full(res.t.shape, r0)).outputs
    assert float(np.max(np.abs(res.x - lin)) / np.max(np.abs(lin))) <= 1e-6
    systems = [pf.Oscillator(ElasticPlastic(1e4, 1.0)), pf.Oscillator(pf.Dahl(1e4, 1.0, 1.5))]
    out = pf.sweep(systems, 0.005, reversals=3)  # both elastic / pre-sliding: v0 below slip
    np.testing.assert_allclose(out[0].reversals.t, math.pi / 2 * math.sqrt(1e-4) * (1 + 2 * np.arange(3)), rtol=1e-8)
    np.testing.assert_allclose(out[1].reversals.F, pf.exact_reversals(systems[1], 0.005, 3).F, rtol=1e-7)


def test_check_model_catches_a_model_that_bakes_its_numbers_into_the_plant():
    """A Dahl variant whose symbolic rate reads self.gamma instead of q would compile a plant
    that is wrong for every other gamma; the contract check compares with a sibling instance."""

    @dataclass(frozen=True)
    class BakedDahl(pf.Dahl):
        def rate(self, z, m, v, s, q):
            return super().rate(z, m, v, s, [self.gamma])

    with pytest.raises(AssertionError, match="must use q"):
        check_model(BakedDahl(1e4, 1.0, 2.0), reversals=3)
    check_model(pf.Dahl(1e4, 1.0, 2.0), reversals=3)  # the same check passes for Dahl itself
