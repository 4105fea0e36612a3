"""prefriction bench --sweep --quick: compiles per structure, cold and warm, errors; the scipy peer."""

from __future__ import annotations

import csv
import math

import numpy as np

import prefriction as pf
from prefriction.cli.bench import main as bench_main
from prefriction.cli.bench_sweep import QUICK_VALUES, main, reversal_error, scipy_reversals, sweep_cases


def test_quick_sweep_bench(tmp_path, monkeypatch, capsys) -> None:
    cache = tmp_path / "parent_cache"
    cache.mkdir()
    monkeypatch.setenv("PREFRICTION_CACHE", str(cache))
    monkeypatch.delenv("PREFRICTION_NO_JIT", raising=False)
    out = tmp_path / "out"
    code = main(["--quick", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    targets = [line for line in text.splitlines() if line.startswith(("T1", "T2"))]
    assert len(targets) == 2 and all("PASS" in line for line in targets), targets

    with (out / "sweep.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    cases = sweep_cases(QUICK_VALUES)
    assert [(r["case"], r["run"]) for r in rows] == [(c.label, run) for c in cases for run in ("cold", "warm")]
    for r in rows:
        assert int(r["n_values"]) == QUICK_VALUES
        expected = 1 if r["run"] == "cold" else 0  # one structure per case, fresh cache for the cold run
        assert int(r["compiles"]) == expected and int(r["compile_lines"]) == expected, r
        assert float(r["max_rel_error"]) < 1e-7, r
        assert float(r["scipy_error"]) < 1e-5, r
        assert float(r["end_to_end_s"]) > 0 and float(r["scipy_s"]) > 0 and float(r["ratio"]) > 0
    # the parent process only runs scipy: nothing is compiled into its own cache
    assert not list(cache.glob("*.so"))


def test_scipy_peer_matches_exact_reversals() -> None:
    for gamma in (0.5, 2.0):  # saturating and non-saturating branches
        system = pf.Oscillator(pf.Dahl(1e4, 1.0, gamma), mass=1.0)
        sc = pf.Scales.of(system)
        R = scipy_reversals(gamma, 1.0 / sc.v, 1e-11, n=20)
        ref = pf.exact_reversals(system, 1.0, 20)
        err = reversal_error(R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F, ref.t, ref.x, ref.F)
        assert err < 1e-8, (gamma, err)


def test_reversal_error_counts_reversals() -> None:
    t = np.arange(1.0, 6.0)
    assert reversal_error(t, t, t, t, t, t) == 0.0
    assert math.isclose(reversal_error(t * (1 + 1e-9), t, t, t, t, t), 1e-9, rel_tol=1e-6)
    assert reversal_error(t[:4], t[:4], t[:4], t, t, t) == math.inf


def test_bench_help_lists_sweep(capsys) -> None:
    try:
        bench_main(["--help"])
    except SystemExit as exc:
        assert exc.code == 0
    assert "--sweep" in capsys.readouterr().out
