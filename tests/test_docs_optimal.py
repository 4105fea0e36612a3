"""Every python block of docs/symbolic.md and docs/optimal.md runs and prints what the page shows;
the docstring examples of prefriction.symbolic, prefriction.optimal and ZeroOrderHold pass."""

from __future__ import annotations

import doctest
import re

import pytest
from _doc_blocks import page_blocks, run_block

import prefriction.optimal.problem
import prefriction.optimal.references
import prefriction.signals.hold
import prefriction.symbolic.branch
import prefriction.symbolic.model
import prefriction.symbolic.plant

def _blocks(page: str) -> list[tuple[str, str]]:
    """(code, shown output) of each python block followed by an output block."""
    blocks = page_blocks(f"docs/{page}")
    return [(body, blocks[i + 1][1]) for i, (lang, body) in enumerate(blocks)
            if lang == "python" and i + 1 < len(blocks) and blocks[i + 1][0] == ""]


def _stable(text: str) -> list[str]:
    """The lines, without IPOPT's wall time (it varies from run to run)."""
    return [re.sub(r"(IPOPT \d+ iterations).*", r"\1", line) for line in text.strip().splitlines()]


CASES = [(page, k, code, shown) for page in ("symbolic.md", "optimal.md")
         for k, (code, shown) in enumerate(_blocks(page))]


@pytest.mark.parametrize(("page", "k", "code", "shown"), CASES, ids=[f"{p}-{k}" for p, k, _, _ in CASES])
def test_doc_block_prints_what_the_page_shows(page, k, code, shown):
    assert _stable(run_block(code, f"docs/{page}")) == _stable(shown)


def test_every_page_has_its_blocks():
    assert len(_blocks("symbolic.md")) == 4 and len(_blocks("optimal.md")) == 3


@pytest.mark.parametrize("module", [prefriction.symbolic.branch, prefriction.symbolic.model, prefriction.symbolic.plant, prefriction.signals.hold,
                                    prefriction.optimal.problem, prefriction.optimal.references])
def test_docstring_examples(module):
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
