"""The no-drift property (docs/models.md#elasto-plastic): under a biased oscillating force below
breakaway the elasto-plastic model settles to the periodic motion of the linear oscillator
``m x'' + (sigma1 + sigma2) x' + sigma0 x = u`` (closed form), while LuGre drifts."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

_FILE = Path(__file__).resolve().parent.parent / "examples" / "elasto_plastic_drift.py"
_spec = importlib.util.spec_from_file_location("elasto_plastic_drift", _FILE)
drift = importlib.util.module_from_spec(_spec)
sys.modules["elasto_plastic_drift"] = drift
_spec.loader.exec_module(drift)


def test_no_drift_below_breakaway_where_lugre_drifts(tmp_path):
    out = drift.main(tmp_path, quick=True)
    assert out["png"].is_file()
    assert out["drift"]["LuGre"] > 5e-7  # about 1.1 um per cycle
    assert abs(out["drift"]["elasto-plastic"]) < 1e-15
    # the elasto-plastic motion is the periodic solution of the linear oscillator (elastic bristle)
    p = drift.LUGRE
    res = drift.run(drift.models()["elasto-plastic"], 20)
    w = 2 * np.pi * drift.FREQUENCY
    H = 1.0 / (p["sigma0"] - drift.MASS * w ** 2 + 1j * w * (p["sigma1"] + p["sigma2"]))
    # u = BIAS + A sin(w t) = BIAS + Im(A e^{i w t})
    x_ss = drift.BIAS / p["sigma0"] + np.imag(drift.AMPLITUDE * H * np.exp(1j * w * res.t))
    last = res.t > 15 / drift.FREQUENCY  # the transient (damping ratio 0.67) has decayed by e^-60
    np.testing.assert_allclose(res.x[last], x_ss[last], rtol=0, atol=1e-9 * np.ptp(x_ss))
    assert np.max(res.x) < drift.Z_BA  # the bristle never reaches breakaway
