"""Every python block of docs/identify.md runs and prints what the page shows after it."""

from __future__ import annotations

import pytest
from _doc_blocks import page_blocks, run_block

BLOCKS = page_blocks("docs/identify.md")
PYTHON = [i for i, (lang, _body) in enumerate(BLOCKS) if lang == "python"]


@pytest.mark.parametrize("i", PYTHON)
def test_block_prints_what_the_page_shows(i, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    printed = run_block(BLOCKS[i][1], f"docs/identify.md block {i}")
    lang, shown = BLOCKS[i + 1]
    assert lang == "" and printed == shown


def test_page_has_the_blocks():
    assert len(PYTHON) == 4
