"""``prefriction paper``: the command runs every figure, prints progress and writes report.md."""

from __future__ import annotations

import re

import matplotlib

matplotlib.use("Agg")

import pytest

from prefriction import cli
from prefriction.cli.paper import FIGURES, examples_dir


def test_paper_command_writes_report_and_every_png(tmp_path, capsys):
    out = tmp_path / "paper_out"
    assert cli.main(["paper", "--out", str(out), "--quick"]) == 0
    printed = capsys.readouterr().out
    for name in FIGURES:
        assert re.search(rf"\] {name}\s+\d+\.\d\d s  ok", printed), name
        png = out / f"{name}.png"
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = (out / "report.md").read_text(encoding="utf-8")
    for name in FIGURES:
        assert f"]({name}.png)" in report
    assert "## Erratum in (3.13)" in report
    assert "E_p(F_i) / (Fc (1 - r^(3/5)))" in report
    assert "0.306853 Fc^2/sigma" in report
    assert "## Where the toolbox disagrees with the paper" in report
    # the error table carries the values of docs/mathematics.md#erratum-3-13: +0.15 % at a = 1, -5.05 % at 0.6, -12.11 % at 0.2
    assert re.search(r"\| 1 \| 0\.59362\d+ \| [\d.]+ \| \+0\.15 % \|", report)
    assert re.search(r"\| 0\.6 \| [\d.]+ \| [\d.]+ \| -5\.05 % \|", report)
    assert re.search(r"\| 0\.2 \| [\d.]+ \| [\d.]+ \| -12\.11 % \|", report)
    assert "Not produced" not in report


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

