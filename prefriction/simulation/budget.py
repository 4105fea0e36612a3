"""The size budget of a run that can grow: refuse up front what would exceed it.

Every run holds its reversal table in memory, at most ``MAX_REVERSALS`` rows (``simulate``
stops a ``t_end`` run that reaches them and says so). A periodic input force of frequency
``f`` can reverse the motion twice per period, so a run to ``t_end`` may need ``2 f t_end``
reversals: :func:`check_input_budget` refuses that before any work when it exceeds the budget
(a 1 GHz sine over 1 s would need 2e9 rows and days of CPU time).
"""

from __future__ import annotations

import math
from typing import Any

from prefriction.signals.algebra import Sum
from prefriction.signals.periodic import Chirp, Sine

__all__ = ["check_input_budget", "max_frequency"]


def max_frequency(u: Any) -> float:
    """Highest frequency [Hz] of the periodic parts of the input signal ``u`` (0 if none is known)."""
    if isinstance(u, Sine):
        return float(u.frequency)
    if isinstance(u, Chirp):
        return float(max(u.f0, u.f1))
    if isinstance(u, Sum):
        return max((max_frequency(term) for term in u.terms), default=0.0)
    return 0.0


def check_input_budget(u: Any, t_end: float, max_reversals: int) -> None:
    """``ValueError`` if the input ``u`` can reverse the motion more than ``max_reversals`` times by ``t_end`` [s]."""
    f = max_frequency(u)
    if f <= 0.0 or not math.isfinite(t_end):
        return
    need = 2.0 * f * t_end
    if need > max_reversals:
        raise ValueError(
            f"t_end = {t_end:.6g} s with an input of frequency {f:.6g} Hz allows about {need:.3g} reversals (two per "
            f"period), more than the {max_reversals:_} a run may hold in memory; allowed: "
            f"t_end <= {max_reversals / (2.0 * f):.3g} s at this frequency (or a lower frequency)")
