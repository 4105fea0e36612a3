"""docs/sweeps.md: every python block runs and prints what the page says it prints."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

import prefriction as pf

PAGE = (Path(__file__).resolve().parent.parent / "docs" / "sweeps.md").read_text()
# each python block and the ``prints `...` `` sentence after it
BLOCKS = re.findall(r"```python\n(.*?)```\s*\n\s*prints `([^`]*)`", PAGE, flags=re.S)


def _run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "docs/sweeps.md", "exec"), {})
    return out.getvalue().strip()


def test_every_python_block_has_its_printed_line() -> None:
    assert len(BLOCKS) == PAGE.count("```python") == 3


def test_thread_pool_chunks_are_the_serial_results() -> None:
    assert _run(BLOCKS[0][0]) == BLOCKS[0][1]


def test_chunk_sizes_block_covers_the_systems() -> None:
    printed = _run(BLOCKS[1][0])
    assert printed == BLOCKS[1][1]
    from prefriction.simulation.chunks import chunk_sizes

    sizes = chunk_sizes(9_999, 2)
    assert sum(sizes) == 9_999 and sizes[0] == 500 and sizes[-1] == 9_999 - sum(sizes[:-1])


def test_dask_block_prints_the_exact_reversal_force() -> None:
    pytest.importorskip("dask.distributed")
    printed = _run(BLOCKS[2][0])
    assert printed == BLOCKS[2][1]
    exact = pf.exact_reversals(pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=2.1)), 1.0, 50).F[-1]
    assert float(re.search(r"([0-9.]+) N", printed).group(1)) == round(abs(exact), 6)
