"""prefriction bench --elements: its systems, table and target decisions (tiny sizes in process)."""

from __future__ import annotations

import numpy as np
import pytest

from prefriction.cli.bench import main
from prefriction.cli.bench.elements import ElementRow, element_rows, element_system, element_table, element_targets


def test_element_systems_sum_to_their_scales() -> None:
    ms, gms = element_system("MaxwellSlip", 5).friction, element_system("GMS", 5).friction
    assert ms.n_elements == gms.n_elements == 5
    assert ms.Fc == pytest.approx(1.0) and ms.sigma == pytest.approx(1.5e4)
    assert np.sum(gms.alpha) == pytest.approx(1.0)


def test_rows_compile_into_an_empty_cache_and_time_the_runs() -> None:
    rows = element_rows((2,), models=("MaxwellSlip",))
    assert len(rows) == 1 and rows[0].n == 2 and rows[0].compile_s > 0.0 and rows[0].per_reversal_s > 0.0


def test_targets_and_table() -> None:
    good = [ElementRow("MaxwellSlip", 3, 0.5, 50e-6), ElementRow("MaxwellSlip", 30, 1.9, 700e-6)]
    assert "PASS" in element_targets(good, False)[0] and "1.40x linear" in element_targets(good, False)[0]
    slow = [ElementRow("MaxwellSlip", 3, 0.5, 50e-6), ElementRow("MaxwellSlip", 30, 2.1, 700e-6)]
    steep = [ElementRow("MaxwellSlip", 3, 0.5, 50e-6), ElementRow("MaxwellSlip", 30, 1.9, 800e-6)]
    assert "FAIL" in element_targets(slow, False)[0] and "FAIL" in element_targets(steep, False)[0]
    assert "PASS" in element_targets(steep, True)[0]
    assert "not measured" in element_targets(good[:1], False)[0]
    assert "  1.40" in element_table(good)


def test_elements_excludes_the_other_sections(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit):
        main(["--elements", "--models"])
    with pytest.raises(SystemExit):
        main(["--elements", "--repeats", "2"])
    assert "--elements" in capsys.readouterr().err
