"""The identification examples run (quick mode, under Agg) and recover the true parameters.

References independent of the fitter: the Dahl closed-form branches (the data of
``fit_dahl_loops``); for Maxwell-slip the stop operators of ``prefriction.identify.synthetic``,
checked here against the closed-form virgin curve ``sum_i min(k_i x, W_i)``, Masing's first
unloading branch and its return to the virgin curve; for LuGre scipy's Radau
(``synthetic.lugre_force``), checked here against the closed-form response at a constant
velocity. The examples are imported from their files, as a fresh clone runs them.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.identify.synthetic import lugre_force, maxwell_slip_force

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def example(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"identify_examples.{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def check_png(png: Path) -> None:
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def within(res: identify.FitResult, truth: np.ndarray, k: float = 3.0) -> None:
    z = np.abs(res.estimates - truth) / res.stderr
    assert np.all(z <= k), (z, res.report())


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_fit_dahl_loops_example(tmp_path):
    ex = example("fit_dahl_loops")
    r = ex.main(tmp_path, quick=True)
    check_png(r["png"])
    res = r["result"]
    within(res, np.array([ex.TRUE.sigma, ex.TRUE.Fc, ex.TRUE.gamma]))
    assert res.statistics.sigma_hat == pytest.approx(0.01 * ex.TRUE.Fc, rel=0.2)
    assert r["seeds"] == 5 and set(r["coverage"]) == {"sigma", "Fc", "gamma"}
    assert "Fc" in r["pre_sliding"].unidentifiable and "sigma" not in r["pre_sliding"].unidentifiable


def test_maxwell_slip_data_follow_the_virgin_curve_and_masing_branch():
    ex = example("fit_maxwell_slip")
    t = np.linspace(0.0, 3.0, 301)
    x = ex.loops(t)
    F = maxwell_slip_force(ex.TRUE, x)
    k, W = np.asarray(ex.TRUE.stiffness), np.asarray(ex.TRUE.slip_force)

    def virgin(y: np.ndarray) -> np.ndarray:
        return np.minimum(np.outer(y, k), W).sum(axis=1)

    r = int(np.argmax(x[: t.size // 6]))          # first peak (t = 0.25 s)
    m = r + int(np.argmin(x[r: t.size // 3]))      # the next trough
    np.testing.assert_allclose(F[: r + 1], virgin(x[: r + 1]), rtol=1e-12, atol=1e-15)
    # Masing's unloading branch down to -x[r], where it meets the virgin curve; beyond, the virgin curve
    down = np.arange(r, m + 1)
    masing = x[down] >= -x[r]
    np.testing.assert_allclose(F[down[masing]], F[r] - 2.0 * virgin((x[r] - x[down[masing]]) / 2.0), rtol=1e-12,
                               atol=1e-14)
    np.testing.assert_allclose(F[down[~masing]], -virgin(-x[down[~masing]]), rtol=1e-12, atol=1e-14)
    assert x[r] > 4e-6 and masing.sum() > 10 and (~masing).sum() > 5  # element 0 slips at the peak


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_fit_maxwell_slip_example(tmp_path):
    ex = example("fit_maxwell_slip")
    r = ex.main(tmp_path, quick=True)
    check_png(r["png"])
    res = r["result"]
    assert isinstance(res.model, pf.MaxwellSlip) and res.unidentifiable == ()
    within(res, np.concatenate([ex.TRUE.stiffness, ex.TRUE.slip_force]))
    assert res.statistics.sigma_hat == pytest.approx(ex.NOISE, rel=0.15)
    # elements 2 and 3 with one slip deflection: only their sums are determined
    assert set(r["tied"].unidentifiable) == {"stiffness[2]", "stiffness[3]", "slip_force[2]", "slip_force[3]"}
    # one sub-step per sample is the stop operator itself: noise-free data give the truth to round-off
    t, x = r["t"], r["x"]
    exact = identify.fit(ex.START, identify.ForceDisplacement(t, x, maxwell_slip_force(ex.TRUE, x)))
    np.testing.assert_allclose(exact.estimates, np.concatenate([ex.TRUE.stiffness, ex.TRUE.slip_force]), rtol=1e-7)


def test_lugre_reference_matches_the_closed_form_at_constant_velocity():
    model = pf.LuGre(sigma0=1.0e5, sigma1=300.0, sigma2=40.0, Fc=1.0, Fs=1.5, vs=1.0e-3)
    v = 1.5e-3
    t = np.linspace(0.0, 0.05, 51)
    F = lugre_force(model, t, lambda tt: v + 0.0 * np.asarray(tt), [])
    g = model.Fc + (model.Fs - model.Fc) * np.exp(-(v / model.vs) ** 2)
    z = g / model.sigma0 * -np.expm1(-model.sigma0 * v * t / g)
    exact = model.sigma0 * z + model.sigma1 * (v - model.sigma0 * v * z / g) + model.sigma2 * v
    np.testing.assert_allclose(F, exact, rtol=1e-7, atol=1e-9)


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_fit_lugre_example(tmp_path):
    ex = example("fit_lugre")
    r = ex.main(tmp_path, quick=True)
    check_png(r["png"])
    res = r["result"]
    truth = np.array([getattr(ex.TRUE, p.name) for p in type(ex.TRUE).parameters])
    assert isinstance(res.model, pf.LuGre) and res.names == tuple(p.name for p in type(ex.TRUE).parameters)
    within(res, truth)
    assert res.statistics.sigma_hat == pytest.approx(ex.NOISE, rel=0.1)
    # without noise the fit lands on the truth: the bias of the prescribed-motion discretisation is
    # a small fraction of the standard error
    t = r["t"]
    clean = identify.fit(ex.START, identify.ForceDisplacement(t, ex.position(t), r["clean"]))
    assert np.all(np.abs(clean.estimates - truth) <= 0.2 * res.stderr), (clean.estimates - truth) / res.stderr
