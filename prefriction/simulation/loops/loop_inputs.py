"""The run-time numbers of a sampled loop: its parameters and its per-sample inputs.

Shared by :func:`prefriction.simulation.loops.runner.run_sampled` (``controllers.simulate_loop``)
and the native run of a sampled :class:`~prefriction.simulation.feedback.LinearFeedback` in
:func:`prefriction.simulate` (:mod:`prefriction.simulation.loops.feedback_loop`), in the
layout of :class:`~prefriction.simulation.loops.compiled_loop.LoopLayout`.
"""

from __future__ import annotations

import numpy as np

from prefriction.models import FrictionModel
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.plant import Layout
from prefriction.units import Scales

from .compiled_loop import LoopLayout

__all__ = ["loop_params", "padded", "sample_inputs"]


def padded(M: np.ndarray, n: int, shape: tuple[int, int]) -> np.ndarray:
    """``M`` in the top-left corner of zeros of ``shape`` (a controller padded to order ``n``)."""
    out = np.zeros(shape)
    out[: M.shape[0], : M.shape[1]] = M
    return out


def loop_params(par: np.ndarray, LL: LoopLayout, L: Layout, model: FrictionModel, sc: Scales, fb: LinearFeedback,
                eps: float, rtol: float, force_scale: float) -> np.ndarray:
    """Fill the run-time parameters ``par`` of a loop without force limit, measurement effects or
    compensator: the plant's constants (tolerance ``eps``, ``rtol``, the units ``sc``, the model's
    numbers), the controller ``fb`` (SI, padded to the layout's order), ``Ts`` and the applied
    ``force_scale`` [Fc]; returns the plant's part (a view)."""
    n = LL.p_B.stop - LL.p_B.start
    par[:] = 0.0
    P0 = par[LL.p_plant]
    pl = L.param
    P0[pl["eps"]], P0[pl["snap"]] = eps, rtol
    P0[pl["tunit"]], P0[pl["xunit"]], P0[pl["Fc"]] = sc.t, sc.x, sc.F
    P0[L.q] = model.runtime_params_for(sc)
    par[LL.p_A] = padded(fb.A, n, (n, n)).T.ravel()  # column-major, as ca.reshape reads it
    par[LL.p_B] = padded(fb.B, n, (n, 1))[:, 0]
    par[LL.p_C] = padded(fb.C, n, (1, n))[0]
    par[LL.param["D"]] = fb.D[0, 0]
    par[LL.param["umax"]] = 1e300
    par[LL.param["Ts"]] = fb.Ts
    par[LL.param["force_scale"]] = force_scale
    par[LL.p_delay.start] = 1.0  # the position of this sample (no delay)
    return P0


def sample_inputs(LL: LoopLayout, fb: LinearFeedback, sc: Scales, tk: np.ndarray, t_end_n: float, Ts_n: float,
                  pad: int) -> np.ndarray:
    """Per-sample inputs of the loop at the normalised sample instants ``tk`` (the last at
    ``t_end_n``, period ``Ts_n``) and ``pad`` inactive rows after them: times, activity and the
    reference ``fb.reference`` [m] at ``t_k`` and ``t_{k+1}``."""
    n_s = len(tk)
    Wall = np.zeros((n_s + pad, LL.nw))
    ii = LL.inp
    Wall[:, ii["t0"]] = t_end_n
    Wall[:, ii["t1"]] = t_end_n
    Wall[:n_s, ii["t0"]] = tk
    Wall[: n_s - 1, ii["t1"]] = tk[1:]
    Wall[: n_s - 1, ii["active"]] = 1.0
    Wall[:n_s, ii["r"]] = np.asarray(fb.reference(tk * sc.t), dtype=float)
    Wall[: n_s - 1, ii["rn"]] = Wall[1:n_s, ii["r"]]
    # the last sample's force is the controller's there: the reference goes on one period (not frozen)
    Wall[n_s - 1, ii["rn"]] = float(np.asarray(fb.reference(np.array([(tk[-1] + Ts_n) * sc.t])), dtype=float)[0])
    return Wall
