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

from prefriction.signals.compiled import linear_pieces
from prefriction.simulation.dense import dense_loop
from prefriction.simulation.loops.feedback_loop import run_feedback_loop
from prefriction.simulation.native.forced import run_forced
from prefriction.simulation.run import Run
from prefriction.simulation.run_state import RunState
from prefriction.simulation.samples import SampleBuffer

__all__ = ["RAMP_ROUNDOFF", "check_ramps", "drive", "sampled_loop"]

RAMP_ROUNDOFF = 0.3
"""Largest force error from the round-off of the time in a ramp of the input force, in units of
the run's error level ``eps`` times the force scale (:func:`prefriction.simulate` refuses
steeper ramps: they started spurious reversal pairs at a rest, or NaN in CasADi's event
transition)."""


def drive(run: Run, t_end: float, n_target: float, times: Optional[np.ndarray], want_dense: bool,
          xc0: np.ndarray, rtol: float) -> tuple[Union[SampleBuffer, list], list]:
    """Run ``run`` from its initial state to the normalised time ``t_end`` or ``n_target``
    reversals on its path: a sampled controller's loop (:func:`sampled_loop`), the forced native
    driver, dense output at the normalised ``times`` (all of them if None:
    :func:`~prefriction.simulation.dense.dense_loop`) or :meth:`Run.advance`. Returns the samples
    (empty without dense output or a sampled controller) and a sampled controller's applied
    forces [N]. First :func:`check_ramps` holds the input's ramps against the run's error
    level (``rtol`` names it in the message)."""
    check_ramps(run, t_end, rtol)
    if run.fb is not None and run.fb.sampled:
        return sampled_loop(run, xc0, t_end, n_target)
    # the requested times bound the count of samples (every DENSE_STEP: grown to an estimate)
    buf = SampleBuffer(len(xc0), len(times) if times is not None else 1024) if want_dense else None
    if run.native_forced is not None:
        run_forced(run, t_end, n_target, times, buf)
    elif buf is not None:
        dense_loop(run, times, t_end, n_target, buf)
    else:
        run.advance(t_end, n_target)
    return ([] if buf is None else buf), []


def sampled_loop(run: Run, xc0: np.ndarray, t_end: float,
                 n_target: float) -> tuple[SampleBuffer, Union[list, np.ndarray]]:
    """Closed loop with a sampled controller: hold its output over each period ``Ts`` up to the
    normalised time ``t_end`` or ``n_target`` reversals; returns the samples at ``k Ts`` and the
    total applied force there [N]. On the native sampled loop where it was built
    (:func:`~prefriction.simulation.loops.feedback_loop.run_feedback_loop`), else one CasADi call
    per period."""
    if run.native_loop is not None:
        return run_feedback_loop(run, xc0, t_end, n_target)
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
        u_hist.append(uk + (_input_after(run, t_si, feedback.Ts) if system.forced else 0.0))
        if tk >= t_end * (1 - 1e-12):
            break
        xc = feedback.A @ xc + feedback.B[:, 0] * e
        if run.advance(min((k + 1) * Ts, t_end), n_target):
            break
        k += 1
    return samples, u_hist


def _input_after(run: Run, t: float, Ts: float) -> float:
    """The oscillator's input force [N] applied from the sample instant ``t`` [s] on: a
    piecewise-linear input's piece over ``[t, t + Ts]`` (its value after a break at ``t``, which
    the round-off of ``t`` could place before it), else the input at ``t``."""
    sig = run.spec.u_sig
    if sig is not None and sig.key == ("PiecewiseLinear",):
        return float(linear_pieces(sig, np.array([t]), np.array([t + Ts]))[0][0])
    return float(run.system.u(t))


def check_ramps(run: RunState, t_end: float, rtol: float) -> None:
    """ValueError if a piece of a piecewise-linear input force is so steep that the round-off of
    its time makes a force error above :data:`RAMP_ROUNDOFF` of the run's error level.

    The plant evaluates a piece as ``a + b (t - t_k)`` from the normalised time ``t``, which
    carries a round-off of about ``2^-53 t``; a slope ``b`` turns it into a force error
    ``2^-53 |b| t``. Near a rest the net force is compared with the error level ``eps`` times the
    force scale (:data:`prefriction.simulation.plant.EPS_REST`): a larger error started the mass
    backwards (a spurious reversal pair), or made CasADi's event transition return NaN.
    """
    sig, sc = run.spec.u_sig, run.sc
    if sig is None or sig.key != ("PiecewiseLinear",):
        return
    level = run.eps * max(run.force_scale, 1e-300)  # error level of the net force (normalised)
    t = np.concatenate(([0.0], run.breaks[run.breaks < t_end], [t_end]))
    _, slopes = linear_pieces(sig, t[:-1] * sc.t, t[1:] * sc.t)  # vectorised: one pass over the pieces
    slopes = np.abs(slopes) * (sc.t / sc.F)  # normalised
    errs = slopes * t[1:] * 2.0 ** -53
    for k in np.flatnonzero(errs > RAMP_ROUNDOFF * level)[:1]:
        ta, tb, slope, err = float(t[k]), float(t[k + 1]), float(slopes[k]), float(errs[k])
        if err > RAMP_ROUNDOFF * level:
            rise = abs(slope) * (tb - ta) * sc.F
            shortest = rise / sc.F * tb * 2.0 ** -53 / (RAMP_ROUNDOFF * level) * sc.t
            raise ValueError(
                f"system.u ramps by {rise:.3g} N over {(tb - ta) * sc.t:.3g} s (from t = {ta * sc.t:.12g} s): at rtol = "
                f"{rtol:g} that is too steep to simulate, because the round-off of the time there (2^-53 t) makes a "
                f"force error of {err * sc.F:.3g} N, more than RAMP_ROUNDOFF = {RAMP_ROUNDOFF:g} times the error "
                f"level of the net force ({level * sc.F:.3g} N) at which a resting mass starts to move. Spread the "
                f"ramp over at least {shortest:.3g} s, loosen rtol, or drop one of its two samples (a jump)"
            )
