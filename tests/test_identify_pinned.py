"""Honest outcomes at bounds and the parameters the data cannot pin down (issue 25).

References independent of the fitter: the records come from scipy's DOP853 integration of Dahl's
published equation (3.2) with every reversal and saturation located as an event
(prefriction.identify.synthetic_events); the shape factor of the reversal transient is checked
against scipy's integration of the branch ``dF/dx = sigma (1 - s F / Fc)^gamma``; which parameters a
small-amplitude record cannot separate follows from the expansion of that branch near ``F = 0``
(``dF/dx = sigma (1 - gamma s F / Fc + ...)``: only ``gamma / Fc`` enters at first order).
"""

from __future__ import annotations

import importlib
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import identify
from prefriction.identify.motion_start import secant
from prefriction.identify.pinned import unpinned
from prefriction.identify.statistics import ConvergenceWarning, IdentifiabilityWarning
from prefriction.identify.synthetic_events import event_record

sys.path.insert(0, str(Path(__file__).parent))
from test_identify_motion_events import MODELS, _drive, _start  # noqa: E402  the record and starts of the event fits


@pytest.mark.parametrize("gamma", [0.6, 1.0, 1.5, 2.0, 3.0])
def test_secant_of_the_reversal_transient_matches_the_integrated_branch(gamma):
    """The secant slope over the first third of the change from ``-Fc`` (closed form) against
    scipy's integration of ``dF/dx = sigma (1 + F / Fc)^gamma`` (motion in +x) from ``F = -Fc``."""
    sigma, Fc = 2e6, 3.0

    def rhs(_x, F):
        return [sigma * max(1.0 - F[0] / Fc, 0.0) ** gamma]

    def third(_x, F):
        return F[0] - (-Fc + 2.0 * Fc / 3.0)
    third.terminal = True
    F0 = -Fc * (1.0 - 1e-12) if gamma >= 1.0 else -Fc   # the asymptote itself is a fixed point of the rate
    sol = solve_ivp(rhs, (0.0, 100.0 * Fc / sigma), [F0], events=third, rtol=1e-12, atol=1e-15, method="DOP853")
    travel = float(sol.t_events[0][0])
    assert secant(gamma) == pytest.approx((2.0 * Fc / 3.0) / travel / sigma, rel=1e-6)


def test_unpinned_tells_an_unpinned_bound_from_a_pinned_one():
    """gamma at 0 with an interval wider than [0, 1): unpinned; a viscous coefficient at 0 with a
    small standard error (a stage without viscous friction): pinned; gamma at the structure
    boundary 1: not this case (structures='both' crosses it)."""
    names = ["gamma", "b", "gamma2"]
    est = np.array([0.0, 0.0, 1.0])
    se = np.array([4.3, 0.01, 5.0])
    low, high = est - 2.0 * se, est + 2.0 * se
    scale = np.array([0.4, 8.0, 1.5])
    lower = {"gamma": 0.0, "b": 0.0, "gamma2": 1.0}
    upper = {"gamma": 1.0, "b": math.inf, "gamma2": 10.0}
    why_low = {"gamma": "the declared range", "b": "the declared range", "gamma2": "the Dahl structure boundary"}
    why_high = dict.fromkeys(names, "the declared range")
    found = unpinned(names, est, se, low, high, scale, lower, upper, why_low, why_high, 0.5)
    assert [n for n, _ in found] == ["gamma"]
    assert "lower bound 0" in found[0][1] and "wider than its allowed range" in found[0][1]


@pytest.mark.slow
def test_noisy_dahl_fit_on_the_gamma_bound_is_not_called_a_success(monkeypatch):
    """The noisy Dahl (gamma 0.6 + offset) record of seed 0 from 1.5x, without the continuation
    in gamma: the solver stops at gamma = 0 with a standard error of about 4 (about 25 s on a
    loaded machine: slow). The result says it is no success, names gamma and what helps;
    FitResult.unidentifiable names it too."""
    fit_module = importlib.import_module("prefriction.identify.fit")
    monkeypatch.setattr(fit_module, "_gamma_continuation", lambda *a, **k: (None, "continuation off (test)"))
    with pytest.warns(ConvergenceWarning, match="cannot pin down gamma"):
        res, _truth = _noisy_gamma_fit(0)
    gamma = res.names.index("gamma")
    assert not res.success
    assert res.estimates[gamma] < 1e-6
    assert "cannot pin down gamma" in res.message and "fixed=['gamma']" in res.message
    assert "longer record" in res.message
    assert "gamma" in res.unidentifiable
    assert "NOT CONVERGED" in res.summary() and "not identifiable: gamma" in res.summary()
    assert "cannot pin down gamma" in res.report()


@pytest.mark.slow
@pytest.mark.parametrize("seed, factor", [(0, 1.5), (5, 2.0)])
def test_continuation_in_gamma_lands_the_noisy_fits_that_ended_on_the_bound(seed, factor):
    """The same records with the pipeline as shipped: seed 0 from 1.5x is refitted with gamma held
    at its start, then freed; seed 5 from a random start within 2x (a fit that once ended on gamma = 0) lands,
    with or without that continuation.
    Both land within 5 % of every parameter (the issue's success criterion) with intervals that
    hold the truth (about 20-60 s each: slow)."""
    model, _fixed = MODELS["dahl"]
    t, u = _drive(model, 300)
    data = event_record(model, 1.0, t, u, offset=0.1, noise=0.01 * model.Fc / model.sigma,
                        rng=np.random.default_rng(seed))
    if factor == 1.5:
        start, off0 = _start("dahl", 1.5), None
    else:
        rng = np.random.default_rng([seed, 7, 200])
        f = [math.exp(rng.uniform(-math.log(2.0), math.log(2.0))) for _ in range(3)]
        start = pf.Dahl(1e5 * f[1], 1.0 * f[2], min(0.6 * f[0], 0.95))
        off0 = 0.1 + rng.uniform(-math.log(2.0), math.log(2.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(start, data, offset=True, offset0=off0)
    truth = dict(sigma=model.sigma, Fc=model.Fc, gamma=model.gamma, offset=0.1)
    assert res.success, res.message
    if factor == 1.5:
        assert any(line.startswith("continuation in gamma") and "its result kept" in line for line in res.start)
    for n, v in truth.items():
        assert abs(res.estimate(n) - v) <= 0.05 * (model.Fc if n == "offset" else v), (n, res.estimate(n))
        lo, hi = res.interval(n)
        assert lo <= v <= hi, (n, lo, v, hi)


def _noisy_gamma_fit(seed: int):
    """The noisy Dahl record and 1.5x start of tests/test_identify_motion_events.py, warnings kept."""
    model, _fixed = MODELS["dahl"]
    t, u = _drive(model, 300)
    data = event_record(model, 1.0, t, u, offset=0.1, noise=0.01 * model.Fc / model.sigma,
                        rng=np.random.default_rng(seed))
    res = identify.fit(_start("dahl", 1.5), data, offset=True)
    truth = dict(sigma=model.sigma, Fc=model.Fc, gamma=model.gamma, offset=0.1)
    return res, np.array([truth[n] for n in res.names])


@pytest.mark.slow
def test_small_amplitude_record_does_not_pin_gamma_and_the_result_says_so():
    """Dahl gamma 0.6 driven at 2 % of Fc (the motion stays within 0.2 Fc / sigma): near F = 0
    the branch is ``dF/dx = sigma (1 - gamma s F / Fc + ...)``, so gamma enters only through the
    small curvature ``gamma / Fc``. The fit (started at the truth, 30 iterations: about 10 s on a
    loaded machine) names gamma in FitResult.unidentifiable and its summary, with an
    IdentifiabilityWarning, while sigma (the slope at F = 0) stays identified within 3 %."""
    model = pf.Dahl(1e5, 1.0, 0.6)
    T = math.sqrt(1.0 / model.sigma)
    t = np.arange(300) * 0.1 * T
    u = 0.02 * (np.sin(2 * np.pi * t / (10 * T)) + 0.2 * np.sin(2 * np.pi * t / (3.3 * T)))
    data = event_record(model, 1.0, t, u, noise=0.01 * model.Fc / model.sigma, rng=np.random.default_rng(1))
    assert np.ptp(data.x) < 0.2 * model.Fc / model.sigma
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = identify.fit(model, data, max_iter=30)
    said = " ".join(str(w.message) for w in caught if issubclass(w.category, IdentifiabilityWarning))
    assert "gamma" in res.unidentifiable and "sigma" not in res.unidentifiable, res.unidentifiable
    assert "cannot identify gamma" in said
    assert "not identifiable: gamma" in res.summary()
    assert "NOT IDENTIFIABLE from these data: gamma" in res.report()
    assert not res.success
    sigma = res.names.index("sigma")
    assert abs(res.estimates[sigma] - model.sigma) < 0.03 * model.sigma
