"""The README's code runs and prints what the README says it prints."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

README = (Path(__file__).resolve().parent.parent / "README.md").read_text()
BLOCKS = re.findall(r"```(\w*)\n(.*?)```", README, flags=re.S)


def _run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), {})
    return out.getvalue()


def test_top_has_exactly_two_commands_and_ci_runs_the_test_command():
    lang, first = BLOCKS[0]
    commands = [line for line in first.splitlines() if line.strip()]
    assert lang == "bash" and len(commands) == 2
    ci = (Path(__file__).resolve().parent.parent / ".ci" / "run").read_text()
    assert commands[1] in ci


def test_quick_start_prints_what_the_readme_shows():
    code = next(body for lang, body in BLOCKS if lang == "python")
    shown = BLOCKS[BLOCKS.index(("python", code)) + 1][1].splitlines()
    printed = _run(code).splitlines()
    assert printed[0] == shown[0]  # |F_50| of simulate and of the exact reference, 9 digits
    assert printed[2] == shown[2]  # the exact map at a = 1
    error = float(printed[1].rsplit(" ", 1)[1])
    assert error < 1e-8  # rtol = 1e-8 run: error within the tolerance


def test_controllers_example_runs_and_respects_the_pd_bound():
    code = next(body for lang, body in BLOCKS if lang == "python" and "controllers" in body)
    out = _run(code)
    ratio = float(re.search(r"\|e\| / bound = ([0-9.]+)", out).group(1))
    assert 0.0 < ratio <= 1.0


def test_sweep_example_matches_the_exact_reference():
    code = next(body for lang, body in BLOCKS if lang == "python" and "pf.sweep" in body)
    out = _run(code)
    assert out.startswith("SweepResult(5 runs, 0 failed")
    import prefriction as pf

    exact = abs(pf.exact_reversals(pf.Oscillator(pf.Dahl(1e4, 1.0, 3.0)), 1.0, 50).F[-1])
    assert float(re.search(r"gamma = 3: ([0-9.]+) N", out).group(1)) == round(exact, 6)
