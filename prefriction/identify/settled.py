"""Whether a converged Motion fit sits at the minimum its own statistics describe.

The solver of a Motion fit stops on its tolerances (relative decrease of the sum of squares, step
size, continuity defects). In a curved valley of the sum of squares (two parameters the record
pins only in a combination, such as the excess ``Fs - Fc`` and the attraction rate ``C`` of a GMS,
:mod:`prefriction.identify.held_first`) the trust region creeps along the bend and can stop
where the parameters the record does pin are still several standard errors from where the
valley's floor puts them: an interval centred there does not hold the truth at its nominal rate.

The Gauss-Newton step of the single-shooting residual at the solution,
``d = -(J^T J)^+ J^T r`` (the Jacobian and residuals the statistics use), measures that distance
in the statistics' own units: at the minimum of a smooth problem it is zero, and its component
``d_i`` over the standard error ``se_i`` of an estimate is how far the linearised minimum lies from
that estimate. Measured on the 1,000-sample GMS(2) records of
:mod:`prefriction.identify._success_events`: a fit stopped 67 residual variances above the valley's
floor had a step of 3 standard errors in ``k[0]``, where that stiffness was 3 standard errors
from the truth.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SETTLED", "unsettled", "unsettled_message"]

SETTLED = 2.0
"""Largest Gauss-Newton step, in standard errors, of an estimate the data pin, at a settled fit: a
linearised minimum beyond it lies outside the estimate's 95 % interval."""


def unsettled(J: np.ndarray, r: np.ndarray, names: list[str], scale: np.ndarray, stderr: np.ndarray,
              pinned: np.ndarray) -> tuple[tuple[str, float], ...]:
    """The pinned estimates whose Gauss-Newton step exceeds :data:`SETTLED` standard errors.

    Parameters
    ----------
    J : numpy.ndarray
        Residual Jacobian (``n x (k + nuisance)``), its first ``k = len(names)`` columns the scaled
        parameters ``p / scale`` (as :func:`prefriction.identify.statistics.gauss_newton` takes it).
    r : numpy.ndarray
        Residuals at the solution (``n``).
    names : list of str
        Parameter names.
    scale : numpy.ndarray
        ``p = w * scale`` of the parameter columns.
    stderr : numpy.ndarray
        Standard errors of the estimates (physical units).
    pinned : numpy.ndarray of bool
        The estimates the data identify (the others' steps are not judged: along their valley the
        sum of squares is flat and the linearisation says little).

    Returns
    -------
    tuple of (str, float)
        ``(name, step in standard errors)`` of each pinned estimate beyond :data:`SETTLED`.
    """
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
        return ()
    d, *_ = np.linalg.lstsq(J, -r, rcond=None)
    k = len(names)
    with np.errstate(invalid="ignore", divide="ignore"):
        size = np.abs(d[:k] * scale) / stderr
    return tuple((n, float(size[i])) for i, n in enumerate(names)
                 if pinned[i] and np.isfinite(size[i]) and size[i] > SETTLED)


def unsettled_message(found: tuple[tuple[str, float], ...], loose: tuple[tuple[str, str], ...]) -> str:
    """The message of a fit that stopped short of its minimum (:func:`unsettled`): where, why and
    what helps; ``loose`` the unidentifiable parameters and why (``Statistics.unidentifiable``)."""
    steps = ", ".join(f"{n} by {s:.2g}" for n, s in found)
    names = [n for n, _ in loose]
    why = (f"; the record does not pin {', '.join(names)} (" + "; ".join(f"{n}: {w}" for n, w in loose)
           + "): a flat, curved valley of the sum of squares the solver creeps along") if names else ""
    hold = ("hold " + " or ".join(f"fixed=[{n!r}]" for n in names) + " at a value you know, ") if names else ""
    return (f"the solver stopped short of the minimum: a Gauss-Newton step at the solution moves {steps} standard "
            f"errors{why}. The estimates and their intervals are not final. What helps: {hold}start values "
            f"closer to the truth, or a record that excites the friction more (slow reversals, speeds near the "
            f"Stribeck velocity) (docs/identify_motion.md#limits)")
