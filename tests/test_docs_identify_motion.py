"""docs/identify_motion.md: every python block runs (in order, one namespace) and prints what the page says."""

from __future__ import annotations

import re
import warnings

import pytest
from _doc_blocks import ROOT, run_block

PAGE = (ROOT / "docs" / "identify_motion.md").read_text()


def _shown(after: str) -> list[str]:
    """What the page says the block prints: the next code block after "prints", or the inline `...`."""
    m = re.match(r"\s*prints\s*\n\s*```\w*\n(.*?)```", after, flags=re.S)
    if m:
        return m.group(1).strip().splitlines()
    m = re.match(r"\s*prints[^`]*`([^`]*)`", after, flags=re.S)
    return [m.group(1)] if m else []


@pytest.mark.slow  # the page's first block is the 1,000-sample closed-loop fit that the fast suite runs in
# tests/test_identify_closed_loop.py (the same record, start and options): about 10 s of CPU again
def test_every_python_block_runs_and_prints_what_the_page_shows():
    namespace: dict = {}
    blocks = list(re.finditer(r"```python\n(.*?)```", PAGE, flags=re.S))
    assert len(blocks) == 6
    for b in blocks:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            printed = run_block(b.group(1), "identify_motion.md", namespace).strip().splitlines()
        shown = _shown(PAGE[b.end():])
        assert shown, "every block says what it prints"
        if len(shown) == 1 and len(printed) == 1:
            assert printed[0].strip() == shown[0].strip()
        else:
            assert printed == shown
