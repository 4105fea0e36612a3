"""``examples/model_figures.py`` runs (quick) and its numbers agree with independent references:
the exact reversal tables of Dahl and Maxwell-slip (closed forms), the initial bristle energy
``F0^2 / (2 sigma0)`` of LuGre and its energy balance."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import prefriction as pf
from prefriction.cli.paper import load_example

pytestmark = pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)


def test_model_figures(tmp_path):
    ex = load_example("model_figures")
    r = ex.main(tmp_path, quick=True)
    for png in r["pngs"]:
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000  # 50 dpi
    systems = ex.systems()
    for name in ("Dahl", "Maxwell-slip"):
        tab = r["tables"][name]
        exact = pf.exact_reversals(systems[name], 0.0, len(tab), F0=ex.F0)
        np.testing.assert_allclose(tab.t, exact.t, rtol=1e-8)
        np.testing.assert_allclose(tab.F, exact.F, rtol=1e-8, atol=1e-12)
    rep = r["lugre"]
    sigma0 = systems["LuGre"].friction.sigma0
    assert rep.E_0 == pytest.approx(ex.F0**2 / (2 * sigma0), rel=1e-12)
    assert rep.residual < 1e-6
    assert rep.total_viscous + rep.total_hysteretic == pytest.approx(rep.E_0 - rep.E_p[-1], rel=1e-6)
    assert 0.0 < rep.total_hysteretic < rep.total_viscous  # damping ratio 0.5: mostly viscous
