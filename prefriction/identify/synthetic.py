"""Synthetic measurements of the Dahl model from references independent of the fitter.

- :func:`dahl_loops`: the force along a prescribed displacement, piecewise linear between
  samples, from the closed-form branches of (3.2) (:func:`prefriction.analysis.branch.force_after_distance`,
  any ``gamma``; (3.4) for ``gamma = 1``).
- :func:`dahl_free_decay`: the unforced oscillator (2.1): reversal times, positions and forces
  from :func:`prefriction.exact_reversals`, the samples in between from scipy's ``solve_ivp``
  (DOP853, ``rtol = 1e-12``) started at each exact reversal.

Gaussian noise of a given standard deviation is added to the measured signal.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from prefriction.analysis.branch import force_after_distance
from prefriction.analysis.exact import exact_reversals
from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.models.dahl import Dahl
from prefriction.models.oscillator import Oscillator

__all__ = ["dahl_free_decay", "dahl_loops", "dahl_loop_force"]


def dahl_loop_force(model: Dahl, x: np.ndarray) -> np.ndarray:
    """Dahl force [N] along the displacement samples ``x`` [m] (linear in between), from zero force.

    Parameters
    ----------
    model : Dahl
        The true model.
    x : numpy.ndarray
        Displacement samples [m].
    """
    F = np.zeros(len(x))
    for k in range(1, len(x)):
        dx = float(x[k] - x[k - 1])
        if dx == 0.0:
            F[k] = F[k - 1]
            continue
        s = 1.0 if dx > 0 else -1.0
        f = force_after_distance(np.array([s * F[k - 1] / model.Fc]), np.array([abs(dx) * model.sigma / model.Fc]),
                                 model.gamma)[0]
        F[k] = s * f * model.Fc
    return F


def dahl_loops(model: Dahl, t: Any, x: Any, noise: float, rng: np.random.Generator) -> ForceDisplacement:
    """Force-displacement data of ``model`` along ``x(t)`` with Gaussian force noise.

    Parameters
    ----------
    model : Dahl
        The true model.
    t, x : array_like
        Sample times [s] and prescribed displacement [m].
    noise : float
        Standard deviation of the force noise [N].
    rng : numpy.random.Generator
        Source of the noise.

    Returns
    -------
    ForceDisplacement
    """
    x = np.asarray(x, dtype=float)
    F = dahl_loop_force(model, x)
    return ForceDisplacement(t, x, F + noise * rng.standard_normal(F.size))


def dahl_free_decay(model: Dahl, mass: float, v0: float, t: Any, noise: float, rng: np.random.Generator) -> Motion:
    """Free-decay positions of the Dahl oscillator (2.1) from rest position 0, velocity ``v0``, force 0.

    Parameters
    ----------
    model : Dahl
        The true model.
    mass : float
        Mass [kg].
    v0 : float
        Initial velocity [m/s].
    t : array_like
        Sample times [s], from 0.
    noise : float
        Standard deviation of the position noise [m].
    rng : numpy.random.Generator
        Source of the noise.

    Returns
    -------
    Motion
        With ``u = 0`` and the known ``mass``.
    """
    t = np.asarray(t, dtype=float)
    n_rev = 1
    while True:
        table = exact_reversals(Oscillator(model, mass=mass), v0, n_rev)
        if table.t[-1] > t[-1]:
            break
        n_rev *= 2
    starts = [(0.0, 0.0, v0, 0.0)] + [(float(a), float(b), 0.0, float(c)) for a, b, c in zip(table.t, table.x, table.F)]
    x = np.empty_like(t)
    sig, Fc, g = model.sigma, model.Fc, model.gamma
    for j, (t0, x0, vv0, F0) in enumerate(starts):
        t1 = float(table.t[j]) if j < len(table.t) else np.inf
        sel = (t >= t0) & (t < t1)
        if not np.any(sel):
            continue
        s = (1.0 if v0 > 0 else -1.0) * (-1.0) ** j

        def rhs(_t: float, y: np.ndarray, s: float = s) -> list[float]:
            gap = max(1.0 - s * y[2] / Fc, 0.0)
            return [y[1], -y[2] / mass, sig * y[1] * gap**g]

        sol = solve_ivp(rhs, (t0, float(t[sel][-1])), [x0, vv0, F0], method="DOP853", rtol=1e-12, atol=1e-14 * Fc / sig,
                        t_eval=t[sel], dense_output=False)
        x[sel] = sol.y[0]
    return Motion(t, x + noise * rng.standard_normal(t.size), 0.0, mass)
