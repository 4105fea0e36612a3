"""Synthetic closed-loop records like the EMPS benchmark, from scipy, independent of the fitter.

A stage of mass ``m`` moved by a digital PD loop at ``1 / dt``: at each sample ``k`` the loop
reads the encoder (the position rounded to steps of ``quantum``), computes
``u_k = Kp (r_k - x_k) - Kd sum_j c_j (x_{k-j} - x_{k-j-1}) / dt`` [N] (velocity filter taps
``c``, default one: the backward difference) and applies ``u_{k-d}`` (``d`` samples of delay,
default 0) until the next sample; the stage obeys ``m x'' + F + F_off = u`` (2.1) with the
friction ``F`` of a LuGre model (Canudas de Wit et al. 1995, (1)-(3)) or a Dahl model (3.2) with
a viscous term ``b v`` (``b_neg v`` for ``v < 0`` if given). scipy's
``solve_ivp`` (LSODA, ``rtol = 1e-10``) integrates each sample interval separately (``u`` jumps
at the samples) and restarts at every velocity reversal inside it (a terminal event; ``|v|`` has
its kink there). The reference is a series of point-to-point moves with cosine velocity
profiles and rests, over about 0.2 m, like the EMPS excitation (Janot, Gautier and Brunot,
*Data set and reference models of EMPS*, 2019).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from prefriction.errors import SolverError
from prefriction.identify.data import Motion
from prefriction.models.base import FrictionModel
from prefriction.models.dahl import Dahl
from prefriction.models.lugre import LuGre

__all__ = ["ClosedLoop", "closed_loop_record", "reference_moves", "replay"]


@dataclass(frozen=True)
class ClosedLoop:
    """The stage and loop of :func:`closed_loop_record`.

    Attributes
    ----------
    friction : LuGre or Dahl
        The friction model (Dahl with any ``gamma``; for ``gamma < 1`` the gap ``1 - s F / Fc``
        reaches 0 at a finite travel and the force stays at ``s Fc`` until the reversal: the rate
        ``sigma v max(gap, 0)^gamma`` is integrated as it stands, the saturation not located as
        an event, so the force there is exact to the integrator's tolerance).
    mass : float
        Moving mass [kg].
    b : float
        Viscous coefficient [N s/m] added to a Dahl model (LuGre has its own ``sigma2``).
    offset : float
        Force offset [N]: ``m x'' + F + offset = u``.
    Kp, Kd : float
        Proportional [N/m] and derivative [N s/m] gains of the PD loop.
    quantum : float
        Encoder step [m].
    dt : float
        Sample interval [s].
    noise : float
        Standard deviation [m] of Gaussian noise added to the position before the encoder
        rounds it (0: rounding only).
    taps : tuple of float
        Velocity filter of the loop (EMPS: ``(0.5, 0.5)``).
    delay : int
        Samples between computing a force and applying it.
    b_neg : float or None
        Viscous coefficient [N s/m] of a Dahl stage for ``v < 0`` (``None``: ``b``).
    """

    friction: FrictionModel
    mass: float = 95.0
    b: float = 0.0
    offset: float = -3.16
    Kp: float = 2.0e5
    Kd: float = 2.0e3
    quantum: float = 5e-8
    dt: float = 1e-3
    noise: float = 0.0
    taps: tuple = (1.0,)
    delay: int = 0
    b_neg: float | None = None


def reference_moves(n: int, dt: float, rng: np.random.Generator, stroke: float = 0.2) -> np.ndarray:
    """Reference positions [m] at ``n`` samples: moves between random points of ``[0, stroke]``
    with cosine velocity profiles (0.25 to 0.8 s) and rests (0.05 to 0.3 s), from ``stroke / 2``."""
    r = np.empty(n)
    k, pos = 0, stroke / 2
    while k < n:
        rest = int(rng.uniform(0.05, 0.3) / dt)
        r[k:k + rest] = pos
        k += rest
        target = rng.uniform(0.0, stroke)
        steps = max(int(rng.uniform(0.25, 0.8) / dt), 2)
        s = np.arange(1, steps + 1) / steps
        r[k:k + steps] = (pos + (target - pos) * 0.5 * (1.0 - np.cos(np.pi * s)))[: max(0, min(steps, n - k))]
        k += steps
        pos = target
    return r


def _rhs(loop: ClosedLoop):
    m, f = loop.mass, loop.friction
    if isinstance(f, LuGre):
        def rhs(_t: float, y: np.ndarray, u: float) -> list[float]:
            v, z = y[1], y[2]
            g = f.Fc + (f.Fs - f.Fc) * np.exp(-(v / f.vs) ** 2)
            dz = v - f.sigma0 * abs(v) * z / g
            F = f.sigma0 * z + f.sigma1 * dz + f.sigma2 * v
            return [v, (u - F - loop.offset) / m, dz]
        return rhs
    if isinstance(f, Dahl):  # gamma < 1: the gap reaches 0 (saturation) and the rate stays 0 there
        b_neg = loop.b if loop.b_neg is None else loop.b_neg

        def rhs(_t: float, y: np.ndarray, u: float) -> list[float]:
            v, F = y[1], y[2]
            gap = max(1.0 - np.sign(v) * F / f.Fc, 0.0)
            b = loop.b if v > 0.0 else b_neg
            return [v, (u - F - b * v - loop.offset) / m, f.sigma * v * gap ** f.gamma]
        return rhs
    raise TypeError(f"friction must be a LuGre or a Dahl model, got {f!r}")


def closed_loop_record(loop: ClosedLoop, n: int, rng: np.random.Generator, *, rtol: float = 1e-10) -> Motion:
    """``n`` samples of the PD loop following :func:`reference_moves`, as :class:`Motion` data.

    Parameters
    ----------
    loop : ClosedLoop
        Stage, friction and loop.
    n : int
        Number of samples (``t = k dt``).
    rng : numpy.random.Generator
        Source of the reference moves and the position noise.
    rtol : float, default 1e-10
        Relative tolerance of LSODA (absolute ``1e-14`` m, m/s and the state's unit).

    Returns
    -------
    Motion
        Encoder positions, the computed motor force ``u`` (``hold="zoh"``; applied ``loop.delay``
        samples later) and the known mass.
    """
    rhs = _rhs(loop)
    dt = loop.dt
    r = reference_moves(n, dt, rng)
    x = np.empty(n)
    u = np.empty(n)
    y = np.array([r[0], 0.0, 0.0])
    taps = len(loop.taps)
    past = [np.round(r[0] / loop.quantum) * loop.quantum] * taps   # x_{k-1}, ..., x_{k-taps}
    e = loop.noise * rng.standard_normal(n)
    for k in range(n):
        xq = np.round((y[0] + e[k]) / loop.quantum) * loop.quantum
        x[k] = xq
        xs = [xq] + past
        u[k] = loop.Kp * (r[k] - xq) - loop.Kd * sum(c * (xs[j] - xs[j + 1]) for j, c in enumerate(loop.taps)) / dt
        past = xs[:taps]
        if k < n - 1:
            applied = u[k - loop.delay] if k >= loop.delay else 0.0
            y = _interval(rhs, y, k * dt, (k + 1) * dt, applied, rtol)
    return Motion(np.arange(n) * dt, x, u, loop.mass, hold="zoh")


def _interval(rhs, y: np.ndarray, t0: float, t1: float, u: float, rtol: float) -> np.ndarray:
    """The state at ``t1`` from ``y`` at ``t0`` under the held force ``u``, restarted at reversals
    (an exact equilibrium, every derivative zero, stays put)."""
    if not np.any(rhs(t0, y, u)):
        return y.copy()
    for _ in range(100):
        s = np.sign(y[1]) or np.sign(rhs(t0, y, u)[1]) or 1.0

        def reversal(_t: float, yy: np.ndarray, _u: float) -> float:
            return yy[1]
        reversal.terminal = True  # type: ignore[attr-defined]
        reversal.direction = -s  # type: ignore[attr-defined]
        sol = solve_ivp(rhs, (t0, t1), y, method="LSODA", rtol=rtol, atol=1e-14, args=(u,), events=reversal)
        if not sol.success:
            raise SolverError(f"LSODA failed between t = {t0!r} s and {t1!r} s ({sol.message}); try a looser rtol")
        y = sol.y[:, -1].copy()
        if sol.status != 1:
            return y
        t0 = float(sol.t[-1])
        y[1] = 0.0
        if t0 >= t1:
            return y
    raise SolverError(f"more than 100 velocity reversals between t = {t0!r} s and {t1!r} s (a chattering loop)")


def replay(loop: ClosedLoop, t: np.ndarray, u: np.ndarray, x0: float, v0: float, F0: float,
           rtol: float = 1e-10) -> np.ndarray:
    """Positions [m] of the stage of ``loop`` driven by the held force ``u`` (open loop).

    The same equations and integration as :func:`closed_loop_record` (LSODA per sample
    interval, restarted at reversals), from position ``x0`` [m], velocity ``v0`` [m/s] and
    friction state ``F0``: the bristle deflection ``z = F0 / sigma0`` [m] for LuGre, the force
    [N] for Dahl.

    Parameters
    ----------
    loop : ClosedLoop
        Stage and friction (the gains are not used).
    t, u : numpy.ndarray
        Sample times [s] and the force [N] held from each sample to the next.
    x0, v0, F0 : float
        Initial position [m], velocity [m/s] and friction state.
    rtol : float, default 1e-10
        Relative tolerance of LSODA.
    """
    rhs = _rhs(loop)
    z0 = F0 / loop.friction.sigma0 if isinstance(loop.friction, LuGre) else F0
    y = np.array([x0, v0, z0], dtype=float)
    x = np.empty(len(t))
    x[0] = x0
    for k in range(len(t) - 1):
        y = _interval(rhs, y, float(t[k]), float(t[k + 1]), float(u[k]), rtol)
        x[k + 1] = y[0]
    return x
