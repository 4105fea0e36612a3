"""A user model whose methods return the wrong number of entries is refused once per structure,
before the plant is built, with the method, its count and the declared size named."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

import prefriction as pf
from test_protocol import ElasticPlastic  # the protocol test's worked example


@dataclass(frozen=True)
class RateTooLong(ElasticPlastic):
    def rate(self, z, m, v, s, q):
        return [v * (1.0 - m[0]), 0.0 * v]


@dataclass(frozen=True)
class EventsMissing(ElasticPlastic):
    n_events = 1  # declared (the default would count the events() entries)

    def events(self, z, m, v, s, q):
        return []


@pytest.mark.parametrize("cls, match", [
    (RateTooLong, r"RateTooLong\.rate\(\) returned 2 entries; the model declares n_states = 1"),
    (EventsMissing, r"EventsMissing\.events\(\) returned 0 entries; the model declares n_events = 1"),
])
def test_wrong_sizes_are_refused_by_simulate(cls, match) -> None:
    with pytest.raises(TypeError, match=match):
        pf.simulate(pf.Oscillator(cls(1e4, 1.0)), 1.0, reversals=3)


def test_a_correct_model_passes() -> None:
    res = pf.simulate(pf.Oscillator(ElasticPlastic(1e4, 1.0)), 0.02, reversals=3)
    assert len(res.reversals) == 3


def test_a_refused_model_is_refused_on_every_call_and_on_every_path() -> None:
    """Only structures that passed are remembered: the same wrong model is refused again, by the
    unforced, the forced and the CasADi path alike (the check comes before any driver)."""
    from prefriction.signals import Sine

    match = r"RateTooLong\.rate\(\) returned 2 entries"
    for kw in ({}, {"method": "erk"}):
        with pytest.raises(TypeError, match=match):
            pf.simulate(pf.Oscillator(RateTooLong(1e4, 1.0)), 1.0, reversals=3, **kw)
    with pytest.raises(TypeError, match=match):
        pf.simulate(pf.Oscillator(RateTooLong(1e4, 1.0), u=Sine(0.5, 10.0)), 0.0, t_end=0.1)


@dataclass(frozen=True)
class NoBranchEnergy(ElasticPlastic):
    branch_energy_of_force = pf.FrictionModel.branch_energy_of_force


@dataclass(frozen=True)
class TwoStatesNoBranchEnergy(NoBranchEnergy):
    n_states = 2

    def rate(self, z, m, v, s, q):
        return [v * (1.0 - m[0]), 0.0 * v]


def test_rate_independent_model_without_branch_energy_is_refused_before_a_run() -> None:
    from prefriction.testing import check_model

    match = r"TwoStatesNoBranchEnergy is rate-independent .* does not implement branch_energy_of_force"
    with pytest.raises(TypeError, match=match):
        pf.simulate(pf.Oscillator(TwoStatesNoBranchEnergy(1e4, 1.0)), 1.0, reversals=3)
    with pytest.raises(TypeError, match=match):
        check_model(TwoStatesNoBranchEnergy(1e4, 1.0))


def test_one_state_model_gets_its_branch_energy_by_quadrature() -> None:
    """The elastic unloading branch stores the triangle ``F~^2 / 2`` (closed form)."""
    import numpy as np

    F = np.array([-0.9, -0.3, 0.0, 0.5])
    np.testing.assert_allclose(NoBranchEnergy(1e4, 1.0).branch_energy_of_force(F, 1.0), 0.5 * F ** 2, rtol=1e-12,
                               atol=1e-16)


@dataclass(frozen=True)
class SelfGamma(pf.Dahl):
    """Reads its own gamma instead of q[0]: every instance would reuse the first one's plant."""

    def rate(self, z, m, v, s, q):
        import casadi as ca

        own = ca.vertcat(self.gamma, *[q[i] for i in range(1, q.numel())]) if isinstance(q, ca.SX) else \
            [self.gamma] + list(q)[1:]
        return pf.Dahl.rate(self, z, m, v, s, own)


def test_check_model_catches_both_mistakes_on_one_instance() -> None:
    from prefriction.testing import check_model

    with pytest.raises(AssertionError, match="must use q, not the instance's numbers"):
        check_model(SelfGamma(1e4, 1.0, 2.5))
    with pytest.raises(TypeError, match=r"events\(\) returned 0 entries"):
        check_model(EventsMissing(1e4, 1.0))
