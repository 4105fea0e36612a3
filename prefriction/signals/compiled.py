"""The form in which the simulator compiles a signal (:func:`compiled_form`)."""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, Optional, Union

import numpy as np

from prefriction.signals.base import LinearPieces, Signal

__all__ = ["compiled_form"]


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
