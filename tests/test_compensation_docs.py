"""Every python block of docs/compensation.md runs, and the quick start prints what the page shows."""

from __future__ import annotations

import pytest
from _doc_blocks import page_blocks, run_block

BLOCKS = page_blocks("docs/compensation.md")
PYTHON = [body for lang, body in BLOCKS if lang == "python"]


def _run(code: str) -> str:
    return run_block(code, "docs/compensation.md")


def test_page_has_python_blocks():
    assert len(PYTHON) >= 4


@pytest.mark.parametrize("index", range(len(PYTHON)))
def test_block_runs(index):
    printed = _run(PYTHON[index])
    assert printed.strip()


def test_quick_start_prints_what_the_page_shows():
    shown = BLOCKS[BLOCKS.index(("python", PYTHON[0])) + 1][1].strip()
    assert _run(PYTHON[0]).strip() == shown


def test_inline_outputs_match():
    assert _run(PYTHON[1]).split() == ["0.1", "1e-05", "0.0002"]
    assert _run(PYTHON[3]).strip() == "['state', 'meas', 'ref', 'params'] -0.005365 N"
