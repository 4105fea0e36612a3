"""``prefriction bench --along``: its rows on a short record (every model within 1e-9 of its scipy
reference) and the option."""

from __future__ import annotations

import numpy as np

import prefriction.along.bench as along_bench
from prefriction.cli.bench import main
from prefriction.cli.bench.options import parse


def test_rows_meet_the_accuracy_target(monkeypatch):
    def short(n):  # the first second of the bench's record: 8 reversals
        t = np.linspace(0.0, 1.0, n)
        return t, 3e-5 * np.sin(2 * np.pi * t) + 1.2e-5 * np.sin(2 * np.pi * 4.3 * t + 0.4)

    monkeypatch.setattr(along_bench, "record", short)
    rows = along_bench.rows(repeats=1, n=1_000, n_ref=100)
    assert [r.name for r in rows] == ["Dahl gamma=1", "Dahl gamma=0.5", "MaxwellSlip(3)", "GMS(3)", "LuGre",
                                      "Dahl + Viscous"]
    assert all(r.error <= along_bench.TARGET_ERR for r in rows), rows
    assert all(r.seconds > 0.0 and r.scipy_seconds > 0.0 for r in rows)


def test_option_selects_the_section(monkeypatch, capsys, tmp_path):
    assert parse(["--along", "--out", str(tmp_path)]).along
    monkeypatch.setattr(along_bench, "rows", lambda repeats, n_ref: [along_bench.Row("Dahl gamma=1", 0.1, 1e-15, 30.0)])
    assert main(["--along", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "Dahl gamma=1" in out and "PASS" in out
