"""The single-shooting polish of a multiple-shooting Motion fit and the profile check of a curved valley.

:func:`polish` takes Gauss-Newton steps (Levenberg-Marquardt steps in a curved valley of the sum of
squares) on the single-shooting problem from the multiple-shooting solution of
:mod:`prefriction.identify.shooting`, so the estimates and their statistics are those of the
single-shooting problem; :func:`valley_secant` profiles the valley parameters
(:func:`prefriction.identify.held_first.valley`) at a held solution and says how much wider than
the linearisation their intervals must be. ``prob`` is the shooting module's problem
(``prefriction.identify.shooting._Problem``: its residuals, reduced Jacobian and node chaining),
typed ``Any`` here so that the two modules do not import each other.
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

from prefriction.identify.held_first import valley
from prefriction.identify.motion_step import segment_functions
from prefriction.identify.parameters import ParameterSpace
from prefriction.models.base import FrictionModel

__all__ = ["POLISH_FRACTIONS", "POLISH_STEPS", "POLISH_TOL", "VALLEY_GAP", "VALLEY_STEPS", "damped", "polish",
           "valley_secant"]


POLISH_STEPS = 6
"""Most Gauss-Newton steps of :func:`polish`."""
POLISH_TOL = 1e-3
"""A Gauss-Newton step below this many standard errors in every parameter ends :func:`polish`."""
POLISH_FRACTIONS = (1.0, 0.5, 0.25, 0.125, 0.0625)
"""Fractions of a Gauss-Newton step :func:`polish` tries, largest first: in a curved valley (GMS
``C`` and ``Fs``, :mod:`prefriction.identify.held_first`) the full step leaves the bend."""
VALLEY_STEPS = 40
"""Most Levenberg-Marquardt steps of :func:`polish` in a curved valley (``valley=True``)."""
VALLEY_GAP = 0.5
"""In a curved valley, :func:`polish` ends when the decrease of ``|r|^2`` the Gauss-Newton step
predicts is below this many residual variances."""


def damped(J: np.ndarray, r: np.ndarray, lam: float) -> np.ndarray:
    """The Levenberg-Marquardt step ``-(J^T J + lam D^2)^-1 J^T r``, ``D`` the column norms of ``J``
    (floored at ``1e-9`` of the largest: a node state the record does not see)."""
    dg = np.sqrt(np.sum(J * J, axis=0))
    dg = np.maximum(dg, 1e-9 * float(np.max(dg, initial=1e-300)))
    A = np.vstack([J, math.sqrt(lam) * np.diag(dg)])
    return np.linalg.lstsq(A, np.r_[-r, np.zeros(J.shape[1])], rcond=None)[0]


def polish(prob: Any, w: np.ndarray, single: ca.Function, lo: np.ndarray,
            hi: np.ndarray, valley: bool = False, hold: tuple[int, ...] = ()) -> tuple[np.ndarray, str]:
    """Gauss-Newton steps on the single-shooting problem from the multiple-shooting solution ``w``.

    The multiple-shooting solution meets the continuity of the segments to :data:`GTOL` of the
    node scales. Chained over the record, such defects move the simulated positions by a fraction
    of the noise, and the parameters that exploit them sit 0.3 to 1.6 standard errors from the
    minimum of the single-shooting problem (measured on the 2.5 kg open-loop stage of
    ``docs/identify.md#coverage``): an error the intervals do not contain. The statistics
    linearise the single-shooting residual ``r(theta, y_0)`` (the chain of segments from the first
    node, each node's flags, the modes of a model's in-branch events, those its predecessor ends
    with), so its Gauss-Newton step ``d = -(J^T J)^+ J^T r`` measures how far ``w`` is from the
    minimum in the covariance's own units. Each step moves the parameters (those strictly inside
    their bounds) and the first node, re-chains the nodes and is kept only if it lowers
    ``|r|^2`` (else a fraction of it, :data:`POLISH_FRACTIONS`); the loop ends when every
    parameter's step is below :data:`POLISH_TOL` standard errors. With ``valley`` (a curved valley
    of the sum of squares: GMS ``C`` and ``Fs`` free, :mod:`prefriction.identify.held_first`) the
    steps are Levenberg-Marquardt steps (:func:`damped`, the damping adapted to the ratio of the
    actual to the predicted decrease), at most :data:`VALLEY_STEPS`, and the loop also ends when the
    Gauss-Newton step predicts a decrease below :data:`VALLEY_GAP` residual variances: there the
    full Gauss-Newton step, and every fraction of it, leaves the bend (measured at the end of the
    free stage of the 25,000-sample GMS(2) record of :mod:`prefriction.identify._success_events`,
    seed 1: a predicted decrease of 263 residual variances, an actual increase for steps of 1 to
    1/8 of it), while damped steps follow the bend and realise the predicted decrease (263 to 2
    residual variances in 6 steps). Freeing the ``c`` continuity defects lowers ``|r|^2`` by
    about ``c s^2``; a polished chain whose ``|r|^2`` exceeds the segments' by more drifts from the
    data (an open-loop replay of a long record) and the multiple-shooting solution is kept.

    ``hold``: indices of parameters held at their values in ``w`` (a profile of the sum of squares).

    Returns
    -------
    (numpy.ndarray, str)
        The polished ``w`` and a note for the solver message (``""`` when nothing moved).
    """
    nth, ny = prob.nth, prob.ny
    w_ms = w
    r_ms, g_ms = prob.plain_eval(w)
    rss_ms = float(r_ms @ r_ms)
    chain = prob.chain_eval(w, single)
    if chain is None:
        prob.clear_flags()
        return w_ms, "; the single-shooting chain is not finite at the solution: not polished"
    w, r = chain
    with np.errstate(invalid="ignore"):
        margin = 1e-9 * np.maximum(1.0, np.abs(w[:nth]))
    where = prob.columns()
    inside = np.r_[(w[:nth] - lo > margin) & (hi - w[:nth] > margin), np.ones(where.size - nth, dtype=bool)]
    inside[list(hold)] = False   # held at their values in w (a profile, valley_secant)
    cols = np.flatnonzero(inside)
    taken, largest, lam = 0, 0.0, 1e-3
    for _ in range(VALLEY_STEPS if valley else POLISH_STEPS):
        J = prob.reduced_jacobian(w)[:, cols]
        d, *_ = np.linalg.lstsq(J, -r, rcond=None)
        s2 = float(r @ r) / max(r.size - cols.size, 1)
        se = np.sqrt(np.clip(np.diag(np.linalg.pinv(J.T @ J)) * s2, 1e-300, None))
        size = float(np.max(np.abs(d / se)[cols < nth], initial=0.0))
        if size < POLISH_TOL or (valley and float(np.sum(np.square(J @ d))) < VALLEY_GAP * s2):
            break
        # in a curved valley, Levenberg-Marquardt steps (the damping adapted to the step's success);
        # else fractions of the Gauss-Newton step
        tries = [(lam * 4.0 ** k, None) for k in range(12)] if valley else [(None, f) for f in POLISH_FRACTIONS]
        for damp, frac in tries:
            step = frac * d if damp is None else damped(J, r, damp)
            trial = w.copy()
            trial[where[cols]] += step
            trial[:nth] = np.clip(trial[:nth], lo, hi)
            chain = prob.chain_eval(trial, single)
            if chain is not None and float(chain[1] @ chain[1]) < float(r @ r):
                trial, rt = chain
                if damp is not None:   # the ratio of actual to predicted decrease sets the next damping
                    pred = float(r @ r) - float(np.sum(np.square(r + J @ step)))
                    rho = (float(r @ r) - float(rt @ rt)) / max(pred, 1e-300)
                    lam = damp * (0.3 if rho > 0.75 else 1.0 if rho > 0.25 else 2.0)
                w, r = trial, rt
                taken += 1
                with np.errstate(invalid="ignore", divide="ignore"):
                    largest = max(largest, float(np.max(np.abs(step[cols < nth] / se[cols < nth]), initial=0.0)))
                break
        else:
            break
    # the defects are g_ms.size slack variables: freeing them lowers |r|^2 by about g_ms.size s^2
    # (a chi-square); a chain that ends far above that drifts from the data (a long record)
    allowed = rss_ms + g_ms.size * rss_ms / max(r_ms.size - nth - ny, 1)
    if float(r @ r) > allowed:
        prob.clear_flags()
        return w_ms, (f"; the single-shooting chain from the first node drifts from the data (|r|^2 "
                      f"{float(r @ r):.3g} against {rss_ms:.3g} of the segments): not polished")
    if not taken:
        return w, ""
    return w, f"; {taken} Gauss-Newton steps of the single-shooting problem moved the parameters by up to " \
              f"{largest:.2g} standard errors"



def valley_secant(prob: Any, w: np.ndarray, J: np.ndarray, r: np.ndarray, space: ParameterSpace,
                   at: FrictionModel, n_sub: int, mass_free: bool, stats: Any) -> dict[str, float]:
    """How much wider than the linearisation the sum of squares puts the valley parameters
    (:func:`prefriction.identify.held_first.valley`: ``C`` and ``Fs``) at ``w``: ``{name: factor > 1}``.

    The linearisation says that ``C`` held ``t`` of its standard errors away (``t`` the 95 % Student
    quantile), the others refitted, raises ``|r|^2`` by ``t^2 s^2``. The profile is computed at both
    ends (``C`` held, the others and the first node refitted by the Levenberg-Marquardt steps of
    :func:`polish`); where the actual rise ``a`` is smaller (a curved, flat valley), ``C``'s secant
    standard error is ``sqrt(t^2 s^2 / a)`` times the linear one (the parabola through the points),
    and ``Fs``'s is widened to reach the ``Fs`` of the profile's ends, scaled alike. Measured on the
    25,000-sample GMS(2) record of seed 1 of :mod:`prefriction.identify._success_events`, held at
    ``C = 27.8``: the profile at the truth ``C = 50`` lies 0.35 residual variances above, while the
    linear standard error of ``C`` was 36 % (the truth 2.2 of them away, outside the interval); the
    others following linearly (no refit) rise by more than ``t^2 s^2``.
    """
    from scipy.stats import t as student_t

    names = valley(at, space)
    if not names or names[0] not in space.free:
        return {}
    single = segment_functions(at, space, prob.lay.K, n_sub, mass_free, prob.native)[0]
    lo, hi = space.theta_bounds()
    chain = prob.chain_eval(w, single)
    if chain is None:
        prob.clear_flags()
        return {}
    wc, rc = chain
    s2 = float(rc @ rc) / max(rc.size - J.shape[1], 1)
    tq = float(student_t.ppf(0.975, stats.dof))
    i = space.free.index(names[0])
    se_i = float(stats.stderr[i]) / abs(float(space.scale[i]))       # in theta
    base = space.values(wc[: prob.nth])
    factor, partner = 1.0, 1.0
    for sign in (1.0, -1.0):
        trial = wc.copy()
        trial[i] = min(max(wc[i] * math.exp(sign * tq * se_i / wc[i]), lo[i]), hi[i])   # C > 0: compounded
        trial = prob.carry_states(trial, single, everything=True)
        prof, _note = polish(prob, trial, single, lo, hi, valley=True, hold=(i,))
        chain = prob.chain_eval(prof, single)
        if chain is None:
            continue
        rt = chain[1]
        rise = max(float(rt @ rt - rc @ rc), 1e-12 * s2)
        if rise >= tq * tq * s2:
            continue
        f = math.sqrt(tq * tq * s2 / rise)
        reach = abs(math.log(prof[i] / wc[i])) * wc[i] / (tq * se_i)   # the distance held, in t se
        factor = max(factor, f * reach)
        if len(names) > 1 and names[1] in space.free:
            j = space.free.index(names[1])
            moved = abs(space.values(prof[: prob.nth])[names[1]] - base[names[1]])
            partner = max(partner, f * moved / (tq * float(stats.stderr[j])))
    prob.clear_flags()   # back to the multiple-shooting flags (the first node's are kept by every chain)
    out = {names[0]: factor} if factor > 1.0 else {}
    if partner > 1.0:
        out[names[1]] = partner
    return out

