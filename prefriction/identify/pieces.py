"""The first window of a long Motion fit cut from pieces of the record around its reversals.

A long record first fits a window of :data:`prefriction.identify.continuation.WINDOW` samples
(continuation, :func:`prefriction.identify.continuation.fit_motion`). A slow record turns seldom: the
open-loop record of a 2.5 kg stage driven by three periods of a two-tone force over 25,000 samples
(5 s at 5 kHz) reverses five times, and its busiest 2,000-sample window holds one reversal. In one
direction of sliding the friction is ``Fc + F_off``, in the other ``-Fc + F_off``, and the mass and
the viscous coefficient act through the same slow accelerations, so a window with one reversal
pins these only in combination (measured: that window's fit from a factor-2 start stopped at
``Fc = 0.65 N``, offset -2.1 N against 3 N and 0.2 N).

When the busiest contiguous window holds fewer than :data:`FEWEST` reversals in each direction, the
record holds more, and at least two of its turns are short (the stage slides again within half a
window: an open-loop record that turns while sliding, not a closed loop resting at its set points
between moves), the first window is cut from up to :data:`MOST_PIECES` pieces of the record, each
centred on a velocity reversal, about half in each direction (:func:`piece_window`), and fitted
before the contiguous one (:func:`prefriction.identify.continuation.fit_motion`): each piece slides
one way, turns through its pre-sliding transient and slides the other way. Measured at 25,000
samples from factor-2 starts: on the slow open-loop records of the success harness the
contiguous window either stops (the 10 kg LuGre stage: 850 s of CPU before the pieces ran) or
converges without pinning the stiffness (the 0.3 kg Dahl stage, no reversal each way), where the
pieces converge in 20 to 30 s; on the closed-loop records (EMPS-like LuGre, the user stage's
LuGre and Dahl), whose turns are rests of 840 to 1,460 samples, the contiguous window converges
in 6 to 18 s and pieces cut around their rests did not converge in 75 to 85 s, so they keep the
contiguous window. The pieces are concatenated as a :class:`Pieces` record; each piece starts its
own piece of the multiple-shooting chain (a node with its own free position, velocity and state,
no continuity constraint into it), the step across the junction is not simulated (its time step
is zero) and the smoothed node start values are computed within each piece
(:func:`prefriction.identify.motion_start.derivatives_of`); it is solved to :data:`PIECE_TOL`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction.identify.data import Motion
from prefriction.identify.motion_start import derivatives, piece_edges

__all__ = ["FEWEST", "MOST_PIECES", "PIECE_TOL", "Pieces", "breaks_of", "concatenate", "describe",
           "describe_moves", "direction_counts", "moves_of", "moving_flips", "piece_window", "reversal_samples"]

FEWEST = 2
"""Fewest reversals in each direction in the busiest contiguous window below which the first window
is built from pieces (:func:`piece_window`)."""
MOST_PIECES = 5
"""Most pieces of a piece window (each at least :data:`LEAST_SEGMENTS` shooting segments long)."""
LEAST_SEGMENTS = 4
"""Fewest shooting segments per piece: a piece must span the sliding on both sides of its reversal."""
PIECE_TOL = 1e-8
"""Least ``tol`` (``xtol`` and ``ftol`` of the last inner solve,
:func:`prefriction.identify.constrained_lsq.solve`) of a piece window: a continuation stage, whose
estimates only start the fit of the whole record (solved to the user's ``tol``). Measured on the
five-reversal open-loop record of the module notes: at ``tol = 1e-10`` the dense solve of the
2,000-sample piece window stops at its 200 evaluations with every estimate within 1e-4 of the
truth, from a factor-2 start (continuity defects of 5e-6) and from the truth alike; at ``1e-8`` it converges from both
(52 and 50 s of CPU, the chain cut at the long hovers of the slow turns)."""
MOVING = 0.05
"""Fraction of the top smoothed speed above which a sample counts as moving for the reversal count
(:func:`moving_flips`, also for :func:`prefriction.identify.continuation._busiest_window`)."""


@dataclass(frozen=True, eq=False)
class Pieces(Motion):
    """Pieces of a :class:`Motion` record concatenated into one record.

    The times of each piece are shifted so that the concatenation is strictly increasing with one
    ordinary sample interval at each junction; the shooting layout does not simulate that interval
    (its time step is set to zero) and starts a new piece of the chain at each junction.

    Attributes
    ----------
    breaks : tuple of int
        Sample index (in the concatenation) of the first sample of every piece after the first.
    source : tuple of int
        Sample index in the original record of the first sample of every piece.
    shift : tuple of float
        Time [s] subtracted from each piece's original times.
    """

    breaks: tuple[int, ...] = ()
    source: tuple[int, ...] = ()
    shift: tuple[float, ...] = ()

    def to_piece_times(self, times: Any) -> list[float]:
        """The given times [s] of the original record that fall inside a piece, in the concatenation's time."""
        edges = (0, *self.breaks, len(self))
        out = []
        for a, b, dt in zip(edges[:-1], edges[1:], self.shift):
            out += [float(r) - dt for r in times if self.t[a] + dt < float(r) < self.t[b - 1] + dt]
        return out


def breaks_of(data: Motion) -> np.ndarray:
    """Sample indices at which a new piece of ``data`` starts (empty for an ordinary record): the
    inner edges of :func:`prefriction.identify.motion_start.piece_edges`."""
    return piece_edges(data)[1:-1]


def moving_flips(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Changes of direction of a smoothed velocity ``v`` [m/s] counting only samples that move
    (``|v|`` above :data:`MOVING` of its top): the last moving sample before each change, the
    first moving sample after it, and the moving directions (+1, -1, 0 where not moving)."""
    moving = np.abs(v) > MOVING * float(np.max(np.abs(v)))
    sv = np.where(moving, np.sign(v), 0.0)
    nz = np.flatnonzero(sv)
    change = sv[nz[1:]] != sv[nz[:-1]]
    return nz[:-1][change], nz[1:][change], sv


def reversal_samples(data: Motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity reversals of a record: the sample of each zero crossing of the smoothed velocity
    (the last one before the speed exceeds :data:`MOVING` of its top in the new direction), the
    new direction (+1 or -1) and the turn's length in samples (from the last moving sample before
    it to the first after it: long where the stage rests between moves).

    Returns
    -------
    tuple of numpy.ndarray
        ``(samples, directions, turns)``, each of one entry per reversal.
    """
    _x, v, _a = derivatives(data.t, data.x)
    prev, flips, sv = moving_flips(v)
    samples = []
    for a, b in zip(prev, flips):  # the last sign change of v between leaving one direction and entering the other
        s = np.sign(v[a:b + 1])
        change = np.flatnonzero(s[1:] * s[:-1] <= 0.0)
        samples.append(a + 1 + int(change[-1]) if change.size else (a + b) // 2)
    return np.asarray(samples, dtype=int), sv[flips], flips - prev


def direction_counts(directions: np.ndarray) -> tuple[int, int]:
    """Reversals into the positive and into the negative direction."""
    return int(np.count_nonzero(directions > 0)), int(np.count_nonzero(directions < 0))


def piece_window(data: Motion, first: int, width: int, K: int) -> Pieces | None:
    """The first window of a long fit from pieces of ``data`` around its reversals, or ``None``
    when the contiguous window ``data[first:first + width]`` (the busiest) holds at least
    :data:`FEWEST` reversals in each direction, the record holds no more than it in the rarer
    direction, fewer than two of the record's turns (from the last moving sample before a reversal
    to the first after it) are shorter than half of ``width`` less two segments (a stage resting
    between moves, module notes), or fewer than two pieces of :data:`LEAST_SEGMENTS` segments fit
    in ``width``.

    Parameters
    ----------
    data : Motion
        The record.
    first, width : int
        First sample and samples of the busiest contiguous window.
    K : int
        Samples per shooting segment: each piece is a multiple of ``K`` samples long, so that
        every junction falls on a node.

    Returns
    -------
    Pieces or None
        About ``width`` samples: up to :data:`MOST_PIECES` pieces of equal length, each centred on a
        reversal (moved inwards at the ends of the record), chosen evenly over the record and
        about half in each direction; pieces that would overlap are joined end to start.
    """
    at, to, turns = reversal_samples(data)
    inside = (at >= first) & (at < first + width)
    if min(direction_counts(to[inside])) >= FEWEST or min(direction_counts(to)) <= min(direction_counts(to[inside])):
        return None
    n_pieces = min(MOST_PIECES, at.size, width // (LEAST_SEGMENTS * K))
    if n_pieces < 2 or np.count_nonzero(turns + 2 * K <= K * (width // (2 * K))) < 2:
        return None   # fewer than two turns within half a window of sliding both ways: a stage resting between moves
    length = K * (width // (n_pieces * K))
    chosen: list[int] = []
    ups, downs = np.flatnonzero(to > 0), np.flatnonzero(to < 0)
    n_up = min(ups.size, max(n_pieces - downs.size, (n_pieces + int(ups.size >= downs.size)) // 2))
    for group, count in ((ups, n_up), (downs, n_pieces - n_up)):
        if count:
            chosen += [int(group[k]) for k in np.unique(np.round(np.linspace(0, group.size - 1, count)).astype(int))]
    n = len(data)
    starts = sorted(int(min(max(at[k] - length // 2, 0), n - length)) for k in chosen)
    pieces: list[tuple[int, int]] = []
    for a in starts:
        a = max(a, pieces[-1][1]) if pieces else a
        b = a + K * ((min(a + length, n) - a) // K)   # whole segments: every junction on a node
        if b - a >= LEAST_SEGMENTS * K:
            pieces.append((a, b))
    if len(pieces) < 2:
        return None
    return concatenate(data, pieces)


def concatenate(data: Motion, spans: list[tuple[int, int]]) -> Pieces:
    """The samples ``a`` to ``b - 1`` of ``data`` for every ``(a, b)`` of ``spans`` (increasing,
    not overlapping) as one :class:`Pieces` record."""
    idx = np.concatenate([np.arange(a, b) for a, b in spans])
    t = data.t[idx].copy()
    breaks, shift, pos = [], [], 0
    for a, b in spans:   # each piece's first interval after the last one's end: its own last interval
        d = float(data.t[a - 1] - t[pos - 1]) if pos else 0.0
        if pos:
            breaks.append(pos)
        shift.append(d)
        t[pos:pos + b - a] = data.t[a:b] - d
        pos += b - a
    return Pieces(t, data.x[idx], data.u[idx], data.mass, data.hold, data.x_noise, data.quantum,
                  breaks=tuple(breaks), source=tuple(a for a, _ in spans), shift=tuple(shift))


def moves_of(data: Motion, left_out: np.ndarray, K: int) -> Pieces | None:
    """``data`` without the shooting segments of ``K`` samples flagged in ``left_out`` (the rests of
    :func:`prefriction.identify.hovers.long_hovers` with ``least=1``): the moves between them, one
    piece each; ``None`` when no segment is left out or every one is."""
    keep = ~np.asarray(left_out, dtype=bool)
    if keep.all() or not keep.any():
        return None
    edges = np.flatnonzero(np.diff(np.r_[0, keep.astype(int), 0]))   # runs of kept segments j..k-1
    # a piece ends where the next segment starts; the last segment runs to the record's end
    return concatenate(data, [(int(j) * K, len(data) if k == keep.size else int(k) * K)
                              for j, k in zip(edges[::2], edges[1::2])])


def describe(window: Pieces) -> str:
    """One line for the fit's steps: the pieces' samples in the original record."""
    return f"{len(window.source)} pieces of the record around reversals (samples {_spans(window)})"


def describe_moves(moves: Pieces) -> str:
    """One line for the fit's steps: the moves' samples in the original record (:func:`moves_of`)."""
    return f"{len(moves.source)} moves (samples {_spans(moves)})"


def _spans(pieces: Pieces) -> str:
    edges = (0, *pieces.breaks, len(pieces))
    return ", ".join(f"{s} to {s + b - a - 1}" for s, a, b in zip(pieces.source, edges[:-1], edges[1:]))


