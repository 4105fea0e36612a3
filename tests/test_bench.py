"""prefriction bench: the error metric, the timing rule, the peers, the stiff cases and the rows
against independent references in-process with tiny sizes; the targets, tables, CSV and figure
on constructed rows; options, --help and --loops; one end-to-end CLI run (bench --models --quick)."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

import prefriction as pf
from prefriction.cli import main as cli_main
from prefriction.cli.bench import (HEADLINE, Case, Row, StabilityRow, format_rows, headline, linear_cost, main,
                                   reversal_error, stability, stability_cases, targets)
from prefriction.cli.bench import reference_rows as rr
from prefriction.cli.bench.costs import analytics_timing
from prefriction.cli.bench.peers import scipy_events, scipy_noevents
from prefriction.cli.bench.report import (headline_section, plot, reference_section, stiff_section,
                                          write_csv)
from prefriction.cli.bench.timing import min_time
from prefriction.cli.bench.work_precision import peer_rows, simulate_point
from prefriction.reversals import ReversalTable


def _table(t: np.ndarray, x: np.ndarray, F: np.ndarray) -> ReversalTable:
    z = np.zeros(len(t))
    return ReversalTable(t=t, x=x, F=F, E_p=z, E_d=z, E_0=0.0)


@pytest.fixture(scope="module")
def headline_ref() -> ReversalTable:
    """The exact table of the headline case, 100 reversals."""
    return pf.exact_reversals(HEADLINE.system, HEADLINE.v0, 100)


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
    assert reversal_error(HEADLINE, t, x, F * np.nan, ref) == math.inf  # never a silent NaN


def _fake_calls(durations: list[float]):
    """A timed call whose k-th call 'takes' durations[k] seconds (read back through ``seconds``)."""
    calls = iter(durations)
    return lambda: next(calls), lambda d: d


@pytest.mark.parametrize(("durations", "kwargs", "n_calls", "best"), [
    ([0.3, 0.2, 0.4], dict(calls=3), 3, 0.2),                                   # exactly `calls`
    ([0.3, 0.6, 0.1], dict(calls=3, stop_best=0.5), 3, 0.1),                    # best stays < 0.5
    ([0.7, 0.1], dict(calls=3, stop_best=0.5), 1, 0.7),                         # one slow call
    ([0.01] * 40, dict(calls=2, most=500, fill=0.1), 10, 0.01),                 # fill 0.1 s
    ([1e-6] * 600, dict(calls=2, most=500, fill=1.0), 500, 1e-6),               # at most 500
    ([0.06, 0.01], dict(most=math.inf, fill=1.0, stop_best=0.05), 1, 0.06),    # slow: no repeat
    ([0.01, 0.2, 0.3, 0.5, 0.1], dict(most=math.inf, fill=1.0, stop_best=0.05), 4, 0.01),  # fill 1 s
    ([2.0, 2.5, 3.0, 1.0], dict(calls=4, stop_spent=4.0), 2, 2.0),              # budget spent
])
def test_min_time_stopping_rules(durations: list[float], kwargs: dict, n_calls: int, best: float) -> None:
    fn, seconds = _fake_calls(durations)
    last, got = min_time(fn, seconds=seconds, **kwargs)
    assert got == best and last == durations[n_calls - 1]


def test_peers_against_the_exact_table_and_their_rows() -> None:
    """The peers with restarts and on the |v| form against exact_reversals (python-control, ~10 s,
    runs in the bench only); a failing peer is a row with an infinite error, a slow one skips its
    tighter tolerances."""
    case = Case("small", 1e4, 1.0, 1.0, 0.005)  # short first excursion: a short |v|-form span
    ref = pf.exact_reversals(case.system, case.v0, 50)
    t, x, F = scipy_noevents(case, 1e-6, "DOP853")  # across the kinks at v = 0: less accurate
    assert reversal_error(case, t, x, F, ref) < 1e-3

    def broken(tol: float) -> tuple:
        raise RuntimeError(f"no convergence at {tol:g}")

    solvers = [("scipy DOP853 +events", lambda tol: scipy_events(case, tol, "DOP853")), ("broken", broken)]
    rows = peer_rows(case, ref, solvers, [1e-6, 1e-9], 1, budget=0.0)
    assert [r.solver for r in rows] == ["scipy DOP853 +events"] * 2 + ["broken"] * 2
    assert rows[0].tol == 1e-6 and rows[0].error < 1e-5 and rows[0].seconds > 0
    assert math.isnan(rows[1].tol) and rows[1].note.startswith("tighter tolerances skipped (run took")
    assert [(r.tol, r.error, r.note) for r in rows[2:]] == [
        (1e-6, math.inf, "failed: no convergence at 1e-06"),
        (1e-9, math.inf, "failed: no convergence at 1e-09")]  # a failure takes no time: no skip
    text = format_rows(rows)
    assert "tighter tolerances skipped" in text and "failed: no convergence at 1e-09" in text


def test_simulate_rows_and_stability_in_process(headline_ref: ReversalTable) -> None:
    row = simulate_point(HEADLINE, 1e-6, "erk", headline_ref, 2, min_seconds=0.0)
    assert row.solver == "simulate[erk]" and row.error <= 10 * row.tol and row.seconds > 0
    assert [r.solver for r in headline([1e-6], 1, peers=False, budget=0.0)] == ["simulate[native]", "simulate[erk]"]
    stab, points = stability([1e-6], 100, 1e-8, cases=[HEADLINE])
    assert len(points) == 1 and stab[0].n_long == 100 and stab[0].passed and stab[0].energy_drift < 1e-6
    names = [c.name for c in stability_cases()]
    for needle in ("gamma=0", "energy ratio=1e-20", "sigma/Fc=1e+10", "mass=1e-06 kg", "F0=-0.999999 Fc"):
        assert any(needle == n.split(",")[0] or needle == n for n in names), needle
    t50, tl = linear_cost(1e-6, 100, 1)
    assert 0 < t50 < 1e-2 and 0 < tl < 1e-2


def test_analytics_timing_lines() -> None:
    lines = analytics_timing(1, n_amp=1000, n_rev=100)
    assert lines[0].startswith("next_amplitude on 1e+03 amplitudes") and "x numpy.exp" in lines[0]
    assert lines[1].startswith("exact_reversals, 100 reversals of the headline case")


def test_stability_rows_against_their_references() -> None:
    # the forced row's reference has the 30 reversals of the issue (0.5 sin(5 t) N, 2.5133 s)
    forced = next(c for c in rr.row_cases(quick=True) if c.expected)
    assert len(rr.reference(forced)) == 30
    # energy row: an elastic Prandtl stop keeps F^2 / (2 sigma) = m v0^2 / 2 at every reversal
    energy = rr.RowCase("gamma=0 elastic", 0.0, 0.005, n=40, metric="energy")
    res = rr.measure(energy, (1e-6,))
    assert res.n_sim == (40,) and res.passed
    # a saturating row (scipy DOP853 rtol 1e-13 with restarts at reversals and saturation)
    sat = rr.RowCase("gamma=0.3 saturating", 0.3, 0.02, n=6)
    res = rr.measure(sat, (1e-6,))
    assert res.n_ref == 6 and res.n_sim == (6,) and res.passed
    text = reference_section([res])
    assert "PASS" in text and "rtol 1e-06" in text and "scipy DOP853 rtol 1e-13" in text
    got = np.zeros((5, 3))
    assert rr.row_error(sat, got, np.zeros((6, 3))) == math.inf  # a missing reversal


def _rows(err: float) -> list[Row]:
    return [Row("h", "simulate[native]", 1e-8, err, 1e-3), Row("h", "scipy DOP853 +events", 1e-9, 5e-9, 0.05)]


def test_targets_decide_from_the_measured_rows() -> None:
    stab = [StabilityRow("c", 2.0, 1e-6, 1e-9, 1e-8, 500, 1e-8, 0.01, 1e-9, True)]
    ok = rr.RowResult("r", "positions", (1.0, 9.0), (1e-6, 1e-9), 10, (10, 10))
    bad = rr.RowResult("r", "positions", (math.inf, 1.0), (1e-6, 1e-9), 10, (9, 10))
    lines = targets(_rows(5e-9), stab, 1e-5, 1.2e-5, 500, [1e-8], [ok])
    assert len(lines) == 3 and all(line.startswith("target") and "PASS" in line for line in lines)
    assert "ratio 50.0x" in lines[1] and "ratio 1.20" in lines[2]
    lines = targets(_rows(5e-7), stab, 1e-5, 1.6e-5, 500, [1e-8], [ok])
    assert "FAIL" in lines[0] and lines[1].startswith("target 2: not measured") and "FAIL" in lines[2]
    assert "FAIL" in targets(_rows(5e-9), stab, 1e-5, 1e-5, 500, [1e-8], [bad])[0]
    slow = [Row("h", "simulate[native]", 1e-8, 5e-9, 1e-2), Row("h", "scipy DOP853 +events", 1e-9, 5e-9, 0.05)]
    assert "FAIL  ratio 5.0x" in targets(slow, stab, 1e-5, 1e-5, 500, [1e-8], [ok])[1]


def test_outputs_tables_csv_and_png(tmp_path) -> None:
    rows = _rows(5e-9) + [Row("h", "simulate[erk]", 1e-6, 4e-7, 8e-4)]
    text = headline_section(rows)
    assert text.startswith("Headline case: " + HEADLINE.name) and text.endswith(format_rows(rows))
    assert "simulate[erk]" in text and "scipy DOP853 +events" in text and "0.40" in text  # err/tol
    stab = [StabilityRow("case c", 2.0, 1e-6, 1e-9, 1e-8, 500, 1e-8, 0.01, 1e-9, False)]
    text = stiff_section(stab, [1e-6, 1e-9], 500)
    assert "ladder 1e-06..1e-09" in text and "all-500 error" in text and text.rstrip().endswith("FAIL")
    write_csv(tmp_path / "bench.csv", rows)
    with (tmp_path / "bench.csv").open() as fh:
        got = list(csv.DictReader(fh))
    assert {"case", "solver", "tol", "max_rel_error", "warm_run_s", "compile_s"} <= set(got[0]) and len(got) == 3
    assert [float(r["max_rel_error"]) for r in got] == [r.error for r in rows]
    plot(tmp_path / "wp.png", rows)
    png = (tmp_path / "wp.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_help_is_plain_text(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for option in ("--stability", "--sweep", "--models", "--loops", "docs/bench.md"):
        assert option in out
    assert "``" not in out and ":func:" not in out


@pytest.mark.parametrize(("argv", "message"), [
    (["--repeats", "-1"], "argument --repeats: must be an integer in [1, 1000], got '-1'"),
    (["--repeats", "0"], "got '0'"),
    (["--repeats", "2.5"], "got '2.5'"),
    (["--repeats", "1001"], "got '1001'"),
    (["--models", "--sweep"], "not allowed with argument"),
    (["--loops", "--stability"], "not allowed with argument"),
    (["--models", "--repeats", "3"], "--repeats applies to the headline and stability sections"),
    (["--loops", "--quick"], "--quick does not apply to --loops"),
    (["--loops", "--out", "x"], "--out does not apply to --loops"),
    (["--out", "/dev/null/x"], "argument --out: cannot create the directory '/dev/null/x'"),
    (["--out", "/proc/no/such/dir"], "argument --out: cannot create the directory"),
    (["--unknown"], "unrecognized arguments: --unknown"),
])
def test_bad_options_are_argparse_errors(argv: list[str], message: str, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_out_must_be_a_directory(tmp_path, capsys) -> None:
    path = tmp_path / "file.txt"
    path.write_text("x")
    with pytest.raises(SystemExit):
        main(["--out", str(path)])
    assert "must be a directory" in capsys.readouterr().err


def test_loops_runs_the_loop_benchmark(monkeypatch, capsys) -> None:
    """``bench --loops --repeats 1``: the loop benchmark's table (its real run, shortened to 3 ms and
    no sweep or lengths here), printed; exit status 0 exactly when every target line says PASS."""
    from controllers import benchmark
    from prefriction.cli import bench_loops

    seen = {}

    def short_run(**kwargs: int) -> str:
        seen.update(kwargs)
        return benchmark.run(t_end=0.003, repeats=kwargs["repeats"], sweep=0, lengths=())

    monkeypatch.setattr(bench_loops, "run", short_run)
    code = main(["--loops", "--repeats", "1"])
    out = capsys.readouterr().out
    verdicts = [line.split()[-1] for line in out.splitlines() if line.endswith(("PASS", "FAIL"))]
    assert seen == {"repeats": 1} and "simulate_loop" in out and len(verdicts) == 3
    assert code == (0 if verdicts == ["PASS"] * 3 else 1)


def test_models_bench_quick_end_to_end(tmp_path, capsys) -> None:
    """``prefriction bench --models --quick`` from the command line entry point: Maxwell-slip
    against its closed form and scipy DOP853; table, target lines and models.csv."""
    code = cli_main(["bench", "--models", "--quick", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert "MaxwellSlip N=3" in out and "scipy DOP853 +events" in out
    targets_ = [line for line in out.splitlines() if line.startswith("target models/")]
    assert len(targets_) == 2 and "accuracy" in targets_[0] and "PASS" in targets_[0]
    assert (code == 0) == all("PASS" in line for line in targets_)
    with (tmp_path / "models.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    sim = [r for r in rows if r["solver"] == "simulate[native]"]
    assert len(sim) == 2 and all(float(r["max_rel_error"]) <= 10 * float(r["tol"]) for r in sim)
