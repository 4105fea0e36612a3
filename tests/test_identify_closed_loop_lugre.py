"""The closed-loop route with LuGre friction sliding fast: the RK4 sub-steps follow the bristle's
relaxation rate, a too coarse step is refused by name, and ``Fs`` (moved as its excess over
``Fc``) is reported as ``Fs``.

Reference independent of the fitter: the record comes from scipy LSODA between the samples
(:mod:`prefriction.identify.synthetic_loop`, written from Canudas de Wit et al. 1995, (1)-(3)), a
PD loop at 5 kHz and a 10 nm encoder.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import prefriction as pf
from prefriction import identify
from prefriction.errors import SolverError
from prefriction.identify.synthetic_loop import ClosedLoop, closed_loop_record, reference_moves

M, RATE = 2.5, 5000.0
WN = 2.0 * math.pi * RATE / 50.0
TRUE = pf.LuGre(sigma0=2e6, sigma1=50.0, sigma2=10.0, Fc=3.0, Fs=4.0, vs=1e-3)
TRUTH = {"sigma0": 2e6, "sigma2": 10.0, "Fc": 3.0, "Fs": 4.0, "offset": 0.2}
LOOP = identify.DigitalLoop(1.0 / RATE, M * WN**2, 1.4 * M * WN)
START = pf.LuGre(sigma0=2.4e6, sigma1=50.0, sigma2=8.0, Fc=2.6, Fs=4.5, vs=1e-3)


def _record(n: int) -> tuple[identify.Motion, np.ndarray]:
    stage = ClosedLoop(TRUE, mass=M, offset=0.2, Kp=M * WN**2, Kd=1.4 * M * WN, quantum=1e-8, dt=1.0 / RATE,
                       noise=1e-8 / 3.0)
    rec = closed_loop_record(stage, n, np.random.default_rng(0), rtol=1e-12)
    data = identify.Motion(rec.t, rec.x, rec.u, M, quantum=1e-8, x_noise=1e-8 / 3.0)
    return data, reference_moves(n, 1.0 / RATE, np.random.default_rng(0))


def test_too_few_substeps_for_the_sliding_bristle_are_refused_by_name():
    data, ref = _record(1400)   # sliding at 0.1 m/s from sample ~1100: sigma0 |v| / Fc ~ 7e4 1/s
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(SolverError, match=r"not finite from sample \d+ .*give substeps= larger"):
            identify.fit_closed_loop(START, data, LOOP, ref, fixed=["sigma1", "vs"], substeps=2)


@pytest.mark.slow  # 64 RK4 sub-steps per sample on 2,500 samples: about 60 s of CPU
def test_lugre_loop_fit_reports_fs_and_lands():
    data, ref = _record(2500)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit_closed_loop(START, data, LOOP, ref, fixed=["sigma1", "vs"])
    assert res.success
    assert res.estimate("Fs") == pytest.approx(res.model.Fs, rel=1e-12)   # Fs itself, not Fs - Fc
    assert res.estimate("Fc") == pytest.approx(res.model.Fc, rel=1e-12)
    for name, value in TRUTH.items():
        assert res.estimate(name) == pytest.approx(value, rel=0.01), (name, res.report())
        lo, hi = res.interval(name)
        assert lo <= res.estimate(name) <= hi
