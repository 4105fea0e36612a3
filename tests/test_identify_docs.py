"""Every python block of docs/identify.md runs and prints what the page shows after it."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

PAGE = (Path(__file__).resolve().parent.parent / "docs" / "identify.md").read_text()
BLOCKS = re.findall(r"```(\w*)\n(.*?)```", PAGE, flags=re.S)
PYTHON = [i for i, (lang, _body) in enumerate(BLOCKS) if lang == "python"]


@pytest.mark.parametrize("i", PYTHON)
def test_block_prints_what_the_page_shows(i, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(BLOCKS[i][1], f"docs/identify.md block {i}", "exec"), {})
    lang, shown = BLOCKS[i + 1]
    assert lang == "" and out.getvalue() == shown


def test_page_has_the_blocks():
    assert len(PYTHON) == 3
