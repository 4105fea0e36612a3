"""prefriction bench --quick: table, CSV, PNG and the three target lines; the error metric."""

from __future__ import annotations

import csv
import math

import numpy as np

from prefriction.cli.bench import HEADLINE, main, reversal_error
from prefriction.cli import main as cli_main
from prefriction.reversals import ReversalTable


def _table(t: np.ndarray, x: np.ndarray, F: np.ndarray) -> ReversalTable:
    z = np.zeros(len(t))
    return ReversalTable(t=t, x=x, F=F, E_p=z, E_d=z, E_0=0.0)


def test_reversal_error_metric() -> None:
    t = np.arange(1.0, 51.0)
    x = np.full(50, 1e-6)  # below Fc / sigma = 1e-4 m: relative to 1e-4
    F = np.linspace(1.0, 0.1, 50)
    ref = _table(t, x, F)
    assert reversal_error(HEADLINE, t, x, F, ref) == 0.0
    assert math.isclose(reversal_error(HEADLINE, t, x + 1e-12, F, ref), 1e-8, rel_tol=1e-6)
    assert math.isclose(reversal_error(HEADLINE, t * (1 + 1e-9), x, F, ref), 1e-9, rel_tol=1e-6)
    assert math.isclose(reversal_error(HEADLINE, t, x, F * (1 - 3e-7), ref), 3e-7, rel_tol=1e-6)
    assert reversal_error(HEADLINE, t[:49], x[:49], F[:49], ref) == math.inf  # a missed reversal


def test_quick_bench_writes_table_csv_png(tmp_path, capsys) -> None:
    code = cli_main(["bench", "--quick", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code in (0, 1)
    for needle in ("simulate[erk]", "scipy DOP853 +events", "scipy LSODA |v| form", "python-control |v| form",
                   "gamma=0", "energy ratio=1e-20", "sigma/Fc=1e+10", "mass=1e-06 kg", "F0=-0.999999 Fc",
                   "JIT compile"):
        assert needle in out, needle
    targets = [line for line in out.splitlines() if line.startswith("target")]
    assert len(targets) == 3
    assert all(("PASS" in line) or ("FAIL" in line) for line in targets)
    assert "ratio" in targets[1]
    assert (code == 0) == all("PASS" in line for line in targets)
    with (tmp_path / "bench.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert {"case", "solver", "tol", "max_rel_error", "warm_run_s", "compile_s"} <= set(rows[0])
    sim = [r for r in rows if r["solver"] == "simulate[erk]" and r["case"] == HEADLINE.name]
    assert len(sim) >= 2 and all(float(r["max_rel_error"]) <= 10 * float(r["tol"]) for r in sim)
    png = (tmp_path / "work_precision.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert "pass" in (tmp_path / "stability.txt").read_text()


def test_bench_help_and_bad_option(capsys) -> None:
    try:
        main(["--help"])
    except SystemExit as exc:
        assert exc.code == 0
    assert "--stability" in capsys.readouterr().out


def test_models_bench_quick(tmp_path, capsys) -> None:
    """``prefriction bench --models --quick``: Maxwell-slip against its closed form and scipy."""
    code = cli_main(["bench", "--models", "--quick", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code in (0, 1)
    assert "MaxwellSlip N=3" in out and "scipy DOP853 +events" in out
    targets = [line for line in out.splitlines() if line.startswith("target models/")]
    assert len(targets) == 2 and "accuracy" in targets[0] and "PASS" in targets[0]
    with (tmp_path / "models.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    sim = [r for r in rows if r["solver"] == "simulate[erk]"]
    assert len(sim) == 2 and all(float(r["max_rel_error"]) <= 10 * float(r["tol"]) for r in sim)
