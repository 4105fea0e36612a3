"""Shared by the docs tests: the fenced blocks of a page, and running one block with its printout captured."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def page_blocks(page: str) -> list[tuple[str, str]]:
    """``(language, body)`` of every fenced block of the file ``page`` (relative to the repository)."""
    return re.findall(r"```(\w*)\n(.*?)```", (ROOT / page).read_text(), flags=re.S)


def run_block(code: str, where: str, namespace: dict | None = None) -> str:
    """Execute ``code`` (named ``where`` in tracebacks) in ``namespace`` (a fresh one if ``None``); what it printed."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, where, "exec"), {} if namespace is None else namespace)
    return out.getvalue()
