"""Runs from several threads at once equal the same runs made one after another, bit for bit.

Runs of one structure share one compiled Function per process; each thread calls it through
its own buffers (prefriction.simulation.per_thread). Before, threads wrote into each other's
buffers: results differed silently, tables were truncated, runs failed at negative times.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

import prefriction as pf
from prefriction import controllers

GAMMAS = [1.0, 1.5, 2.0, 3.0]


def _dahl_run(gamma: float) -> pf.SimulationResult:
    return pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1.0, gamma)), 1.0, reversals=60)


def _same(a: pf.SimulationResult, b: pf.SimulationResult) -> bool:
    ra, rb = a.reversals, b.reversals
    return (len(ra) == len(rb) and a.status == b.status
            and all(np.array_equal(getattr(ra, k), getattr(rb, k)) for k in ("t", "x", "F")))


def test_simulate_from_four_threads_equals_serial() -> None:
    serial = [_dahl_run(g) for g in GAMMAS]
    with ThreadPoolExecutor(4) as pool:
        for _ in range(4):
            threaded = list(pool.map(_dahl_run, GAMMAS * 2))
            assert all(_same(s, r) for s, r in zip(serial * 2, threaded))


def _loop_run(step: float) -> np.ndarray:
    stage = pf.Oscillator(pf.Dahl(sigma=1e6, Fc=1.0))
    Cd = controllers.design_pid(stage, wn=2 * np.pi * 150.0, zeta=0.7).c2d(1e-4)
    return controllers.simulate_loop(stage, Cd, step, 0.05).x


def test_sampled_loop_from_four_threads_equals_serial() -> None:
    steps = [1e-6, 2e-6, 3e-6, 5e-6]
    serial = [_loop_run(s) for s in steps]
    with ThreadPoolExecutor(4) as pool:
        for _ in range(4):
            threaded = list(pool.map(_loop_run, steps * 2))
            assert all(np.array_equal(s, r) for s, r in zip(serial * 2, threaded))


def test_motion_fits_from_threads_equal_serial() -> None:
    """identify.fit on motion data shares one IPOPT problem per layout: threads take turns on the
    solve (concurrent solves crashed the process with a segmentation fault)."""
    import warnings

    from prefriction import identify
    from prefriction.identify.synthetic import dahl_free_decay

    true, mass = pf.Dahl(sigma=1.0e4, Fc=1.0, gamma=1.0), 1.0
    t = np.linspace(0.0, 16.0 * np.sqrt(mass / true.sigma), 81)
    clean = dahl_free_decay(true, mass, 1.2 / np.sqrt(true.sigma), t, 0.0, np.random.default_rng(0)).x

    def fit(seed: int) -> np.ndarray:
        x = clean + 3e-7 * np.random.default_rng(seed).standard_normal(clean.size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return identify.fit(pf.Dahl(1.3e4, 0.8, 1.0), identify.Motion(t, x, 0.0, mass), fixed=["gamma"]).estimates

    serial = [fit(s) for s in range(4)]
    with ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(fit, range(4)))
    assert all(np.array_equal(a, b) for a, b in zip(serial, threaded))
