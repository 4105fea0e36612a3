"""symbolic.branch_model: acados / do-mpc names, and its right-hand side against the stage's
equations (2.1) and Dahl's (3.2) written here in normalised units (dF~/dt~ through the chain rule
of the model's force, independent of the model's rate code)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import prefriction as pf


def test_names_and_shapes_are_those_of_an_acados_model():
    m = pf.symbolic.branch_model(pf.Oscillator(pf.Dahl(sigma=2e6, Fc=3.0), mass=2.5), 1.0, name="stage")
    for field in ("x", "xdot", "u", "p", "f_expl_expr", "f_impl_expr"):
        assert isinstance(getattr(m, field), ca.SX), field
    assert m.name == "stage" and m.x.shape == m.xdot.shape == m.f_expl_expr.shape == (3, 1)
    assert m.u.shape == (1, 1) and m.p.shape == m.p_values.shape + (1,)
    diff = ca.Function("d", [m.x, m.xdot, m.u, m.p], [m.f_impl_expr - (m.xdot - m.f_expl_expr)])
    assert float(ca.norm_inf(diff([0.1, 0.2, 0.3], [1, 2, 3], 0.5, m.p_values))) == 0.0
    assert ca.depends_on(m.f_expl_expr, m.u) and not ca.depends_on(m.f_expl_expr, m.xdot)
    with pytest.raises(ValueError, match="name must be a C identifier"):
        pf.symbolic.branch_model(pf.Oscillator(pf.Dahl(2e6, 3.0), 2.5), 1.0, name="my stage")
    with pytest.raises(TypeError, match="Oscillator"):
        pf.symbolic.branch_model(pf.Dahl(2e6, 3.0), 1.0)


@pytest.mark.parametrize("gamma", [1.0, 2.5, 0.5])
@pytest.mark.parametrize("s", [1.0, -1.0])
def test_right_hand_side_is_the_stage_and_dahls_equation(gamma, s):
    system = pf.Oscillator(pf.Dahl(sigma=2e6, Fc=3.0, gamma=gamma), mass=2.5)
    m = pf.symbolic.branch_model(system, s)
    f = ca.Function("f", [m.x, m.u, m.p], [m.f_expl_expr])
    F = ca.Function("F", [m.x, m.p], [m.force(m.x, m.p)])
    dF = ca.Function("dF", [m.x, m.p], [ca.jacobian(m.force(m.x, m.p), m.x)])
    rng = np.random.default_rng(3)
    for _ in range(20):
        x = np.array([rng.uniform(-5, 5), s * rng.uniform(0.0, 3.0), rng.uniform(0.05, 2.0)])
        u = rng.uniform(-3, 3)
        rhs = np.array(f(x, u, m.p_values)).ravel()
        Fn = float(F(x, m.p_values))
        assert abs(Fn) < 1.0
        assert rhs[0] == x[1]                                  # x~' = v~
        assert rhs[1] == pytest.approx(u - Fn, abs=1e-14)      # v~' = u~ - F~, (2.1) normalised
        dFdt = float(np.array(dF(x, m.p_values)).ravel() @ rhs)
        assert dFdt == pytest.approx(x[1] * (1.0 - s * Fn) ** gamma, rel=1e-10, abs=1e-14)  # (3.2)


def test_reset_is_the_reversal_map_keeping_the_force():
    system = pf.Oscillator(pf.Dahl(sigma=2e6, Fc=3.0), mass=2.5)
    up, down = (pf.symbolic.branch_model(system, s) for s in (1.0, -1.0))
    x = np.array([1.0, 0.0, 0.7])
    after = np.array(up.reset(x, up.p_values)).ravel()
    assert after[0] == x[0] and after[1] == x[1]
    assert float(down.force(after, down.p_values)) == pytest.approx(float(up.force(x, up.p_values)), rel=1e-12)
