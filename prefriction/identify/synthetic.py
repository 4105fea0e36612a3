"""Synthetic measurements from references independent of the fitter.

- :func:`dahl_loops`: the Dahl force along a prescribed displacement, piecewise linear between
  samples, from the closed-form branches of (3.2) (:func:`prefriction.analysis.branch.force_after_distance`,
  any ``gamma``; (3.4) for ``gamma = 1``).
- :func:`dahl_free_decay`: the unforced oscillator (2.1): reversal times, positions and forces
  from :func:`prefriction.exact_reversals`, the samples in between from scipy's ``solve_ivp``
  (DOP853, ``rtol = 1e-12``) started at each exact reversal.
- :func:`maxwell_slip_loops`: the Maxwell-slip force along a piecewise-linear displacement, each
  element's force by the closed-form stop operator ``z_i <- clip(z_i + k_i dx, -W_i, W_i)``.
- :func:`lugre_loops`: the LuGre force along a smooth prescribed motion with known velocity
  reversals, from scipy's ``solve_ivp`` (Radau, ``rtol = 1e-9``) restarted at each reversal,
  where ``|v|`` has its kink.
- :func:`lugre_free_decay`: the unforced oscillator (2.1) with LuGre friction, from Radau with
  the velocity reversals located as terminal events and the integration restarted there.

Gaussian noise of a given standard deviation is added to the measured signal.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from scipy.integrate import solve_ivp

from prefriction.analysis.branch import force_after_distance
from prefriction.analysis.exact import exact_reversals
from prefriction.errors import SolverError
from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.models.dahl import Dahl
from prefriction.models.lugre import LuGre
from prefriction.models.maxwell_slip import MaxwellSlip
from prefriction.models.oscillator import Oscillator

__all__ = ["dahl_free_decay", "dahl_loops", "dahl_loop_force", "lugre_force", "lugre_free_decay", "lugre_loops",
           "maxwell_slip_force", "maxwell_slip_loops"]


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


def maxwell_slip_force(model: MaxwellSlip, x: np.ndarray) -> np.ndarray:
    """Maxwell-slip force [N] along the displacement samples ``x`` [m] (linear in between), from rest.

    Each element is a stop operator: along a monotone piece ``dx`` its force is
    ``clip(z_i + k_i dx, -W_i, W_i)``, exact for a piecewise-linear displacement (Iwan 1966).

    Parameters
    ----------
    model : MaxwellSlip
        The true model.
    x : numpy.ndarray
        Displacement samples [m], the first one with every element unloaded.
    """
    k, W = np.asarray(model.stiffness, dtype=float), np.asarray(model.slip_force, dtype=float)
    z = np.zeros(k.size)
    F = np.zeros(len(x))
    for i, dx in enumerate(np.diff(np.asarray(x, dtype=float)), start=1):
        z = np.clip(z + k * dx, -W, W)
        F[i] = z.sum()
    return F


def maxwell_slip_loops(model: MaxwellSlip, t: Any, x: Any, noise: float, rng: np.random.Generator) -> ForceDisplacement:
    """Force-displacement data of a Maxwell-slip ``model`` along ``x(t)`` with Gaussian force noise.

    Parameters
    ----------
    model : MaxwellSlip
        The true model.
    t, x : array_like
        Sample times [s] and prescribed displacement [m] (the elements unloaded at ``x[0]``).
    noise : float
        Standard deviation of the force noise [N].
    rng : numpy.random.Generator
        Source of the noise.

    Returns
    -------
    ForceDisplacement
    """
    x = np.asarray(x, dtype=float)
    F = maxwell_slip_force(model, x)
    return ForceDisplacement(t, x, F + noise * rng.standard_normal(F.size))


def lugre_force(model: LuGre, t: np.ndarray, velocity: Callable[[float], float], reversals: Any,
                rtol: float = 1e-9) -> np.ndarray:
    """LuGre force [N] at the times ``t`` [s] of a prescribed motion with velocity ``velocity(t)``.

    Integrates the bristle deflection ``z' = v - sigma0 |v| z / g(v)`` (Canudas de Wit et al.
    1995, (1)-(3)) from ``z = 0`` at ``t[0]`` with scipy's Radau, restarted at every velocity
    reversal (the kink of ``|v|``), and returns ``F = sigma0 z + sigma1 z' + sigma2 v``.

    Parameters
    ----------
    model : LuGre
        The true model.
    t : numpy.ndarray
        Sample times [s], increasing.
    velocity : callable
        ``v(t)`` [m/s] of the prescribed motion, vectorised over numpy arrays.
    reversals : array_like
        The times [s] where ``v`` changes sign (those outside ``t`` are ignored).
    rtol : float, default 1e-9
        Relative tolerance of Radau (absolute: ``1e-12 Fc / sigma0``). On the loops of
        ``examples/fit_lugre.py`` the force at ``1e-9`` is within ``2e-10 Fc`` of ``rtol = 1e-11``.
    """
    t = np.asarray(t, dtype=float)
    m = model

    def g(v: Any) -> Any:
        return m.Fc + (m.Fs - m.Fc) * np.exp(-(v / m.vs) ** 2)

    def rhs(tt: float, z: np.ndarray) -> list[float]:
        v = float(velocity(tt))
        return [v - m.sigma0 * abs(v) * z[0] / g(v)]

    rev = np.sort(np.asarray(reversals, dtype=float))
    edges = np.r_[t[0], rev[(rev > t[0]) & (rev < t[-1])], t[-1]]
    z = np.empty_like(t)
    z0 = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (t >= a) & (t <= b)
        sol = solve_ivp(rhs, (a, b), [z0], method="Radau", rtol=rtol, atol=1e-12 * m.Fc / m.sigma0, t_eval=t[sel],
                        dense_output=True)
        if not sol.success:
            raise SolverError(f"Radau failed between t = {a!r} s and {b!r} s from z = {z0!r} m ({sol.message}); "
                              f"try a looser rtol than {rtol!r} or a smoother velocity")
        z[sel] = sol.y[0]
        z0 = float(sol.sol(b)[0])
    v = np.asarray(velocity(t), dtype=float)
    dz = v - m.sigma0 * np.abs(v) * z / g(v)
    return m.sigma0 * z + m.sigma1 * dz + m.sigma2 * v


def lugre_loops(model: LuGre, t: Any, position: Callable[[Any], Any], velocity: Callable[[Any], Any],
                reversals: Any, noise: float, rng: np.random.Generator) -> ForceDisplacement:
    """Force-displacement data of a LuGre ``model`` along a smooth prescribed motion, with noise.

    Parameters
    ----------
    model : LuGre
        The true model.
    t : array_like
        Sample times [s].
    position, velocity : callable
        ``x(t)`` [m] and ``v(t) = x'(t)`` [m/s] of the prescribed motion (vectorised).
    reversals : array_like
        The times [s] where ``v`` changes sign.
    noise : float
        Standard deviation of the force noise [N].
    rng : numpy.random.Generator
        Source of the noise.

    Returns
    -------
    ForceDisplacement
        The positions at ``t`` and the force of :func:`lugre_force` plus noise.
    """
    t = np.asarray(t, dtype=float)
    F = lugre_force(model, t, velocity, reversals)
    return ForceDisplacement(t, position(t), F + noise * rng.standard_normal(F.size))


def lugre_free_decay(model: LuGre, mass: float, v0: float, t: Any, noise: float, rng: np.random.Generator,
                     rtol: float = 1e-9) -> tuple[Motion, np.ndarray]:
    """Free-decay positions of the oscillator (2.1) with LuGre friction, from ``x = z = 0`` and ``v0``.

    ``m x'' = -F``, ``F = sigma0 z + sigma1 z' + sigma2 v``, ``z' = v - sigma0 |v| z / g(v)``
    (Canudas de Wit et al. 1995), integrated by scipy's Radau. Each velocity reversal is a
    terminal event (``v`` crossing zero against the current direction), where the integration
    restarts, so no step straddles the kink of ``|v|``.

    Parameters
    ----------
    model : LuGre
        The true model.
    mass : float
        Mass [kg].
    v0 : float
        Initial velocity [m/s], non-zero.
    t : array_like
        Sample times [s], from 0.
    noise : float
        Standard deviation of the position noise [m].
    rng : numpy.random.Generator
        Source of the noise.
    rtol : float, default 1e-9
        Relative tolerance of Radau.

    Returns
    -------
    (Motion, numpy.ndarray)
        The data (``u = 0``, the known ``mass``) and the reversal times [s] inside the record.
    """
    t = np.asarray(t, dtype=float)
    m = model

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        v, z = y[1], y[2]
        g = m.Fc + (m.Fs - m.Fc) * np.exp(-(v / m.vs) ** 2)
        dz = v - m.sigma0 * abs(v) * z / g
        return [v, -(m.sigma0 * z + m.sigma1 * dz + m.sigma2 * v) / mass, dz]

    x = np.empty_like(t)
    y0, t0, s = [0.0, float(v0), 0.0], float(t[0]), float(np.sign(v0))
    reversals: list[float] = []
    while True:
        def reversal(_t: float, y: np.ndarray) -> float:
            return y[1]
        reversal.terminal = True  # type: ignore[attr-defined]
        reversal.direction = -s   # type: ignore[attr-defined]
        sol = solve_ivp(rhs, (t0, float(t[-1])), y0, method="Radau", rtol=rtol, atol=1e-12 * m.Fc / m.sigma0,
                        events=reversal, dense_output=True)
        if not sol.success or (sol.status == 1 and not sol.t[-1] > t0):
            raise SolverError(f"Radau stopped at t = {sol.t[-1]!r} s, state {sol.y[:, -1]!r} ({sol.message}); "
                              f"try a looser rtol than {rtol!r}")
        sel = (t >= t0) & (t <= sol.t[-1])
        if np.any(sel):
            x[sel] = sol.sol(t[sel])[0]
        if sol.status != 1:
            break
        t0, s = float(sol.t[-1]), -s
        y0 = [float(sol.y[0, -1]), 0.0, float(sol.y[2, -1])]
        reversals.append(t0)
    return Motion(t, x + noise * rng.standard_normal(t.size), 0.0, mass), np.array(reversals)
