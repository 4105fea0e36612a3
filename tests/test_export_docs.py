"""docs/export.md: every python block runs and prints what the page shows after it.

Lines that name a temporary directory are compared up to it, the time per step by its form
(it is this machine's); every other line exactly.
"""

from __future__ import annotations

import re

import pytest
from _doc_blocks import ROOT, page_blocks, run_block

from prefriction import export

PAGE = (ROOT / "docs" / "export.md").read_text()
BLOCKS = page_blocks("docs/export.md")
PYTHON = [(i, body) for i, (lang, body) in enumerate(BLOCKS) if lang == "python"]


def _run(code: str) -> str:
    return run_block(code, "docs/export.md")


def _same(shown: str, printed: str) -> bool:
    if " in /tmp/" in shown:
        return printed.startswith(shown.split(" in /tmp/")[0] + " in /")
    if shown.endswith("ns per step"):
        return re.fullmatch(r"\d+ ns per step", printed) is not None
    if shown == "/usr/bin/gcc":
        return printed.endswith("gcc")
    if _roundoff(shown) and _roundoff(printed):  # a rounding-level difference: its digits vary with the build
        return shown.rsplit("=", 1)[0] == printed.rsplit("=", 1)[0]
    return printed == shown


def _roundoff(line: str) -> bool:
    """A line ending ``= <number>`` with the number below 1e-13 (a difference at double rounding)."""
    m = re.search(r"= ([0-9.]+e-\d+)$", line)
    return m is not None and float(m.group(1)) < 1e-13


@pytest.mark.skipif(export.gcc() is None, reason="gcc is not on the PATH: the page's examples compile C")
@pytest.mark.parametrize(("index", "code"), PYTHON, ids=[f"block{i}" for i, _ in PYTHON])
def test_block_prints_what_the_page_shows(index, code):
    lang, shown = BLOCKS[index + 1]
    assert lang == "", f"block {index} is not followed by its output"
    printed = _run(code).splitlines()
    shown_lines = shown.splitlines()
    assert len(printed) == len(shown_lines), (printed, shown_lines)
    for s, p in zip(shown_lines, printed):
        assert _same(s, p), (s, p)


def test_page_has_its_timing_table_and_examples_of_every_public_name():
    assert "TIMING_TABLE" not in PAGE
    code = "\n".join(body for _i, body in PYTHON)
    for name in export.__all__:
        if name not in ("CRun", "CSource", "PlantRun", "LoopRun"):  # results, shown by their use
            assert f"export.{name}" in code, name
