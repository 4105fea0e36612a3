"""Every python code block of every docs page runs, verbatim.

The blocks of a page run in order in one namespace (a later block may use an earlier one's
names), from a temporary working directory (blocks may write files); a block that defines
``test_*`` functions has them called (over their ``pytest.mark.parametrize`` values). Pages that colleagues test with their own test are left
to those tests. Signatures and shell commands are fenced as ``text``/``bash``, not ``python``.
"""

from __future__ import annotations

import contextlib
import io
import re
import textwrap
from pathlib import Path

import pytest
from _doc_blocks import ROOT, run_block

DOCS = ROOT / "docs"
# identify.md: tests/test_identify_docs.py runs every python block and compares what it prints with the page
OWN_TESTS = {"along.md", "compensation.md", "symbolic.md", "optimal.md", "export.md", "identify_motion.md",
             "identify.md"}
PAGES = sorted(p for p in DOCS.glob("*.md") if p.name not in OWN_TESTS)


def _blocks(page: Path) -> list[str]:
    return [textwrap.dedent(b) for b in re.findall(r"^[ \t]*```python\n(.*?)^[ \t]*```", page.read_text(),
                                                    flags=re.S | re.M)]


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_python_blocks_run(page: Path, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    for i, code in enumerate(_blocks(page)):
        before = set(ns)
        run_block(code, f"{page.name} python block {i + 1}", ns)
        with contextlib.redirect_stdout(io.StringIO()):
            for name in sorted(set(ns) - before):
                if name.startswith("test_") and callable(ns[name]):
                    for kwargs in _parameter_sets(ns[name]):
                        ns[name](**kwargs)


def _parameter_sets(fun) -> list[dict]:
    """The keyword sets of a test's ``pytest.mark.parametrize`` marks (one empty set without marks)."""
    sets: list[dict] = [{}]
    for mark in getattr(fun, "pytestmark", []):
        if mark.name != "parametrize":
            continue
        names = [n.strip() for n in mark.args[0].split(",")] if isinstance(mark.args[0], str) else list(mark.args[0])
        rows = [v if len(names) > 1 else (v,) for v in mark.args[1]]
        sets = [{**base, **dict(zip(names, row))} for base in sets for row in rows]
    return sets
