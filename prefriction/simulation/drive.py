"""The path of one :func:`prefriction.simulate` run, from its initial state to its end.

:func:`drive` chooses the path by the plant that was built for the run
(:mod:`prefriction.simulation.build`): a sampled controller's loop (:func:`sampled_loop`), the
forced native driver (:func:`~prefriction.simulation.native.forced.run_forced`), CasADi's
dense-output loop (:func:`~prefriction.simulation.dense.dense_loop`) or the reversals only
(:meth:`~prefriction.simulation.run.Run.advance`, on the unforced native driver where it was
built). The samples go into a :class:`~prefriction.simulation.samples.SampleBuffer`.
"""

from __future__ import annotations

from typing import Optional, Union

import numpy as np

from prefriction.simulation.dense import dense_loop
from prefriction.simulation.native.forced import run_forced
from prefriction.simulation.run import Run
from prefriction.simulation.samples import SampleBuffer

__all__ = ["drive", "sampled_loop"]


def drive(run: Run, t_end: float, n_target: float, times: Optional[np.ndarray], want_dense: bool,
          xc0: np.ndarray) -> tuple[Union[SampleBuffer, list], list]:
    """Run ``run`` from its initial state to the normalised time ``t_end`` or ``n_target``
    reversals on its path: a sampled controller's loop (:func:`sampled_loop`), the forced native
    driver, dense output at the normalised ``times`` (all of them if None:
    :func:`~prefriction.simulation.dense.dense_loop`) or :meth:`Run.advance`. Returns the samples
    (empty without dense output or a sampled controller) and a sampled controller's applied
    forces [N]."""
    if run.fb is not None and run.fb.sampled:
        return sampled_loop(run, xc0, t_end, n_target)
    if run.native_forced is not None:
        samples = SampleBuffer(0, len(times) if times is not None else 1024) if want_dense else []
        run_forced(run, t_end, n_target, times, samples if want_dense else None)
        return samples, []
    if want_dense:
        return dense_loop(run, times, t_end, n_target), []
    run.advance(t_end, n_target)
    return [], []


def sampled_loop(run: Run, xc0: np.ndarray, t_end: float, n_target: float) -> tuple[SampleBuffer, list]:
    """Closed loop with a sampled controller: hold its output over each period ``Ts`` up to the
    normalised time ``t_end`` or ``n_target`` reversals; returns the samples at ``k Ts`` and the
    total applied force there [N]."""
    system, feedback, sc = run.system, run.fb, run.sc
    samples = SampleBuffer(len(xc0))
    u_hist: list = []
    Ts = feedback.Ts / sc.t
    xc = xc0.copy()
    k = 0
    while True:
        tk = min(k * Ts, t_end)
        t_si = tk * sc.t
        e = float(feedback.reference(t_si)) - run.st["x"] * sc.x
        uk = float(feedback.C[0] @ xc + feedback.D[0, 0] * e)
        run.st["uhold"] = uk
        run.st["xc"] = xc.copy()
        samples.append(run.sample())
        u_hist.append(uk + (float(system.u(t_si)) if system.forced else 0.0))
        if tk >= t_end * (1 - 1e-12):
            break
        xc = feedback.A @ xc + feedback.B[:, 0] * e
        if run.advance(min((k + 1) * Ts, t_end), n_target):
            break
        k += 1
    return samples, u_hist
