"""Timing helpers shared by the sections of ``prefriction bench``.

Every run time the benchmark reports is the minimum over repeated warm calls
(``docs/bench.md#timing``); :func:`min_time` is that loop, with the stopping rules of the
different sections as its keyword arguments. :func:`progress` prints the one-line progress
messages on stderr, so that the tables on stdout stay clean.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Callable, Optional, TypeVar

T = TypeVar("T")


def min_time(fn: Callable[[], T], *, calls: int = 1, most: float = 0, fill: float = 0.0,
             stop_best: float = math.inf, stop_spent: float = math.inf,
             seconds: Optional[Callable[[T], float]] = None) -> tuple[T, float]:
    """Call ``fn`` repeatedly; return its last result and the least time of one call [s].

    The calls go on until at least ``calls`` calls are done *and* either ``fill`` seconds were
    spent or ``most`` calls were made; they stop early once the least time exceeds
    ``stop_best`` or the time spent exceeds ``stop_spent``. ``fn`` is called at least once.

    Parameters
    ----------
    fn : callable
        The timed call, without arguments.
    calls : int, optional
        Least number of calls (default 1).
    most : float, optional
        Most calls while filling ``fill`` seconds (default 0: ``calls`` calls only; ``math.inf``:
        no limit).
    fill : float, optional
        Seconds of calls to fill once ``calls`` calls are done [s] (default 0).
    stop_best : float, optional
        Stop as soon as the least time of one call is at least this [s] (a slow call needs no
        repeats).
    stop_spent : float, optional
        Stop as soon as the calls took more than this in total [s].
    seconds : callable, optional
        Time of one call taken from its result (e.g. ``stats.wall_time`` of a simulation, the
        integration alone); default the wall-clock time of the call.

    Returns
    -------
    (result, float)
        The result of the last call and the least time of one call [s].
    """
    best, spent, k = math.inf, 0.0, 0
    while True:
        start = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - start if seconds is None else seconds(out)
        best, spent, k = min(best, dt), spent + dt, k + 1
        if best >= stop_best or spent > stop_spent:
            return out, best
        if k >= calls and (spent >= fill or k >= most):
            return out, best


def progress(message: str) -> None:
    """One progress line ``  ... message`` on stderr (the tables go to stdout)."""
    print(f"  ... {message}", file=sys.stderr, flush=True)
