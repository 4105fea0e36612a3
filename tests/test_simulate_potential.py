"""The branch potential behind the speed at model events (``docs/simulator.md#event-speed``):
Dahl's ``H(p)`` for gamma < 1 on floats and CasADi symbols against the independent force form
``H_gamma(f) = int_0^f phi (1 - phi)^-gamma dphi`` of :func:`prefriction.analysis.branch.branch_potential`."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import prefriction as pf
from prefriction.analysis.branch import branch_potential
from prefriction.models.dahl import p_of_force


@pytest.mark.parametrize("gamma", [0.0, 0.1, 0.3, 0.7, 0.95])
def test_dahl_branch_potential_is_the_stored_energy_of_the_force(gamma: float) -> None:
    model = pf.Dahl(1e4, 1.0, gamma)
    P = ca.SX.sym("p")
    Q = ca.SX.sym("q")
    sym = ca.Function("H", [P, Q], [model.branch_potential([P], [0.0], 1.0, [Q])])
    H_sat = 1.0 / ((1.0 - gamma) * (2.0 - gamma))  # the energy to saturation
    for f in np.linspace(-1.0, 1.0, 41):
        p = p_of_force(float(f), gamma)
        want = float(branch_potential(np.array(f), gamma))
        got = model.branch_potential([p], [0.0], 1.0, [gamma])
        # p + ((1 - e p)^(1/e + 1) - 1) / (1 + e): the terms linear in p cancel, so the error is
        # round-off of p, not of H (what the speed at saturation needs: H(1/e) - H(p) to 1e-14 H_sat)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-14 * H_sat)
        assert float(sym(p, gamma)) == pytest.approx(got, rel=1e-14, abs=1e-16)
    assert model.branch_potential([1.0 / (1.0 - gamma)], [0.0], 1.0, [gamma]) == pytest.approx(H_sat, rel=1e-14)
    assert pf.Dahl(1e4, 1.0, 1.5).branch_potential([0.1], [], 1.0, [1.5]) is None  # no events
