"""Runge-Kutta sub-steps fine enough that the discretisation moves no estimate of a Motion fit.

A :class:`prefriction.identify.Motion` fit simulates the stage by ``n_sub`` classical RK4
sub-steps per sample (:mod:`prefriction.identify.motion_step`). Its error, ``O(h^4)`` in the
sub-step ``h``, is a bias of the simulated positions that no interval contains. The rule that
picks ``n_sub`` (:func:`prefriction.identify.shooting._substeps`) bounds ``h`` by the stage's
period and the model's rates; it does not know the noise. On a record that pins the parameters
to a few parts per million (95.1 kg, 1 kHz, 50 nm encoder, 1,000 samples) the bias of two
sub-steps per sample was 13 standard errors of Dahl's ``sigma``.

The check here measures that bias in the covariance's own units: at the estimate ``w`` it
evaluates the single-shooting residual ``r`` with ``n_sub`` and ``r_f`` with ``2 n_sub``
sub-steps (the chain from the first node, same parameters), and takes the Gauss-Newton step
``d = (J^T J)^+ J^T (r_f - r)`` that the finer simulation would move the parameters by (``J``
the reduced Jacobian of the statistics). With RK4 the bias of ``n_sub`` is ``16/15 d``. If any
free parameter's ``|d|`` exceeds :data:`STEP_SHIFT` of its (white-residual) standard error, the
fit is solved again with ``2 n_sub`` from ``w`` and checked again, up to 64 sub-steps.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RELATIVE_FLOOR", "STEP_SHIFT", "step_shift"]

STEP_SHIFT = 0.1
"""Most change of an estimate, in its standard errors, that doubling the Runge-Kutta sub-steps
may cause before a Motion fit (or the closed-loop route's recorded-force stage) is solved again with twice as many (the bias left is then at most
``0.1 * 16 / 15`` standard errors)."""

RELATIVE_FLOOR = 1e-6
"""Smallest standard error, relative to the estimate, that the check measures shifts against: on a
record with (nearly) no noise the standard errors shrink with the discretisation error itself, and a
bias below a part per million of every estimate is not worth more sub-steps."""


def step_shift(J: np.ndarray, r: np.ndarray, r_fine: np.ndarray, params: np.ndarray | None = None,
               values: np.ndarray | None = None, *, centred: bool = False) -> float:
    """Largest change of a parameter, in its white-residual standard errors, from the residuals
    ``r`` to ``r_fine`` at the same point.

    Parameters
    ----------
    J : numpy.ndarray
        Residual Jacobian ``n x c`` (parameters and nuisance columns).
    r, r_fine : numpy.ndarray
        Residuals [any unit, the same as ``J``'s rows] of the coarse and the fine simulation.
    params : numpy.ndarray, optional
        Indices of the columns of ``J`` that are parameters (the others are nuisance: marginalised);
        all columns if omitted.
    values : numpy.ndarray, optional
        The parameters' values in ``J``'s columns; their standard errors are then taken at least
        :data:`RELATIVE_FLOOR` times ``|values|``.
    centred : bool
        The residuals carry a profiled-out constant (the closed-loop replay's initial position,
        :mod:`prefriction.identify.closed_loop_fit`): ``r`` and ``r_fine`` are centred first and
        ``s^2 = |r - mean(r)|^2 / n``.

    Returns
    -------
    float
        ``max_i |d_i| / se_i`` over ``params``, ``d = (J^T J)^+ J^T (r_fine - r)`` and
        ``se_i = s sqrt((J^T J)^+_ii)``, ``s^2 = |r|^2 / (n - c)`` (centred: ``|r - mean(r)|^2 / n``; at
        least ``RELATIVE_FLOOR |values_i|``); ``inf`` if a residual is not finite.
    """
    params = np.arange(J.shape[1]) if params is None else params
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(r_fine))) or params.size == 0:
        return float("inf") if params.size else 0.0
    if centred:
        r, r_fine = r - r.mean(), r_fine - r_fine.mean()
    H = np.linalg.pinv(J.T @ J)
    d = H @ (J.T @ (r_fine - r))
    s2 = float(r @ r) / (r.size if centred else max(r.size - J.shape[1], 1))
    se = np.sqrt(np.clip(np.diag(H)[params] * s2, 1e-300, None))
    if values is not None:
        se = np.maximum(se, RELATIVE_FLOOR * np.abs(values[params]))
    return float(np.max(np.abs(d[params]) / se))
