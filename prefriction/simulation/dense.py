"""Dense output of a run: samples at requested times, integrated through the dense plant."""

from __future__ import annotations

from typing import Optional

import numpy as np

from prefriction.simulation.run import N_DENSE, Run

__all__ = ["DENSE_STEP", "dense", "dense_loop"]

DENSE_STEP = 2.0 * np.pi / 64.0
"""Normalised spacing of ``dense=True`` samples (64 per small cycle)."""


def dense(self: Run, times: np.ndarray, t_end: float, n_target: float) -> tuple[list, bool]:
    """Integrate ``self`` (a :class:`~prefriction.simulation.run.Run`) through the sorted
    normalised ``times``; returns the samples and the stop flag."""
    samples = []
    # breaks up to the last requested time only: the caller continues from there
    last = min(t_end, float(times[-1]))
    grid = np.union1d(times, self.breaks[(self.breaks > self.st["t"]) & (self.breaks < last)])
    is_sample = np.isin(grid, times)
    i = 0
    if grid.size and grid[0] <= self.st["t"]:
        samples.append(self.sample())
        i = 1
    while i < grid.size:
        if len(self.rev) >= n_target:
            return samples, True
        pts = list(grid[i:i + N_DENSE])
        m = len(pts)
        nstop = min(n_target, 1e18)
        xf, a = self._call(self.f1, self.L, pts, nstop)
        used = m
        for j in range(m):
            out = self._unpack(self.L, xf[:, j], a, len(self.rev), nstop)
            if out["overflow"]:  # more than K reversals between two outputs: redo that piece
                if self.advance(pts[j], n_target):
                    return samples, True
                used = j + 1
                if is_sample[i + j]:
                    samples.append(self.sample())
                break
            self._accept(out, pts[j])
            if out["frozen"]:
                return samples, True
            if is_sample[i + j]:
                samples.append(self.sample())
        i += used
    return samples, False


def dense_loop(run: Run, times: Optional[np.ndarray], t_end: float, n_target: float) -> list:
    """Samples at the normalised ``times`` (every ``DENSE_STEP`` if None), integrating up to the
    normalised time ``t_end`` or ``n_target`` reversals."""
    if times is not None:
        samples, stopped = dense(run, times, t_end, n_target)
        if not stopped:
            run.advance(t_end, n_target)
        return samples
    samples: list = []
    stopped = False
    t0 = 0.0
    while not stopped and t0 <= t_end:
        block = t0 + DENSE_STEP * np.arange(0, 256)
        block = block[block <= t_end]
        if block.size and block[-1] < t_end < block[-1] + DENSE_STEP:
            block = np.append(block, t_end)  # the last sample is at t_end
        if block.size == 0:
            break
        got, stopped = dense(run, block, t_end, n_target)
        samples.extend(got)
        t0 = block[-1] + DENSE_STEP
    return samples
