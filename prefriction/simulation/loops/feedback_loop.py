"""A sampled :class:`~prefriction.simulation.feedback.LinearFeedback` of :func:`prefriction.simulate`
on the native sampled loop (``native/loop.c``, the driver of ``controllers.simulate_loop``).

The controller ``xc[k+1] = A xc[k] + B e[k]``, ``u[k] = C xc[k] + D e[k]``, ``e[k] = r(k Ts) -
x(k Ts)`` is the loop's law without force limit, measurement effects or compensator
(:func:`~prefriction.simulation.loops.compiled_loop.control_law`); its output is held over each
period, every reversal located inside it, the step size carried over from period to period;
:data:`NATIVE_BLOCK` periods per C call. The oscillator's own input force, of any
:mod:`prefriction.signals` kind, is generated as C as for a forced run
(:func:`~prefriction.simulation.native.forced.input_function`) and added to the held force, the
integration broken at its break times inside a period. A run that asks for ``reversals`` stops
after the block in which they came and keeps the samples up to the last reversal, as the CasADi
loop of
:func:`prefriction.simulation.drive.sampled_loop` does.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Optional

import numpy as np

from prefriction._memory import check_memory
from prefriction.signals.compiled import linear_pieces
from prefriction.simulation.feedback import sample_count
from prefriction.simulation.native.forced import input_tables
from prefriction.simulation.samples import SampleBuffer

from .compiled_loop import LoopLayout, LoopSpec
from .loop_inputs import loop_params, padded, sample_inputs
from .native_loop import LoopDriver, loop_driver, run_blocks

if TYPE_CHECKING:
    from prefriction.simulation.plant import PlantSpec
    from prefriction.simulation.run_state import RunState

__all__ = ["MIN_ORDER", "NATIVE_BLOCK", "feedback_loop_driver", "run_feedback_loop"]

NATIVE_BLOCK = 4096
"""Sample periods per C call (bounds the records' buffers and the overshoot of a ``reversals`` stop)."""
MIN_ORDER = 2
"""Controllers are padded to this order: P, PD and PID loops share one library (and share it with
``controllers.simulate_loop``)."""


def _spec(spec: "PlantSpec", n_c: int) -> LoopSpec:
    """The loop of ``spec``'s plant with its input (``spec.u_sig``) and the held force added in C."""
    return LoopSpec(dataclasses.replace(spec, fb="none"), max(n_c, MIN_ORDER), NATIVE_BLOCK)


def feedback_loop_driver(spec: "PlantSpec", n_c: int) -> tuple[Optional[LoopDriver], float]:
    """The native loop of a sampled controller of ``n_c`` states around the open-loop plant
    ``spec`` (its input force, the held force added) and the setup time [s]; ``(None, 0)``
    where it cannot be used (:func:`~prefriction.simulation.loops.native_loop.loop_driver`)."""
    return loop_driver(_spec(spec, n_c))


def _loop_state(run: "RunState", LL: LoopLayout, xc0: np.ndarray, n: int) -> np.ndarray:
    """The loop state of ``LL`` at the start: the plant's from ``run.st``, the controller's ``xc0``
    (padded to ``n`` states), the rest zero."""
    st, ix = run.st, LL.state
    S = np.zeros(LL.nS)
    S[ix["x"]], S[ix["v"]], S[ix["s"]], S[ix["rest"]] = st["x"], st["v"], st["s"], float(st["rest"])
    for i, zi in enumerate(st["z"]):
        S[ix[f"z{i}"]] = zi
    for i, mi in enumerate(st["m"]):
        S[ix[f"m{i}"]] = mi
    S[ix["xc0"]: ix["xc0"] + n] = padded(np.reshape(xc0, (1, -1)), n, (1, n))[0]
    return S


def run_feedback_loop(run: "RunState", xc0: np.ndarray, t_end: float,
                      n_target: float) -> tuple[SampleBuffer, np.ndarray]:
    """The sampled loop of ``run`` (``run.native_loop``, ``run.fb`` sampled) from its state
    ``run.st`` to the normalised ``t_end`` or ``n_target`` reversals; the reversals go into
    ``run.rev`` and ``run.rev_events``, the final state into ``run.st``. Returns the samples at
    ``k Ts`` (normalised) and the applied force there [N]."""
    drv, fb, sc, st = run.native_loop, run.fb, run.sc, run.st
    LL = LoopLayout(_spec(run.spec, fb.n_states))
    n = LL.p_B.stop - LL.p_B.start
    L = LL.plant
    Ts_n = fb.Ts / sc.t
    n_s = sample_count(t_end, Ts_n, t_end / Ts_n)
    check_memory(f"the sampled loop of {type(run.model).__name__}", n_s, LL.nw + LL.nrec + 6 + n,
                 "sample instants", "increase Ts or split the run")
    tk = np.minimum(np.arange(n_s) * Ts_n, t_end)
    par = np.zeros(LL.npar)
    P0 = loop_params(par, LL, L, run.model, sc, fb, run.eps, run.snap, run.force_scale)
    Wall = sample_inputs(LL, fb, sc, tk, t_end, Ts_n, 0)  # no line of the input: it is pf_input's
    S = _loop_state(run, LL, xc0, n)
    cfg = np.array([run.eps_native, run.eps, run.snap, sc.t, 1.0 / sc.F, run.force_scale, 0.0,
                    1.0 if drv.linear else 0.0, 0.0])
    recs, cols, calls, steps, fst = run_blocks(drv, LL, S, Wall, n_s, par, np.ascontiguousarray(P0[L.q]), cfg,
                                               NATIVE_BLOCK, n_target,
                                               input_tables(run, run.spec.u_sig, t_end) if run.system.forced else None)
    run.calls += calls
    run.steps = (run.steps or 0) + steps
    stopped = len(cols[0]) >= n_target
    n_rev = int(min(n_target, len(cols[0])))
    if stopped:  # at the n_target-th reversal: the samples up to it (k Ts <= its time)
        recs = recs[:max(int(np.searchsorted(tk[:len(recs)], cols[0][n_rev - 1], side="right")), 1)]
    run.rev.extend_columns(cols[0][:n_rev], cols[1][:n_rev], cols[2][:n_rev], cols[3][:n_rev])
    run.rev_events.extend(cols[4][:n_rev].astype(int).tolist())
    ix, last = LL.state, recs[-1]
    st.update(t=float(tk[len(recs) - 1]), x=float(last[ix["x"]]), v=float(last[ix["v"]]), s=float(last[ix["s"]]),
              z=[float(last[ix[f"z{i}"]]) for i in range(L.nz)], m=[float(last[ix[f"m{i}"]]) for i in range(L.nm)],
              rest=float(last[ix["rest"]]), W=float(last[ix["W"]]), ne=int(fst[4]), F=float(last[LL.rec["F"]]),
              xc=last[ix["xc0"]: ix["xc0"] + n].copy())
    if stopped:  # the state at the reversal
        st.update(t=float(cols[0][n_rev - 1]), x=float(cols[1][n_rev - 1]), v=0.0, F=float(cols[2][n_rev - 1]), ne=0)
    buf = SampleBuffer(n, len(recs))
    buf.extend(tk[:len(recs)], recs[:, ix["x"]], recs[:, ix["v"]], recs[:, LL.rec["F"]], 0.0,
               recs[:, ix["xc0"]: ix["xc0"] + n])
    return buf, recs[:, LL.rec["u"]] + _input_after(run, tk[:len(recs)] * sc.t, fb.Ts)


def _input_after(run: "RunState", t: np.ndarray, Ts: float) -> np.ndarray:
    """The oscillator's input force [N] applied from each sample instant ``t`` [s] on (as
    :func:`prefriction.simulation.drive.sampled_loop` records it): a piecewise-linear input's
    value at the start of its piece over ``[t, t + Ts]``, else the input at ``t``; zero without one."""
    if not run.system.forced:
        return np.zeros(len(t))
    sig = run.spec.u_sig
    if sig.key == ("PiecewiseLinear",):
        return linear_pieces(sig, t, t + Ts)[0]
    return np.asarray(run.system.u(t), dtype=float) * np.ones(len(t))
