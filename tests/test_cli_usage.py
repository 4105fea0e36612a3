"""The dispatcher's usage conventions: help exits 0, a missing command exits 2 (argparse's)."""

from __future__ import annotations

import pytest

from prefriction.cli import COMMANDS, main


@pytest.mark.parametrize("flag", ["-h", "--help"])
def test_help_lists_every_command_and_exits_0(flag, capsys):
    assert main([flag]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: prefriction COMMAND")
    for name in COMMANDS:
        assert f"  {name} " in out


def test_no_command_is_a_usage_error(capsys):
    assert main([]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("usage: prefriction COMMAND")
    assert "error: a command is required" in captured.err
