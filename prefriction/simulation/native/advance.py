"""The loop of an unforced run on the native driver: blocks of reversals per C call.

:meth:`prefriction.simulation.run.Run.advance` calls :func:`advance_native` for the compact
unforced model when the structure's native driver exists (:func:`~prefriction.simulation.native.library.native_driver`).
One C call runs up to :data:`BLOCK` reversals (or to ``t_target``); the reversals come back in
four arrays and join the run's :class:`~prefriction.simulation.reversal_log.ReversalLog`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from prefriction.simulation.native.library import HEAD
from prefriction.simulation.stiff import advance_stiff

if TYPE_CHECKING:
    from prefriction.simulation.run_state import RunState

__all__ = ["BLOCK", "advance_native"]

BLOCK = 1 << 16  # reversals per C call (4 x 512 kB of output buffers)
STIFF = 6  # the driver's code of a stiff branch (PF_STIFF)
_WHY = {
    2: "its amplitude fell below 1e-250 normalised units, or its velocity crosses zero only at the level of "
       "the integration error",
    3: "the right-hand side became non-finite",
    4: "more than 1e6 steps without a reversal (the driver's limit per half-cycle; these steps were held by the "
       "accuracy asked for, not by stiffness, which switches to the implicit method after 20,000 steps): the "
       "half-cycle is very long against its own time scale",
    5: "the step size fell below round-off of the time",
}


def advance_native(run: "RunState", t_target: float, n_target: float) -> bool:
    """:meth:`~prefriction.simulation.run.Run.advance` (``run``: its state) on the native driver: integrate to normalised time ``t_target`` or
    ``n_target`` reversals (True if the latter), appending the reversals to ``run.rev`` and their
    half-cycles' model events to ``run.rev_events``; ``SolverError`` if the driver stops early."""
    drv, st, model = run.native, run.st, run.model
    times = run.rev.t
    state = np.empty(drv.width)
    state[:HEAD] = (st["t"], st["x"], st["v"], st["s"], st.get("ne", 0),
                    times[-1] if len(times) else math.nan, times[-2] if len(times) > 1 else math.nan, 1.0)
    state[HEAD:HEAD + drv.nz] = st["z"]
    state[HEAD + drv.nz:] = st["m"]
    q = np.ascontiguousarray(run.q, dtype=float)
    done, steps = np.zeros(1, np.int64), np.zeros(1, np.int64)
    n = len(run.rev)
    code = 0
    while n < n_target:
        want = int(min(n_target - n, BLOCK))
        out = np.empty((4, want))
        code = drv.run(q, run.eps, run.snap, state, t_target, want, out[0], out[1], out[2], out[3], done, steps)
        run.calls += 1
        k = int(done[0])
        run.rev.extend_columns(out[0, :k], out[1, :k], out[2, :k])
        run.rev_events.extend(out[3, :k].astype(int).tolist())
        n += k
        if code != 0:
            break
    run.steps = (run.steps or 0) + int(steps[0])
    t, x, v, s, ne = state[:5]
    z, m = state[HEAD:HEAD + drv.nz].tolist(), state[HEAD + drv.nz:].tolist()
    st.update(t=float(t), x=float(x), v=float(v), s=float(s), z=z, m=m, ne=int(ne),
              F=float(model.force(z, m, float(v), float(s), run.q.tolist())))
    if code == STIFF:  # the rest of the run on the implicit method (docs/simulator.md#stiff)
        run.note = (f"switched to the implicit Radau method at t = {st['t'] * run.sc.t:.9g} s after "
                    f"{len(run.rev)} reversal{'' if len(run.rev) == 1 else 's'}: the explicit Runge-Kutta step was held by stability "
                    f"(h |lambda| > 3.25 on 15 steps of a branch longer than 20,000 steps), the problem is stiff")
        return advance_stiff(run, t_target, n_target)
    if code > 1:
        raise run._failure(_WHY[code])
    return n >= n_target
