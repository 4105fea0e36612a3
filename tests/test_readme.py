"""The README's code runs and prints what the README says it prints."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from _doc_blocks import ROOT, page_blocks, run_block

BLOCKS = page_blocks("README.md")


def _run(code: str) -> str:
    return run_block(code, "README.md")


def test_top_has_exactly_two_commands_and_ci_runs_the_test_command():
    lang, first = BLOCKS[0]
    commands = [line for line in first.splitlines() if line.strip()]
    assert lang == "bash" and len(commands) == 2
    ci = (Path(__file__).resolve().parent.parent / ".ci" / "run").read_text()
    assert commands[1] in ci


def test_quick_start_prints_what_the_readme_shows():
    code = next(body for lang, body in BLOCKS if lang == "python")
    shown = BLOCKS[BLOCKS.index(("python", code)) + 1][1].splitlines()
    printed = _run(code).splitlines()
    assert printed[0] == shown[0]  # |F_50| of simulate and of the exact reference, 9 digits
    assert printed[2] == shown[2]  # the exact map at a = 1
    error = float(printed[1].rsplit(" ", 1)[1])
    assert error < 1e-8  # rtol = 1e-8 run: error within the tolerance


def test_readme_is_short_and_has_no_development_history():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 300
    for phrase in ("this commit", "issue ", "before this", "redesign"):
        assert phrase not in text.lower(), phrase


def test_every_link_and_image_of_the_readme_exists():
    text = (ROOT / "README.md").read_text()
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert any(t.endswith(".png") for t in targets)
    for target in targets:
        if "://" not in target:
            assert (ROOT / target).exists(), target


def test_first_command_runs_the_stage_workflow_that_exists():
    first = [line for line in BLOCKS[0][1].splitlines() if line.strip()][0]
    script = re.search(r"python (examples/\S+\.py)", first).group(1)
    assert (ROOT / script).is_file()


_NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def _same_line(printed: str, shown: str) -> bool:
    """Equal text; every number equal to the digits shown (2 units of the last digit, 1e-3 relative)."""
    if _NUMBER.sub("#", printed) != _NUMBER.sub("#", shown):
        return False
    for got, want in zip(_NUMBER.findall(printed), _NUMBER.findall(shown)):
        mantissa = want.lower().split("e")[0]
        digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
        exponent = int(want.lower().split("e")[1]) if "e" in want.lower() else 0
        unit = 10.0 ** (exponent - digits)
        if abs(float(got) - float(want)) > max(2 * unit, 1e-3 * abs(float(want))):
            return False
    return True


PRINTING = [(i, body) for i, (lang, body) in enumerate(BLOCKS)
            if lang == "python" and i + 1 < len(BLOCKS) and BLOCKS[i + 1][0] == ""]


# the quick start (it prints |F_50|) is compared by test_quick_start_prints_what_the_readme_shows
@pytest.mark.parametrize("index", [i for i, body in PRINTING if "|F_50|" not in body])
def test_every_python_block_prints_what_the_readme_shows(index, tmp_path, monkeypatch):
    """Every README block followed by a 'prints' block: the same lines, numbers to the shown digits."""
    monkeypatch.chdir(tmp_path)  # blocks may write figures
    code = BLOCKS[index][1]
    printed = _run(code).strip().splitlines()
    shown = BLOCKS[index + 1][1].strip().splitlines()
    assert len(printed) == len(shown), (printed, shown)
    for got, want in zip(printed, shown):
        assert _same_line(got, want), (got, want)


def test_every_python_block_runs(tmp_path, monkeypatch):
    """The blocks without a 'prints' block run without error too."""
    monkeypatch.chdir(tmp_path)
    for i, (lang, body) in enumerate(BLOCKS):
        if lang == "python" and i not in dict(PRINTING):
            _run(body)
