"""Measures of one loop run: errors, reversal spikes, settling, control effort."""

from __future__ import annotations

import math

import numpy as np

from .._loop_result import LoopResult
from .cases import BAND, WINDOW, Task


def measures(res: LoopResult, task: Task) -> dict[str, float]:
    """RMS and largest tracking error [m], the largest spike after the reference reversals [m]
    (max ``|e|`` within ``WINDOW`` after each), the settling time [s] after the ends of the moves
    into ``+-BAND`` (largest over the moves; nan without moves, inf if never), the RMS of the
    applied force [N] and of its sample-to-sample change [N]."""
    t, e, u = res.t, res.error, res.u
    spikes = [np.max(np.abs(e[(t >= tr) & (t <= tr + WINDOW)])) for tr in task.reversals]
    settle = []
    for i, te in enumerate(task.move_ends):
        stop = task.reversals[i] if i < len(task.reversals) and task.reversals[i] > te else t[-1]
        inside = (t >= te) & (t <= stop)
        out = np.flatnonzero(np.abs(e[inside]) > BAND)
        if out.size == 0:
            settle.append(0.0)
        elif out[-1] == np.count_nonzero(inside) - 1:
            settle.append(math.inf)
        else:
            settle.append(float(t[inside][out[-1] + 1] - te))
    return {
        "rms": float(np.sqrt(np.mean(e * e))), "max": float(np.max(np.abs(e))), "spike": float(max(spikes)),
        "settle": max(settle) if settle else math.nan, "effort": float(np.sqrt(np.mean(u * u))),
        "du": float(np.sqrt(np.mean(np.diff(u) ** 2))),
    }
