"""Stored energy of a one-state rate-dependent model at the reversals of a sampled trajectory.

For a model with one internal state whose branch unloads elastically after a reversal (the
elasto-plastic model of Dupont et al. 2002: ``alpha = 0`` while ``sign(z) != sign(v)``), the
energy stored at a reversal is the branch energy of the force there,
:meth:`prefriction.FrictionModel.branch_energy_of_force` (the base class's quadrature
``-int F dx`` back to the force zero; ``sigma0 z^2 / 2`` for the elasto-plastic model, since
``F = sigma0 z`` at ``v = 0``). The dissipation per half-cycle then follows from the balance
(2.10) as for the rate-independent models (``docs/mathematics.md#lugre-energy`` derives the
split of the same balance for a bristle model).

The force at a reversal is extrapolated in time along the incoming branch, quadratically from
the three samples before it: near ``v = 0`` the rate terms ``sigma1 z' + sigma2 v`` vary like
``v``, which is smooth in time but not in the position (``v ~ sqrt`` of the distance to the
turning point), so the extrapolation in ``x`` that serves the rate-independent models does not
apply.
"""

from __future__ import annotations

import numpy as np

from prefriction.analysis.energy.sampled_reversals import SampledReversals
from prefriction.models.base import FrictionModel
from prefriction.units import Scales

__all__ = ["initial_stored_energy", "reversal_forces", "stored_energy"]


def reversal_forces(t: np.ndarray, F: np.ndarray, rev: SampledReversals) -> np.ndarray:
    """The friction force [N] at each reversal of ``rev``: the sample on it if there is one, else
    the quadratic through the three samples before it on the incoming branch, evaluated at the
    reversal time (the line through two samples where the branch holds only two, the sampled
    reversals' own estimate where it holds one)."""
    out = np.array(rev.F, dtype=float)
    starts = np.concatenate(([0], rev.index[:-1] + 1))  # first sample of each incoming branch
    for k, (a, tr) in enumerate(zip(rev.index.tolist(), rev.t.tolist())):
        if t[a + 1] == tr or t[a] == tr:  # a sample on the reversal (v = 0 there)
            out[k] = F[a + 1] if t[a + 1] == tr else F[a]
            continue
        lo = max(int(starts[k]), a - 2)
        ts, Fs = t[lo:a + 1], F[lo:a + 1]
        if ts.size >= 2:
            out[k] = float(np.polyval(np.polyfit(ts - tr, Fs, ts.size - 1), 0.0))
    return out


def stored_energy(F: np.ndarray, direction: np.ndarray, *, friction: FrictionModel) -> np.ndarray:
    """Energy [J] stored at rest on a branch of ``direction`` with the friction force ``F`` [N]:
    ``(Fc^2 / sigma) E~(F / Fc)`` with ``E~`` the model's
    :meth:`~prefriction.FrictionModel.branch_energy_of_force`."""
    E = (friction.Fc ** 2 / friction.sigma) * friction.branch_energy_of_force(np.asarray(F) / friction.Fc, direction)
    return np.asarray(E, dtype=float)


def initial_stored_energy(F0: float, v0: float, s0: int, *, friction: FrictionModel, scales: Scales) -> float:
    """Stored energy [J] of the state whose friction force at the velocity ``v0`` [m/s] is ``F0``
    [N] on a branch of direction ``s0``: the model's :meth:`~prefriction.FrictionModel.initial_state`
    of the rest force ``f`` for which the force at ``v0`` is ``F0`` (``f = F0`` at rest).

    While the bristle slides, the force at a given speed need not grow with the deflection (the
    elasto-plastic ``alpha`` rises from 0 to 1 past breakaway), so several states can have the
    force ``F0``; the one of least deflection is taken (that of a run started at the rest force
    0, as :func:`prefriction.simulate` starts by default). The roots are bracketed on 256
    intervals of ``|f|`` up to the model's largest hysteretic force and refined by ``brentq``;
    ``ValueError`` if there is none.
    """
    from scipy.optimize import brentq

    f_max = friction.max_hysteretic_force / friction.Fc
    target = F0 / friction.Fc
    if v0 != 0.0:
        q = friction.runtime_params_for(scales).tolist()
        vn = v0 / scales.v

        def gap(f: float) -> float:
            z, m = friction.initial_state(f, s0)
            return float(friction.force(z, m, vn, s0, q)) - target

        grid = np.linspace(-f_max, f_max, 257)
        g = np.array([gap(f) for f in grid.tolist()])
        roots = grid[g == 0.0].tolist()
        for k in np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0).tolist():
            roots.append(brentq(gap, grid[k], grid[k + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))
        if not roots:
            raise ValueError(
                f"no state of {type(friction).__name__} has the friction force F[0] = {F0!r} N at the velocity "
                f"v[0] = {v0!r} m/s: F[0] must be the model's force at t[0] with that velocity")
        target = min(roots, key=abs)
    return float(stored_energy(np.array([target * friction.Fc]), np.array([float(s0)]), friction=friction)[0])
