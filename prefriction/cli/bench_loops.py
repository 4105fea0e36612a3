"""``prefriction bench --loops``: the positioning-loop benchmark of :mod:`controllers.benchmark`.

:func:`run` returns the table (time per sample of the compiled 1 s, 10 kHz PID loop against
python-control in the same run, its error against a tight scipy reference, a 100-gain tuning
sweep from an empty compile cache, loop lengths 0.1, 1 and 10 s, the targets as PASS/FAIL);
:func:`main` prints it (``docs/controllers.md#benchmark``).
"""

from __future__ import annotations

from typing import Optional


def run(*, t_end: float = 1.0, repeats: int = 3, sweep: int = 100, lengths: tuple = (0.1, 1.0, 10.0)) -> str:
    """The benchmark's table (see :func:`controllers.benchmark.run`)."""
    from prefriction.controllers.benchmark import run as run_loops

    return run_loops(t_end=t_end, repeats=repeats, sweep=sweep, lengths=lengths)


def main(argv: Optional[list[str]] = None) -> int:
    """Command line of ``prefriction bench --loops`` (arguments of ``python -m prefriction.controllers.benchmark``)."""
    from prefriction.controllers.benchmark import main as main_loops

    return main_loops(argv)
