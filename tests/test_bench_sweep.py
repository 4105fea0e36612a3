"""prefriction bench --sweep, in-process with tiny sizes: the child's body against exact_reversals,
one warm child process (no compile), the matched-error scipy peer, the target decisions, the
table and CSV, --help and --out."""

from __future__ import annotations

import csv
import dataclasses
import math
import shutil

import numpy as np
import pytest

import prefriction as pf
from prefriction.cli.bench import main as bench_main
from prefriction.cli.bench.sweep import (ChildRun, SweepRow, exact_tables, format_table, main, match_notes,
                                         matched_rtol, reversal_error, run_child, scipy_reversals, sweep_cases, targets,
                                         worker, write_csv)
from prefriction.cli.bench.sweep.measure import _child_row
from prefriction.simulation.compiled import cache_dir

SPEC = {"case": "gamma_ge1", "n": 2, "reference": None}


def test_worker_against_exact_reversals() -> None:
    """The child's body in this process: a sweep of 2 gamma values, errors vs exact_reversals."""
    rep = worker(SPEC, 0.25)
    assert rep["failed"] == 0 and rep["import_s"] == 0.25 and len(rep["errors"]) == 2
    assert rep["error"] < 1e-7 and rep["sweep_s"] > 0 and rep["sim_wall_s"] > 0


def test_warm_child_process_compiles_nothing(monkeypatch, tmp_path) -> None:
    """A new process that finds the structure in the cache: no new library, no compile line."""
    monkeypatch.delenv("PREFRICTION_NO_JIT", raising=False)
    worker(SPEC, 0.0)  # the structure is in this process's cache (compiled or loaded)
    # the child gets a copy of the cache: another test worker may compile into the shared one meanwhile
    private = shutil.copytree(cache_dir(), tmp_path / "cache")
    child = run_child(SPEC, private)
    assert child.new_libraries == 0 and child.compile_lines == 0
    assert child.report["error"] < 1e-7 and child.report["failed"] == 0
    # a row of warm children: the least time, the most compiles, a failed value (None) is inf
    slower = ChildRun(dict(child.report, sweep_s=2 * child.report["sweep_s"], error=None), 1, 1)
    row = _child_row(sweep_cases(2)[0], "warm", [slower, child], "exact_reversals")
    assert row.end_to_end_s == child.report["sweep_s"] and (row.compiles, row.compile_lines) == (1, 1)
    assert row.max_rel_error == math.inf and row.repeats == 2 and row.n_values == 2
    assert row.jit == ",".join(f"{k}:{v}" for k, v in sorted(child.report["jit"].items()))


def test_matched_scipy_rtol_reaches_the_target() -> None:
    case = sweep_cases(2)[0]
    refs = exact_tables(case)
    rtol, matched, tried = matched_rtol(case, refs, 1e-8)
    assert matched and tried[-1] == (rtol, tried[-1][1]) and tried[-1][1] <= 1e-8
    assert all(err > 1e-8 for _, err in tried[:-1])  # the loosest rtol that matches


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


def _row(case: str, run: str, compiles: int, ratio: float, error: float = 1e-9) -> SweepRow:
    return SweepRow(case=case, run=run, n_values=4, compiles=compiles, compile_lines=compiles, end_to_end_s=0.1,
                    per_value_ms=25.0, import_s=0.5, setup_s=0.01, sim_wall_s=0.05, max_rel_error=error,
                    reference="exact_reversals", scipy_rtol=1e-10, scipy_s=0.1 * ratio, scipy_error=5e-9,
                    ratio=ratio, repeats=1, jit="cached:4")


def test_targets_table_and_csv(tmp_path) -> None:
    cases = sweep_cases(4)
    good = [_row(c.label, run, 1 if run == "cold" else 0, 30.0) for c in cases for run in ("cold", "warm")]
    lines = targets(good, cases, quick=False)
    assert [line[:2] for line in lines] == ["T1", "T2"] and all("PASS" in line for line in lines)
    slow = [dataclasses.replace(r, ratio=5.0) for r in good]
    assert "FAIL" in targets(slow, cases, quick=False)[0] and "PASS" in targets(slow, cases, quick=True)[0]
    twice = [dataclasses.replace(r, compiles=2, compile_lines=2) if r.run == "cold" else r for r in good]
    assert all("FAIL" in line for line in targets(twice, cases, quick=False))
    assert match_notes(good) == []  # scipy's sweep error 5e-9 is within 1e-8
    loose = [dataclasses.replace(r, scipy_error=3e-8) for r in good]
    notes = match_notes(loose)
    assert len(notes) == 3 and all("ratios are lower bounds" in n and "3.0e-08 > 1.0e-08" in n for n in notes)
    text = format_table(good)
    assert all(c.label in text for c in cases) and "30.0x" in text
    write_csv(tmp_path / "sweep.csv", good)
    with (tmp_path / "sweep.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["case"], r["run"]) for r in rows] == [(c.label, run) for c in cases for run in ("cold", "warm")]
    assert set(rows[0]) == {f.name for f in dataclasses.fields(SweepRow)}


def test_help_and_out(tmp_path, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        bench_main(["--help"])
    assert exc.value.code == 0 and "--sweep" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0 and "--quick" in out and "``" not in out and ":func:" not in out
    (tmp_path / "f").write_text("")
    with pytest.raises(SystemExit) as exc:
        main(["--out", str(tmp_path / "f")])
    assert exc.value.code == 2 and "must be a directory" in capsys.readouterr().err


def test_scaling_targets_and_table() -> None:
    """T3 from made-up rows: the speed-up thresholds, a failed run, no dask, --quick."""
    from prefriction.cli.bench.sweep import ScaleRow, format_scaling, scale_systems, scaling_targets

    good = [ScaleRow(1000, 0.5, 2.0, 1.2, 1.4, 0, 2e-3, 1.9e-3, 0.9e-3), ScaleRow(10_000, 0.5, 20.0, 12.0, 14.0, 0, 2e-3, 1.9e-3, 0.9e-3)]
    assert "PASS" in scaling_targets(good, False)[0] and "PASS" in scaling_targets(good, False)[1]
    slow_sweep = [ScaleRow(10_000, 0.5, 20.0, 12.0, 14.0, 0, 2e-3, 1.6e-3, 0.9e-3)]  # 1.25x one simulate
    assert "FAIL" in scaling_targets(slow_sweep, False)[1] and "PASS" in scaling_targets(slow_sweep, True)[1]
    far_from_c = [ScaleRow(10_000, 0.5, 20.0, 12.0, 14.0, 0, 2e-3, 1.9e-3, 0.7e-3)]  # 2.86x plain C
    assert "FAIL" in scaling_targets(far_from_c, False)[1]
    slow_pool = [good[0], ScaleRow(10_000, 0.5, 20.0, 12.6, 14.0, 0)]  # 1.59x
    assert "FAIL" in scaling_targets(slow_pool, False)[0] and "PASS" in scaling_targets(slow_pool, True)[0]
    slow_dask = [good[0], ScaleRow(10_000, 0.5, 20.0, 12.0, 14.4, 0)]  # 1.39x
    assert "FAIL" in scaling_targets(slow_dask, False)[0]
    assert "FAIL" in scaling_targets([good[0], ScaleRow(10_000, 0.5, 20.0, 12.0, 14.0, 1)], False)[0]
    no_dask = [ScaleRow(1000, 0.5, 2.0, 1.2, math.nan, 0)]
    assert "PASS" in scaling_targets(no_dask, False)[0] and "not installed" in scaling_targets(no_dask, False)[0]
    table = format_scaling(good)
    assert "10,000" in table and "1.67x" in table and "1.43x" in table and "  1.05 " in table and "  2.22" in table
    assert "dask at" not in table  # no CPU times: no breakdown line
    timed = ScaleRow(10_000, 0.5, 20.0, 12.0, 14.0, 0, serial_cpu_s=19.6, dask_parent_cpu_s=0.5, dask_worker_cpu_s=20.4)
    # 2 x 14 s = 28 s of cores: runs 19.6 s, workers' other 0.8 s, parent 0.5 s, rest 7.1 s
    assert timed.dask_breakdown() == ("dask at 10,000, 2 x 14.00 s of cores: runs 70%, workers' other CPU 3% "
                                      "(0.080 ms/system), parent CPU (scheduler, client, sweep) 2% (0.050 ms/system), "
                                      "idle or other processes 25% (0.710 ms/system)")
    assert timed.dask_breakdown() in format_scaling([timed])
    a, b = scale_systems(3), scale_systems(3)
    assert [s.friction.gamma for s in a] == [s.friction.gamma for s in b]
    assert all(1.0 <= s.friction.gamma <= 3.0 and 1e3 <= s.friction.sigma <= 1e5 for s in a)
