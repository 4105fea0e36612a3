"""Dense output of a run on CasADi's integrator: samples at requested times, through the dense plant.

Outputs of one integrator call (:data:`~prefriction.simulation.samples.N_DENSE` of them) are
converted together into the run's :class:`~prefriction.simulation.samples.SampleBuffer`; only
the columns with a reversal and the last one go through the run's per-column bookkeeping.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional

import numpy as np

from prefriction.simulation.samples import DENSE_STEP, N_DENSE, SampleBuffer

if TYPE_CHECKING:
    from prefriction.simulation.run import Run

__all__ = ["dense", "dense_loop"]

_BLOCK = 4096  # requested times integrated per pass (bounds the temporaries of the time grid)


def dense(run: "Run", times: np.ndarray, t_end: float, n_target: float, buf: SampleBuffer) -> bool:
    """Integrate ``run`` through the sorted normalised ``times``, adding a sample at each to
    ``buf``; True if the run stopped (``n_target`` reversals or a frozen state)."""
    # breaks up to the last requested time only: the caller continues from there
    last = min(t_end, float(times[-1]))
    b = run.breaks
    grid = np.union1d(times, b[(b > run.st["t"]) & (b < last)]) if b.size else np.asarray(times, dtype=float)
    is_sample = np.isin(grid, times) if b.size else np.ones(grid.size, dtype=bool)
    is_break = np.isin(grid, b) if b.size else np.zeros(grid.size, dtype=bool)
    i = 0
    if grid.size and grid[0] <= run.st["t"]:
        buf.append(run.sample())
        i = 1
    n_key, tm = run.L.state["n"], run.L.state.get("tmiss")
    nstop = min(n_target, 1e18)
    while i < grid.size:
        if len(run.rev) >= n_target:
            return True
        pts = grid[i:i + N_DENSE]
        m = len(pts)
        n0 = len(run.rev)
        xf, a = run._call(run.f1, run.L, pts.tolist(), nstop)
        m = _rest_ends_at_break(run, xf, pts, is_break[i:i + m], a, nstop)
        pts = pts[:m]
        cols = xf[:, :m]
        n_col = np.floor(cols[n_key] + 0.5)
        total = n_col[-1] - n0
        new = np.diff(n_col, prepend=n0) if total > 0 else None  # reversals per column
        missed = tm is not None and cols[tm, -1] > 0.5  # a reversal pair skipped inside one step
        if n_col[-1] >= nstop or missed or (total > run.spec.K and new.max() > run.spec.K):  # stop or register
            # overflow: column by column
            used, stopped = _columns_one_by_one(run, cols, pts, is_sample[i:i + m], a, n_target, nstop, buf)
            if stopped:
                return True
        else:
            _columns_together(run, cols, pts, is_sample[i:i + m], a, new, nstop, buf)
            used = m
        i += used
    return False


def _rest_ends_at_break(run: "Run", xf: np.ndarray, pts: np.ndarray, is_break: np.ndarray, a: dict,
                        nstop: float) -> int:
    """Number of the call's outputs to keep: all of them, or those up to the first sample time of
    the input or reference (``is_break``) at which a resting mass feels a net force above the
    rest threshold. The input's jump there falls between two output intervals, where the plant
    sees no sign change of its rest-exit indicator; the next call starts at that time and
    leaves the rest (``Run._leave_rest``)."""
    if "rest" not in run.L.state:
        return len(pts)
    rest = xf[run.L.state["rest"], :len(pts) - 1]
    for j in np.flatnonzero(is_break[:-1] & (rest > 0.5)):
        out = run._unpack(run.L, xf[:, j], a, len(run.rev), nstop)
        if not out["frozen"] and run._leaves_rest_at(out, float(pts[j]), a["Av"]):
            return int(j) + 1
    return len(pts)


def _columns_together(run: "Run", cols: np.ndarray, pts: np.ndarray, is_sample: np.ndarray, a: dict,
                      new: Optional[np.ndarray], nstop: float, buf: SampleBuffer) -> None:
    """Take the outputs ``cols`` of one call (no stop, no register overflow): reversals of the
    columns that have some, the run's state from the last column, samples in one block."""
    L = run.L
    if new is not None:
        for j in np.flatnonzero(new[:-1]):
            run._record(run._unpack(L, cols[:, j], a, len(run.rev), nstop))
    run._accept(run._unpack(L, cols[:, -1], a, len(run.rev), nstop), float(pts[-1]))
    if is_sample.all():
        sel: "slice | np.ndarray" = slice(None)
    else:
        sel = np.flatnonzero(is_sample)
        if sel.size == 0:
            return
    c = cols[:, sel]
    ix = L.state
    x = a["xref"] + a["Ax"] * c[0]
    v = a["Av"] * c[1]
    z = (a["AF"] * c[2:2 + L.nz]).T.tolist()
    mm = c[[ix[f"m{k}"] for k in range(L.nm)]].T.tolist()
    s = c[ix["s"]].tolist()
    force, q = run.model.force, run.q
    F = [float(force(zj, mj, vj, sj, q)) for zj, mj, vj, sj in zip(z, mm, v.tolist(), s)]
    Ef = a["Efref"] + a["AE"] * c[ix["Eh"]] if "Eh" in ix else 0.0
    if not buf.width:
        xc = None
    elif run.spec.fb == "continuous":
        xc = (c[L.xc] * run.S[:, None]).T
    else:
        xc = np.asarray(run.st["xc"], dtype=float)  # held: the same for every sample
    buf.extend(pts[sel], x, v, F, Ef, xc)


def _columns_one_by_one(run: "Run", cols: np.ndarray, pts: np.ndarray, is_sample: np.ndarray, a: dict,
                        n_target: float, nstop: float, buf: SampleBuffer) -> tuple[int, bool]:
    """Take the outputs of one call column by column (the run stops in it, or more than ``K``
    reversals fell between two outputs, or a reversal pair inside one step stopped the call:
    that piece is integrated again by ``advance``). Returns the number of outputs used and
    whether the run stopped."""
    L = run.L
    for j in range(cols.shape[1]):
        out = run._unpack(L, cols[:, j], a, len(run.rev), nstop)
        t = float(pts[j])
        if out["overflow"] or out["tmiss"] is not None:
            if run.advance(t, n_target):
                return j + 1, True
            if is_sample[j]:
                buf.append(run.sample())
            return j + 1, False
        run._accept(out, t)
        if out["frozen"]:
            return j + 1, True
        if is_sample[j]:
            buf.append(run.sample())
    return cols.shape[1], False


def _estimate(run: "Run", buf: SampleBuffer, t_end: float, n_target: float) -> float:
    """Estimated final number of samples: by the time left to ``t_end`` and by the mean duration
    of the last (up to 64) half-cycles times the reversals still to come."""
    t_now = run.st["t"]
    est = len(buf) + max(t_end - t_now, 0.0) / DENSE_STEP + 2.0
    rev = run.rev
    k = min(len(rev), 64)
    if k >= 2 and math.isfinite(n_target):
        per_rev = (rev.t[-1] - rev.t[-k]) / (k - 1)
        t_last = rev[-1][0] + max(n_target - len(rev), 0.0) * per_rev  # of the n_target-th reversal
        est = min(est, len(buf) + max(t_last - t_now, 0.0) / DENSE_STEP + 2.0)
    return est


def dense_loop(run: "Run", times: Optional[np.ndarray], t_end: float, n_target: float, buf: SampleBuffer) -> None:
    """Samples at the normalised ``times`` (every ``DENSE_STEP`` if None) into ``buf``,
    integrating up to the normalised time ``t_end`` or ``n_target`` reversals."""
    if times is not None:
        for k in range(0, len(times), _BLOCK):
            if dense(run, times[k:k + _BLOCK], t_end, n_target, buf):
                return
        run.advance(t_end, n_target)
        return
    k0 = 0  # index of the next sample: t~ = k DENSE_STEP
    while True:
        block = DENSE_STEP * np.arange(k0, k0 + _BLOCK, dtype=float)
        block = block[block <= t_end]
        if block.size and block[-1] < t_end < block[-1] + DENSE_STEP:
            block = np.append(block, t_end)  # the last sample is at t_end
        if block.size == 0:
            return
        if len(buf) + block.size > buf.capacity:  # grow to the estimated final count (2 % margin),
            # at most doubling: an estimate made early (gross sliding) may be far off
            est = 1.02 * _estimate(run, buf, t_end, n_target) + 2 * N_DENSE
            buf.reserve(max(len(buf) + block.size, int(min(est, 2 * buf.capacity))))
        if dense(run, block, t_end, n_target, buf):
            return
        k0 += _BLOCK


