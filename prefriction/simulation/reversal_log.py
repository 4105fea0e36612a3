"""The reversals a run has found, in columns of doubles: 32 bytes per reversal.

A list of ``(t~, x~, F~, W~)`` tuples held 180 bytes per reversal (a tuple and four float
objects); with the arrays the reversal table was built from, a run of 1e6 reversals peaked at
790 bytes per reversal, 20x the table it returned. :class:`ReversalLog` keeps the four columns
in :class:`array.array` (8 bytes per number) and hands them to numpy without a copy.
"""

from __future__ import annotations

from array import array
from typing import Iterable, Optional, Union

import numpy as np

__all__ = ["ReversalLog"]


class ReversalLog:
    """Reversals ``(t~, x~, F~, W~)`` (normalised units) in four columns, appended one at a time.

    Behaves as the list of 4-tuples it replaces for what the loops do with it: ``append``,
    ``extend``, ``len``, truth, and ``log[i]`` (a tuple); ``log.t`` is the column of times;
    :meth:`columns` gives the first ``n`` rows as numpy arrays (views, no copy).
    """

    __slots__ = ("t", "x", "F", "W")

    def __init__(self) -> None:
        self.t, self.x, self.F, self.W = array("d"), array("d"), array("d"), array("d")

    def append(self, row: tuple) -> None:
        """Add one reversal ``(t~, x~, F~, W~)``."""
        t, x, F, W = row
        self.t.append(t)
        self.x.append(x)
        self.F.append(F)
        self.W.append(W)

    def extend(self, rows: Iterable[tuple]) -> None:
        """Add reversals ``(t~, x~, F~, W~)`` in order."""
        for row in rows:
            self.append(row)

    def extend_columns(self, t: np.ndarray, x: np.ndarray, F: np.ndarray, W: Optional[np.ndarray] = None) -> None:
        """Add reversals from columns of times, positions, forces and input works (None: ``W~ = 0``,
        unforced runs)."""
        for col, values in ((self.t, t), (self.x, x), (self.F, F), (self.W, np.zeros(len(t)) if W is None else W)):
            col.frombytes(memoryview(np.ascontiguousarray(values, dtype=float)).cast("B"))  # no bytes copy

    def __len__(self) -> int:
        return len(self.t)

    def __getitem__(self, i: int) -> tuple:
        return (self.t[i], self.x[i], self.F[i], self.W[i])

    def columns(self, n: Union[int, None] = None, writable: bool = False) -> tuple[np.ndarray, ...]:
        """The first ``n`` reversals (all if None) as four float arrays, views of the log (no
        copy): read-only, or ``writable`` for a caller that converts them in place (the log is
        then consumed)."""
        out = []
        for col in (self.t, self.x, self.F, self.W):
            arr = np.frombuffer(col, dtype=float) if len(col) else np.zeros(0)
            arr = arr[:n]
            arr.flags.writeable = writable
            out.append(arr)
        return tuple(out)
