"""The run-time numbers of a continuous controller on the forced native driver (``pf_forced_fb``).

The controller of a :class:`~prefriction.simulation.feedback.LinearFeedback` (``Ts=None``) in
the normalised units of the CasADi plant (:mod:`prefriction.simulation.plant`, module notes;
``docs/simulator.md#native-forced``): ``An = A t_unit``, ``Bn = B t_unit x_unit``,
``Cn = C / Fc``, ``Dn = D x_unit / Fc``, ``umax = u_max / Fc`` (1e300: none),
``kaw = k_aw t_unit Fc``, then the error scales ``1 / |Cn_i|`` (1 where ``Cn_i = 0``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from prefriction.simulation.run_state import RunState

__all__ = ["controller_numbers"]


def controller_numbers(run: "RunState", state: np.ndarray, k: int,
                       pcr: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Write the controller states and the clip's mode of ``run`` into the driver's run state
    ``state`` from entry ``k`` on and return the arguments ``fbp, thr, pcr`` of ``pf_forced_fb``
    (``pcr``: the reference's per-interval numbers, rows as the input's)."""
    fb, sc, nc = run.fb, run.sc, run.spec.n_c
    state[k:k + nc] = np.asarray(run.st["xc"], dtype=float)
    st = run.st
    if fb.u_max is None:  # the force limit's mode now: 0 inside, +-1 clipped at +-u_max
        state[k + nc] = 0.0
    else:
        w = float(fb.output(st["xc"], float(fb.reference(st["t"] * sc.t)) - st["x"] * sc.x))
        state[k + nc] = 0.0 if abs(w) <= fb.u_max else math.copysign(1.0, w)
    Cn = fb.C[0] / sc.F
    xs = np.where(Cn != 0.0, 1.0 / np.where(Cn == 0.0, 1.0, np.abs(Cn)), 1.0)
    umax = 1e300 if fb.u_max is None else fb.u_max / sc.F
    fbp = np.concatenate(((fb.A * sc.t).ravel(), fb.B[:, 0] * sc.t * sc.x, Cn, [fb.D[0, 0] * sc.x / sc.F, umax],
                          fb.k_aw * sc.t * sc.F, xs))
    thr = np.ascontiguousarray(_params(run.spec.r_sig), dtype=float)
    return np.ascontiguousarray(fbp), thr if thr.size else np.zeros(1), np.ascontiguousarray(pcr, dtype=float)


def _params(sig: Any) -> np.ndarray:
    return np.zeros(0) if sig is None else np.asarray(sig.params(), dtype=float)
