"""The shipped tribometer record: intact, licensed, converted to SI, packaged."""

from __future__ import annotations

import gzip
import hashlib
import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from prefriction.data import tribometer
from prefriction.identify import ForceDisplacement

ROOT = Path(__file__).resolve().parents[1]


def test_file_is_the_upstream_one_with_its_licence():
    folder = resources.files("prefriction.data") / "tribometer"
    readme = (folder / "README.md").read_text()
    digest = re.search(r"sha256\s+`([0-9a-f]{64})`", readme).group(1)
    raw = gzip.decompress((folder / "test_data_2.txt.gz").read_bytes())
    assert hashlib.sha256(raw).hexdigest() == digest
    assert len(raw) == 1_579_921
    licence = (folder / "LICENSE").read_text()
    assert licence.startswith("MIT License") and "Jason Christopherson" in licence
    assert "FrictionModels.jl" in readme and "MIT" in readme


def test_si_conversion_against_the_raw_text():
    raw = gzip.decompress((resources.files("prefriction.data") / "tribometer" / "test_data_2.txt.gz").read_bytes())
    rows = raw.decode().splitlines()
    assert rows[0].split("\t") == ["Time [s]", "Normal [uN]", "Position [mm]", "Friction [uN]"]
    first, k = rows[1].split("\t"), 20_001
    row_k = [float(v) for v in rows[k].split("\t")]
    rec = tribometer()
    assert len(rec) == 42_579 == len(rows) - 1
    assert rec.t[k - 1] == row_k[0]
    assert rec.normal[k - 1] == pytest.approx(row_k[1] * 1e-6, rel=1e-12)
    assert rec.x[k - 1] == pytest.approx((row_k[2] - float(first[2])) * 1e-3, abs=1e-15)
    assert rec.F[k - 1] == pytest.approx(-row_k[3] * 1e-6, rel=1e-12)
    assert 0.22e-3 < np.ptp(rec.x) < 0.25e-3            # 0.23 mm stroke
    assert 4.9 < np.median(rec.normal[(rec.t > 10) & (rec.t < 200)]) < 5.1   # 5 N load
    assert 2.2 < rec.F.max() < 2.7 and -2.6 < rec.F.min() < -2.2
    assert not rec.F.flags.writeable
    assert "TribometerRecord(42579 samples" in repr(rec)


def test_window_and_its_checks():
    rec = tribometer()
    d = rec.window(12.0, 60.0, step=4)
    assert isinstance(d, ForceDisplacement) and d.t[0] >= 12.0 and d.t[-1] <= 60.0
    assert len(d) == len(np.flatnonzero((rec.t >= 12.0) & (rec.t <= 60.0))[::4])
    with pytest.raises(ValueError, match="start, stop"):
        rec.window(60.0, 12.0)
    with pytest.raises(ValueError, match="step"):
        rec.window(12.0, 60.0, step=0)
    with pytest.raises(ValueError, match="holds 1 samples"):
        rec.window(12.0, 12.004)


def test_wheel_declares_the_data_files():
    text = (ROOT / "pyproject.toml").read_text()
    assert '"prefriction.data" = ["tribometer/*"]' in text


def test_docstring_example_runs():
    import doctest

    import prefriction.data

    assert doctest.testmod(prefriction.data).failed == 0
