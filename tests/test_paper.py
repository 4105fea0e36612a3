"""``prefriction paper``: options, progress lines, report, failures and where the figure scripts are found."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest

from prefriction import cli
from prefriction.cli import paper
from prefriction.cli.paper import FIGURES, examples_dir


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_paper_command_runs_the_scripts_prints_progress_and_writes_the_report(tmp_path, capsys, monkeypatch):
    # the command's plumbing on two cheap scripts; every script and the full report are
    # checked in tests/test_examples.py, which runs each figure once
    names = ("fig5_force_displacement", "fig3_potential_energy")
    monkeypatch.setattr(paper, "FIGURES", names)
    out = tmp_path / "new" / "paper_out"
    assert cli.main(["paper", "--out", str(out), "--quick"]) == 0
    printed = capsys.readouterr().out
    for k, name in enumerate(names, 1):
        assert re.search(rf"\[ ?{k}/2\] {name}\s+\d+\.\d\d s  ok", printed), printed
        png = out / f"{name}.png"
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {out / 'report.md'} and 2 figures in" in printed
    report = (out / "report.md").read_text(encoding="utf-8")
    assert f"`prefriction paper --out {out} --quick`" in report
    for name in names:
        assert f"]({name}.png)" in report
    assert "## Erratum in (3.13)" in report and "Not produced" not in report


def test_paper_command_reports_a_failing_script_and_exits_1(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(paper, "FIGURES", ("fig3_potential_energy",))

    def broken(name):
        raise RuntimeError(f"{name} broke")

    monkeypatch.setattr(paper, "load_example", broken)
    out = tmp_path / "paper_out"
    assert cli.main(["paper", "--out", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "FAILED: RuntimeError: fig3_potential_energy broke" in printed
    assert "failed: fig3_potential_energy" in printed
    assert "**Not produced**: `RuntimeError: fig3_potential_energy broke`" in (out / "report.md").read_text(encoding="utf-8")


def test_paper_command_needs_out(capsys):
    with pytest.raises(SystemExit) as err:
        cli.main(["paper"])
    assert err.value.code == 2
    assert "--out" in capsys.readouterr().err


def test_examples_dir_holds_every_figure_script():
    d = examples_dir()
    for name in FIGURES:
        assert (d / f"{name}.py").is_file()


@pytest.mark.parametrize("kind", ["file", "under_a_file"])
def test_paper_command_refuses_an_unwritable_out(tmp_path, capsys, kind):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    out = blocker if kind == "file" else blocker / "sub"
    with pytest.raises(SystemExit) as err:
        cli.main(["paper", "--out", str(out), "--quick"])
    assert err.value.code == 2
    printed = capsys.readouterr()
    assert "--out" in printed.err and str(out) in printed.err
    assert "Traceback" not in printed.err and printed.out == ""


def test_paper_help_is_plain_text(capsys):
    with pytest.raises(SystemExit) as err:
        cli.main(["paper", "--help"])
    assert err.value.code == 0
    text = capsys.readouterr().out
    assert "--out DIR" in text and "report.md" in text
    for rest in ("``", ":func:", ":class:", ".. ", "Parameters\n"):
        assert rest not in text



def test_examples_dir_is_found_beside_the_package_from_any_directory(tmp_path, monkeypatch):
    beside = Path(paper.__file__).resolve().parents[1] / "examples"  # prefriction/examples (installed with it)
    if not (beside / "fig3_potential_energy.py").is_file():
        pytest.skip("prefriction is imported from an installed copy, not the source tree")
    monkeypatch.chdir(tmp_path)
    assert examples_dir() == beside
    monkeypatch.setattr(paper, "__file__", str(tmp_path / "site-packages" / "prefriction" / "cli" / "paper.py"))
    with pytest.raises(FileNotFoundError, match="examples/fig"):
        examples_dir()
