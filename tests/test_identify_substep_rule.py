"""The RK4 sub-steps of Motion fits with Dahl gamma > 1 (prefriction.identify.substep_rule).

References independent of the code under test: the closed form of Dahl's branch at gamma = 2
(``dw/dx~ = -w^2``: ``1 / w = 1 / w0 + travel``), and scipy's LSODA integration of the loop's
equations (prefriction.identify.synthetic_loop) for the positions at the truth.

Accuracy criterion: a change ``dr`` of the position residuals moves a least-squares estimate by
``(J'J)^-1 J' dr``, which in standard errors ``sigma sqrt(diag (J'J)^-1)`` is at most
``|dr| / sigma`` (Cauchy-Schwarz), ``sigma`` the position noise of the record (Gaussian ``q / 3``
before rounding to the encoder step ``q``, plus the rounding's ``q / sqrt(12)``). So if the
residuals at the truth move by ``|dr| <= 0.02 sigma`` between the rule's count and twice it, no
estimate moves by more than 0.02 of its standard error.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from prefriction.identify import _success as S
from prefriction.identify import shooting as sh
from prefriction.identify.motion_predict import _simulator
from prefriction.identify.motion_start import derivatives
from prefriction.identify.substep_rule import follows_data, rates_along
from prefriction.identify.synthetic_loop import _interval, _rhs
from prefriction.models.dahl import Dahl
from prefriction.models.lugre import LuGre
from prefriction.models.viscous import Viscous
from prefriction.units import Scales


def test_which_models_follow_the_data():
    """Only a Dahl term with gamma > 1 (alone or summed) takes the rule along the record."""
    assert follows_data(Dahl(sigma=2e6, Fc=3.0, gamma=2.0))
    assert follows_data(Dahl(sigma=2e6, Fc=3.0, gamma=1.5) + Viscous(8.0))
    assert not follows_data(Dahl(sigma=2e6, Fc=3.0, gamma=1.0))
    assert not follows_data(Dahl(sigma=2e6, Fc=3.0, gamma=0.6) + Viscous(8.0))
    assert not follows_data(LuGre(sigma0=2e6, sigma1=50.0, sigma2=10.0, Fc=3.0, Fs=3.0, vs=1e-3))


def test_rates_along_a_record_match_the_closed_form_branch_at_gamma_two():
    """Dahl gamma = 2 along a sine velocity (one reversal): the gap of the closed form
    ``1 / w = 1 / w0 + travel`` (travel in ``Fc / sigma`` since the branch began, ``w0 = 1`` from
    rest, ``w0 = 2 - w`` after the reversal), ``omega = w`` and ``lambda = |v~| w``."""
    sigma, Fc, mass = 2e6, 3.0, 2.5
    T, V = math.sqrt(mass / sigma), Fc / math.sqrt(mass * sigma)
    t = np.linspace(0.0, 40.0 * T, 401)
    v = 3.0 * V * np.sin(2.0 * math.pi * t / t[-1] + 0.3)
    omega, lam = rates_along(Dahl(sigma=sigma, Fc=Fc, gamma=2.0), t, v, mass)
    vn, dtn = v / V, np.diff(t) / T
    w, w_ref, seg_sign = 1.0, np.empty(t.size), 1.0
    for i in range(t.size):       # the exact step of sample i holds the sample's velocity to i + 1
        if np.sign(vn[i]) != seg_sign:
            seg_sign, w = -seg_sign, 2.0 - w
        w_ref[i] = w
        if i < t.size - 1:
            w = 1.0 / (1.0 / w + abs(vn[i]) * dtn[i])
    assert np.sum(np.diff(np.sign(vn)) != 0) == 2
    np.testing.assert_allclose(omega, w_ref, rtol=1e-9)
    np.testing.assert_allclose(lam, np.abs(vn) * w_ref, rtol=1e-9)


def _truth_states(stage: S.Stage, data) -> np.ndarray:
    """``(x, v, F)`` at every sample: scipy's LSODA on the loop's equations under the record's force."""
    rhs = _rhs(stage.loop)
    Y = np.zeros((len(data), 3))
    for k in range(len(data) - 1):
        Y[k + 1] = _interval(rhs, Y[k], float(data.t[k]), float(data.t[k + 1]), float(data.u[k]), 1e-10)
    return Y


def _segment_errors(stage: S.Stage, data, Y: np.ndarray, n_sub: int, K: int = 50) -> np.ndarray:
    """Positions of the fit's one-sample step (``n_sub`` RK4 sub-steps) over segments of ``K``
    samples, each started at the true state, minus the true positions [m]."""
    model, m, off = stage.model(), stage.mass, stage.offset
    sc = Scales(x=model.Fc / model.sigma, F=model.Fc, t=math.sqrt(m / model.sigma),
                v=model.Fc / math.sqrt(m * model.sigma), E=model.Fc**2 / model.sigma)
    pp = np.r_[m, model.sigma, model.Fc, off, np.asarray(model.runtime_params_for(sc), float)]
    sim = _simulator(model, n_sub, K)
    err = []
    for j in range(0, len(data) - K, K):
        x0, v0, F0 = Y[j]
        s0 = 1.0 if v0 > 0 else -1.0 if v0 < 0 else (1.0 if data.u[j] - off - F0 >= 0 else -1.0)
        z0, m0 = model.initial_state(F0 / model.Fc, s0)
        u = data.u[None, j:j + K]
        out = np.asarray(sim(np.r_[x0, v0, z0, m0, s0], u, u, np.diff(data.t)[None, j:j + K], pp))
        err.append(out[0] - Y[j + 1:j + K + 1, 0])
    return np.concatenate(err)


@pytest.mark.parametrize("gamma", [pytest.param(1.5, marks=pytest.mark.slow), 2.0,
                                   pytest.param(3.0, marks=pytest.mark.slow)])
def test_rule_count_holds_the_objective_at_the_truth(gamma):
    """The 2.5 kg, 2 kHz, 10 nm closed-loop stage of the success harness (Dahl + viscous +
    offset, 600 samples): at the truth the residuals with the rule's count are within 0.05 noise
    rms of scipy's positions and move by at most 0.02 of it at twice the count (estimates move by
    at most 0.02 standard errors, module text); one sub-step is far off (the check can fail)."""
    base = S.STAGES[2]
    stage = dataclasses.replace(base, friction=dataclasses.replace(base.friction, gamma=gamma))
    data = S.stage_record(stage, 600, np.random.default_rng([0, 2]))
    Y = _truth_states(stage, data)
    noise = math.hypot(stage.quantum / 3.0, stage.quantum / math.sqrt(12.0))
    _x, v, _a = derivatives(data.t, data.x, sh._NODE_WINDOW)
    n = sh._substeps(stage.model(), data, stage.mass, v, None)
    assert 1 < n <= 20
    r1 = _segment_errors(stage, data, Y, n)
    r2 = _segment_errors(stage, data, Y, 2 * n)
    assert np.linalg.norm(r1) <= 0.05 * noise
    assert np.linalg.norm(r1 - r2) <= 0.02 * noise
    assert np.linalg.norm(_segment_errors(stage, data, Y, 1)) > 1.0 * noise
