"""Positions a fitted model predicts for another :class:`Motion` record (``FitResult.predict``).

The record's applied force ``u`` drives ``m x'' + F + F_off = u`` (2.1) with the fitted model,
mass and offset, from an initial state taken from the record, sample by sample through the same
step as the fit (:func:`prefriction.identify.motion_step.step_function`, ``u`` held or linear
as ``data.hold`` says). This is a simulation, not a one-step-ahead prediction: nothing of the
record but its first samples enters, so the error accumulates as it would in a model used to
design a controller. A record that starts mid-motion has a friction state nobody measured:
by default it is the friction force of the first sample's force balance ``u - m a - F_off``
(``a`` from a Savitzky-Golay fit of the first samples), taken as the model's state of that
force (``initial_state``); give ``F0`` when it is known (a record that starts at rest after a
long stop, for instance).
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

from prefriction._validation import check_finite
from prefriction.identify.data import Motion
from prefriction.identify.motion_start import derivatives
from prefriction.identify.motion_step import step_function
from prefriction.units import Scales


__all__ = ["predict_motion"]

_WINDOW = 7
"""Savitzky-Golay window [samples] of the initial velocity and acceleration."""
_SIMS: dict[Any, ca.Function] = {}


def predict_motion(result: Any, data: Motion, *, v0: float | None = None, F0: float | None = None,
                   substeps: int | None = None) -> np.ndarray:
    """Positions [m] of ``result``'s fitted model driven by ``data.u``, from ``data.x[0]``.

    Parameters
    ----------
    result : FitResult
        A fit to :class:`Motion` data (:func:`prefriction.identify.fit`); its model, mass
        (:attr:`FitResult.mass`) and offset (``"offset"`` if fitted) are used.
    data : Motion
        The record: times, positions (only the first samples are used) and applied force.
    v0 : float, optional
        Initial velocity [m/s]; default: the smoothed velocity at the first sample.
    F0 : float, optional
        Initial friction force [N] (the model's state of that force); default: ``u - m a - F_off``
        at the first sample, clipped to 99 % of the model's largest hysteretic force.
    substeps : int, optional
        Runge-Kutta sub-steps per sample, 1 to 64; default: as the fit chooses them.

    Returns
    -------
    numpy.ndarray
        Predicted positions [m] at ``data.t``.

    Raises
    ------
    TypeError
        If ``data`` is not :class:`Motion` or ``result`` is not a Motion fit.
    ValueError
        If ``v0`` or ``F0`` is not finite, or ``substeps`` is outside ``[1, 64]``.

    Examples
    --------
    >>> x_hat = result.predict(held_out)   # doctest: +SKIP
    """
    from prefriction.identify.shooting import _substeps

    if not isinstance(data, Motion) or result.mass is None:
        raise TypeError(f"predict_motion needs a Motion fit and Motion data, got a fit to "
                        f"{type(result.data).__name__} and {type(data).__name__}")
    model, m = result.model, float(result.mass)
    off = result.estimate("offset") if "offset" in result.names else 0.0
    _x, v, a = derivatives(data.t, data.x, _WINDOW)
    v0 = float(v[0]) if v0 is None else check_finite("v0", v0)
    if F0 is None:
        cap = 0.99 * model.max_hysteretic_force
        F0 = float(np.clip(data.u[0] - m * a[0] - off, -cap, cap))
    else:
        F0 = check_finite("F0", F0)
    if substeps is not None and not (isinstance(substeps, int) and 1 <= substeps <= 64):
        raise ValueError(f"substeps must be an integer in [1, 64], got {substeps!r}")
    n_sub = _substeps(model, data, m, v, substeps)
    s0 = 1.0 if v0 > 0 else -1.0 if v0 < 0 else (1.0 if data.u[0] - off - F0 >= 0 else -1.0)
    z0, m0 = model.initial_state(F0 / model.Fc, s0)
    sc = Scales(x=model.Fc / model.sigma, F=model.Fc, t=math.sqrt(m / model.sigma),
                v=model.Fc / math.sqrt(m * model.sigma), E=model.Fc**2 / model.sigma)
    pp = np.r_[m, model.sigma, model.Fc, off, np.asarray(model.runtime_params_for(sc), dtype=float)]
    u0 = data.u[:-1]
    u1 = u0 if data.hold == "zoh" else data.u[1:]
    sim = _simulator(model, n_sub, len(data) - 1)
    Y = np.asarray(sim(np.r_[float(data.x[0]), v0, z0, m0, s0], u0[None, :], u1[None, :], np.diff(data.t)[None, :], pp))
    return np.r_[data.x[0], Y[0]]


def _simulator(model: Any, n_sub: int, n: int) -> ca.Function:
    """The step of ``model`` repeated over ``n`` samples (``mapaccum``), cached per structure."""
    key = (type(model), model.structure_key(), n_sub, n)
    if key not in _SIMS:
        if len(_SIMS) > 16:
            _SIMS.clear()
        _SIMS[key] = step_function(model, n_sub).mapaccum("predict", n)
    return _SIMS[key]
