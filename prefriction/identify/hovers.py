"""The hovers of a record: where a stage rests about its set point, the shooting chain is cut after
the long ones (:func:`hover_nodes`), or the samples of every rest are left out
(:func:`prefriction.identify.pieces.moves_of`)."""

from __future__ import annotations

import numpy as np

__all__ = ["HOVER", "HOVER_RUN", "HOVER_SEGMENTS", "hover_nodes", "long_hovers"]

HOVER = 0.02
"""Fraction of the record's top speed below which the smoothed speed of the data counts as slow."""


HOVER_RUN = 10
"""A segment *hovers* when it holds at least this many consecutive slow samples (:data:`HOVER`):
a stage held about its set point, or settling into or breaking away from a rest. A reversal
inside a move is slow for a few samples only (measured on the 2.5 kg stage at 10,000 samples:
2 to 7)."""


HOVER_SEGMENTS = 3
"""Fewest consecutive hovering segments of a *long* hover, after whose segments the chain is cut
(:func:`hover_nodes`); a short rest stays chained (it converges, and the chain through it
carries information: on the 1,000-sample EMPS-like record of the first example, cutting after
every hovering segment widened the intervals 2.5 times)."""


def hover_nodes(speed: np.ndarray, nodes: np.ndarray, K: int) -> np.ndarray:
    """Nodes after the segments of a long hover (:data:`HOVER_RUN`, :data:`HOVER_SEGMENTS`).

    A stage held about its set point near the friction limit reverses a dozen times per segment
    under the noise its loop feeds back (the bristle of LuGre at ``z ~ 0.95``: the state's rate
    is ``v (1 - z)`` one way and ``v (1 + z)`` the other), so a segment's end state is a
    piecewise-smooth function of its start with kinks on the scale of ``1e-3`` of the node
    scales, and continuity defects or Gauss-Newton steps of that size cannot be resolved. In a
    long hover the node after each of its segments carries no continuity constraint: it starts a new piece of the
    chain with its own free state (a nuisance variable of the statistics). No constraint then
    passes through a hovering segment: its kinks reach only its own residuals, where the
    positions change by a fraction of an encoder step, and each move is chained from its start."""
    hover = long_hovers(speed, nodes, K)
    free = np.zeros(nodes.size, dtype=bool)
    free[1:] = hover[:-1]
    return free


def long_hovers(speed: np.ndarray, nodes: np.ndarray, K: int, least: int = HOVER_SEGMENTS) -> np.ndarray:
    """The segments of long hovers: runs of at least ``least`` (:data:`HOVER_SEGMENTS`) segments
    that each hold at least :data:`HOVER_RUN` consecutive slow samples (:data:`HOVER`); ``least = 1``:
    every hovering segment, the rests between moves too."""
    top = float(np.max(speed, initial=0.0))
    if not top > 0.0:
        return np.zeros(nodes.size, dtype=bool)
    slow = np.r_[0, (speed <= HOVER * top).astype(int), 0]
    edges = np.flatnonzero(np.diff(slow))                       # starts and ends of the slow runs
    starts, ends = edges[::2], edges[1::2]
    hover = np.zeros(nodes.size, dtype=bool)
    for a, b in zip(starts, ends):                              # samples a..b-1 are slow
        first, last = np.searchsorted(nodes, a, side="right") - 1, np.searchsorted(nodes, b - 1, side="right") - 1
        for j in range(max(first, 0), last + 1):
            lo, hi = max(a, nodes[j]), min(b, nodes[j] + K + 1)
            hover[j] |= hi - lo >= HOVER_RUN
    long = np.zeros(nodes.size, dtype=bool)
    run = np.r_[0, hover.astype(int), 0]
    edges = np.flatnonzero(np.diff(run))
    for a, b in zip(edges[::2], edges[1::2]):                  # segments a..b-1 hover
        if b - a >= least:
            long[a:b] = True
    return long
