"""The form in which the simulator compiles a signal (:func:`compiled_form`), and the numbers of
its piecewise-linear form on many intervals at once (:func:`linear_pieces`)."""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, Optional, Union

import numpy as np

from prefriction.signals.base import LinearPieces, Signal

__all__ = ["compiled_form", "linear_pieces"]


class _PiecewiseLinear(LinearPieces):
    """A piecewise-linear signal as the simulator compiles it: one structure for every
    piecewise-linear kind, the value and slope of each interval as per-interval numbers."""

    __slots__ = ("base",)

    def __init__(self, base: Signal) -> None:
        self._set(base=base)

    @property
    def key(self) -> Hashable:
        return ("PiecewiseLinear",)

    def piece(self, ta: float, tb: float) -> np.ndarray:
        a, b = self.base.linear_piece(ta, tb)
        return np.array([ta, a, b])

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        return self.base(t)

    def breaks(self) -> np.ndarray:
        return self.base.breaks()

    def bound(self, t_end: float) -> float:
        return self.base.bound(t_end)

    def __repr__(self) -> str:
        return f"PiecewiseLinear({self.base!r})"


def compiled_form(sig: Optional[Signal]) -> Optional[Signal]:
    """The form in which the simulator compiles ``sig``: piecewise-linear signals (constants,
    steps, ramps, samples and their sums) all share the structure ``("PiecewiseLinear",)``,
    their numbers given per integration interval; other signals are compiled as they are.

    Parameters
    ----------
    sig : Signal or None
        The signal.

    Returns
    -------
    Signal or None
    """
    if sig is None or isinstance(sig, _PiecewiseLinear):
        return sig
    return _PiecewiseLinear(sig) if sig.linear_piece(0.0, 0.0) is not None else sig


def linear_pieces(sig: Any, ta: np.ndarray, tb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value at ``ta`` and slope of a piecewise-linear signal (the simulator's compiled form,
    ``key == ("PiecewiseLinear",)``) on each interval ``[ta, tb]`` [s] (no break inside), in one
    vectorised pass: the line through the quarter points (exact for a linear piece)."""
    q1, q3 = ta + 0.25 * (tb - ta), ta + 0.75 * (tb - ta)
    u1, u3 = np.asarray(sig.base(q1), dtype=float), np.asarray(sig.base(q3), dtype=float)
    slope = (u3 - u1) / (q3 - q1)
    return u1 - slope * (q1 - ta), slope
