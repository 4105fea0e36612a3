"""The start of a Motion fit with a free Dahl exponent from the force balance
(``prefriction/identify/balance_start.py``), against the true values of seeded scipy records
(``prefriction/identify/_success.py``: LSODA between the samples, an encoder after noise)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import prefriction as pf
from prefriction.identify import Motion
from prefriction.identify._success import STAGES, stage_record
from prefriction.identify.balance_start import balance_start
from prefriction.identify.parameters import ParameterSpace

STAGE = dataclasses.replace(STAGES[2], closed=False, stroke=2.0)   # Dahl gamma = 2 + viscous, open loop


@pytest.fixture(scope="module")
def record() -> Motion:
    return stage_record(STAGE, 1000, np.random.default_rng([0, 2]))


def _space(model: pf.FrictionModel, fixed: list[str] | None = None) -> ParameterSpace:
    return ParameterSpace(model, None, fixed, None, mass=4.0, offset=6.0, offset0=0.5)


def test_the_force_balance_finds_gamma_from_a_start_far_off(record: Motion) -> None:
    start = pf.Dahl(sigma=1e6, Fc=6.0, gamma=3.5) + pf.Viscous(4.0)      # sigma 0.5x, Fc 2x, gamma 1.75x
    found = balance_start(start, record, _space(start), None, None, None, True)
    assert found is not None and found.gamma == "gamma"
    dahl, visc = found.model.models
    assert abs(dahl.gamma - 2.0) < 0.3 and abs(dahl.Fc - 3.0) < 0.3 and abs(found.mass - 2.5) < 0.1
    assert abs(found.offset - STAGE.offset) < 0.1
    assert "gamma 3.5 -> " in found.line and "held at" in found.line


def test_no_force_balance_start_without_a_free_gamma_or_with_events(record: Motion) -> None:
    start = pf.Dahl(sigma=1e6, Fc=6.0, gamma=3.5) + pf.Viscous(4.0)
    assert balance_start(start, record, _space(start, ["gamma"]), None, ["gamma"], None, True) is None
    lugre = pf.LuGre(sigma0=1e6, sigma1=50.0, sigma2=4.0, Fc=3.0, Fs=3.0, vs=1e-3)
    assert balance_start(lugre, record, _space(lugre), None, None, None, True) is None
    below = pf.Dahl(sigma=1e6, Fc=6.0, gamma=0.6)        # gamma < 1: in-branch events, not this start
    assert balance_start(below, record, _space(below), None, None, None, True) is None


def test_a_stage_that_stopped_hands_on_its_estimates_only_where_they_follow_the_record(record: Motion) -> None:
    """``continuation.closer_estimates``: the estimates of a stage that did not converge start the next stage only
    where the shooting segments follow the scipy record more closely than at the values before it."""
    from prefriction.identify.continuation import closer_estimates

    truth = STAGE.model()
    space = ParameterSpace(truth, None, None, None, mass=STAGE.mass, offset=3.0, offset0=STAGE.offset)
    exact = dict(space.start)
    off = dict(exact, sigma=1.5 * exact["sigma"], gamma=2.6)
    assert closer_estimates(record, space, off, exact) == exact
    assert closer_estimates(record, space, exact, off) is None
    assert closer_estimates(record, space, exact, dict(off, Fc=float("nan"))) is None


@pytest.mark.parametrize("held_iter", [100, None])
def test_a_long_record_held_from_the_balance_fits_its_window_again_free(monkeypatch, held_iter) -> None:
    """``continuation.fit_motion`` on a record longer than two windows with a held stage: with the
    budget of a start from the force balance (``held_iter``) the stages are the first window with
    ``gamma`` held, the same window with every parameter free, then the record once; without it
    (``held_first``'s holds), the window, the record held, then the record free. The solver is a
    stand-in that converges at once (this tests the order of the stages, not the fit)."""
    from prefriction.identify import continuation, shooting

    n = 2 * continuation.WINDOW + 500
    t = np.arange(n) * 1e-3
    data = Motion(t, 1e-6 * np.sin(7.0 * t), np.zeros(n), None, "zoh")
    truth = STAGE.model()
    space = ParameterSpace(truth, None, None, None, mass=STAGE.mass, offset=3.0, offset0=STAGE.offset)
    held = ParameterSpace(truth, None, ["gamma"], None, mass=STAGE.mass, offset=3.0, offset0=STAGE.offset)
    window = Motion(t[:50], data.x[:50], data.u[:50], None, "zoh")
    calls = []

    def solved(sp: ParameterSpace, theta: np.ndarray) -> shooting.MotionSolution:
        w = np.r_[theta, np.zeros(3)]
        return shooting.MotionSolution(w, np.zeros(50), np.zeros((50, w.size)), None, np.zeros(50), {}, "converged")

    def first_window(model, record, sp, theta, *args):
        calls.append(("first window", record is data, tuple(sp.free)))
        return solved(sp, theta), window, "the window"

    def layouts(model, record, sp, theta, *args):
        calls.append(("window" if record is window else "record" if record is data else "?", True, tuple(sp.free)))
        return solved(sp, theta)

    monkeypatch.setattr(continuation, "_first_window", first_window)
    monkeypatch.setattr(continuation, "solve_layouts", layouts)
    monkeypatch.setattr(continuation, "_settled_without", lambda *args: None)
    continuation.fit_motion(truth, data, space, n_sub=4, max_iter=10, tol=1e-8, held=held, held_iter=held_iter)
    free, kept = tuple(space.free), tuple(held.free)
    assert "gamma" in free and "gamma" not in kept
    if held_iter is not None:
        assert calls == [("first window", True, kept), ("window", True, free), ("record", True, free)]
    else:
        assert calls == [("first window", True, kept), ("record", True, kept), ("record", True, free)]
