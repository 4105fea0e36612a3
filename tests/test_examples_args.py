"""The example scripts' shared command line ``[outdir] [--quick]`` (prefriction.plotting.script_args)."""

from __future__ import annotations

import pytest

from prefriction.plotting import script_args


@pytest.mark.parametrize(
    "argv, expected",
    [
        ([], ("out", False)),
        (["--quick"], ("out", True)),
        (["figs"], ("figs", False)),
        (["figs", "--quick"], ("figs", True)),
        (["--quick", "figs"], ("figs", True)),
    ],
)
def test_outdir_and_quick_in_any_order(argv, expected):
    assert script_args(argv, "out", prog="x.py") == expected


@pytest.mark.parametrize("argv", [["--quik"], ["figs", "--fast"], ["-q"]])
def test_unknown_option_exits_2_naming_it(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        script_args(argv, "out", prog="x.py")
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "usage: x.py [outdir] [--quick]" in err
    assert repr([a for a in argv if a.startswith("-")][0]) in err


def test_quick_refused_where_the_script_has_no_quick_mode(capsys):
    with pytest.raises(SystemExit) as exc:
        script_args(["--quick"], "out", allow_quick=False, prog="x.py")
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "'--quick'" in err and "[--quick]" not in err


def test_two_output_directories_refused(capsys):
    with pytest.raises(SystemExit) as exc:
        script_args(["a", "b"], "out", prog="x.py")
    assert exc.value.code == 2
    assert "['a', 'b']" in capsys.readouterr().err


def test_help_prints_usage_and_exits_0(capsys):
    with pytest.raises(SystemExit) as exc:
        script_args(["-h"], "out", prog="x.py")
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == "usage: x.py [outdir] [--quick]"
