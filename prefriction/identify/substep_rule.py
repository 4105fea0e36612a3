"""The stiffness of a model along a record, for the RK4 sub-steps of a Motion fit.

A model whose stiffness depends on its state as much as on the speed (Dahl with ``gamma > 1``:
its log-gap ``L`` has the rate ``s v~ exp(-(gamma - 1) L)``, whose derivative in ``L`` is
``-(gamma - 1) |v~| w^(gamma - 1)`` with the gap ``w = 1 - s F / Fc = exp(-L)``) is stiff only
where both are large. The gap is near 2 just after a reversal, where the stage is slow, and
tends to 0 in fast sliding: pairing the record's top speed with a gap after a reversal (the rule
of :func:`prefriction.identify.shooting._substeps` for the other models) overstates the rate
by up to the record's top speed over the speed where the gap is large. Here the model runs along
the record instead: its state follows the smoothed velocity of the data (exact steps at the
sample's velocity, ``FrictionModel.advance``; ``reverse`` where the velocity changes sign), and
each sample's Jacobian of the normalised oscillator and state,

    v~' = u~ - F~(z, v~),   z' = r(z, v~),

gives the local oscillation ``omega^2 = (dF~/dz)(dr/dv~)`` (the tangent stiffness ``dF~/dx~``;
``w^gamma`` for Dahl) and the local decay ``lambda = max(|dF~/dv~|, |eig(dr/dz)|)``.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.models.dahl import Dahl
from prefriction.models.parallel import Parallel

__all__ = ["follows_data", "rates_along"]


def follows_data(model: FrictionModel) -> bool:
    """Whether :func:`rates_along` sets the sub-steps of ``model``: a Dahl term with ``gamma > 1``
    (alone or in a sum), no in-branch events and an exact step for every term."""
    parts = model.models if isinstance(model, Parallel) else (model,)
    if model.n_events > 0 or not any(isinstance(p, Dahl) and p.gamma > 1.0 for p in parts):
        return False
    z, m = model.initial_state(0.0, 1.0)
    q = [float(c) for c in model.runtime_params()]
    return model.advance(z, m, 0.0, 0.0, 1.0, q) is not None


def rates_along(model: FrictionModel, t: np.ndarray, v: np.ndarray, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """Local oscillation ``omega`` and decay ``lambda`` (normalised, per time unit
    ``sqrt(mass / sigma)``) of ``model`` at every sample of a record.

    Parameters
    ----------
    model : FrictionModel
        A model for which :func:`follows_data` holds.
    t : numpy.ndarray
        Sample times [s].
    v : numpy.ndarray
        Smoothed velocity at the samples [m/s].
    mass : float
        Moving mass [kg].

    Returns
    -------
    omega, lam : numpy.ndarray
        ``sqrt(max(0, dF~/dz dr/dv~))`` and ``max(|dF~/dv~|, |eig(dr/dz)|)`` per sample.
    """
    from prefriction.units import Scales

    T = math.sqrt(mass / model.sigma)
    V = model.Fc / math.sqrt(mass * model.sigma)
    sc = Scales(x=model.Fc / model.sigma, F=model.Fc, t=T, v=V, E=model.Fc**2 / model.sigma)
    q = [float(c) for c in model.runtime_params_for(sc)]
    vn, dtn = np.asarray(v, float) / V, np.diff(np.asarray(t, float)) / T
    n, nz = vn.size, model.n_states
    s = 1.0 if vn[np.flatnonzero(vn)[0]] > 0 else -1.0 if np.any(vn) else 1.0
    z, m = model.initial_state(0.0, s)
    Z, S = np.empty((nz, n)), np.empty(n)
    for i in range(n):
        if vn[i] != 0.0 and math.copysign(1.0, vn[i]) != s:
            s = -s
            z, m = model.reverse(z, m, s, q, 0.0)
        Z[:, i], S[i] = z, s
        if i < n - 1:
            z, m = model.advance(z, m, float(vn[i]), float(dtn[i]), s, q)
    zs, vs, ss = ca.SX.sym("z", nz), ca.SX.sym("v"), ca.SX.sym("s")
    zl = [zs[k] for k in range(nz)]
    F = model.force(zl, list(m), vs, ss, q)
    r = ca.vertcat(*model.rate(zl, list(m), vs, ss, q))
    fn = ca.Function("rates_along", [zs, vs, ss], [ca.jacobian(F, zs), ca.jacobian(F, vs), ca.jacobian(r, vs),
                                          ca.jacobian(r, zs)]).map(n)
    dFdz, dFdv, drdv, drdz = (np.asarray(a) for a in fn(Z, vn[None, :], S[None, :]))
    omega2 = np.einsum("ki,ki->i", dFdz.reshape(n, nz).T, drdv.reshape(nz, n))
    D = drdz.reshape(nz, n, nz).transpose(1, 0, 2)
    decay = np.max(np.abs(np.linalg.eigvals(D)), axis=1)
    return np.sqrt(np.maximum(omega2, 0.0)), np.maximum(np.abs(dFdv.ravel()), decay)
