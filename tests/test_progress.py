"""Progress lines: rewritten in place on a terminal, one whole line per event in a log."""

from __future__ import annotations

import io
import sys

import pytest

from prefriction._progress import ProgressLine


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("stream, expected", [
    (io.StringIO(), "step 1/2\nstep 2/2\n"),
    (_Terminal(), "\rstep 1/2\rstep 2/2\n"),
])
def test_progress_line(monkeypatch, stream, expected) -> None:
    monkeypatch.setattr(sys, "stderr", stream)
    line = ProgressLine()
    line.show("step 1/2")
    line.show("step 2/2")
    line.close()
    assert stream.getvalue() == expected
