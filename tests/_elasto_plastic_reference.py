"""Independent scipy integration of the elasto-plastic model of Dupont et al. (2002), in SI units.

Written from the paper's equations (7)-(9), not from ``prefriction/models/elasto_plastic.py``::

    z' = v - alpha(z, v) sigma0 |v| z / f_ss(v),   f_ss(v) = Fc + (Fs - Fc) exp(-(v / vs)^2),
    F  = sigma0 z + sigma1 z' + sigma2 v,
    alpha = 0 if sign(z) != sign(v) or |z| <= z_ba; 1 if |z| >= z_ss(v) = f_ss(v) / sigma0;
            (1 + sin(pi (|z| - (z_ss + z_ba) / 2) / (z_ss - z_ba))) / 2 in between.

``solve_ivp`` (DOP853, rtol 1e-12) restarts at every velocity reversal, every breakaway crossing
``|z| = z_ba`` and the first crossing of ``|z| = z_ss(v)`` on a branch. Before breakaway on a
branch ``alpha = 0``; after it ``alpha`` is evaluated from its definition above.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Optional

import numpy as np
from scipy.integrate import solve_ivp

ELASTIC, TRANSITION, SATURATED = 0, 1, 2


def f_ss(p: Any, v: float) -> float:
    return p.Fc + (p.Fs - p.Fc) * math.exp(-(v / p.vs) ** 2)


def alpha(p: Any, z: float, v: float) -> float:
    """The 2002 ``alpha(z, v)`` from its definition."""
    zss = f_ss(p, v) / p.sigma0
    if math.copysign(1.0, z) != math.copysign(1.0, v) or abs(z) <= p.z_ba:
        return 0.0
    if abs(z) >= zss:
        return 1.0
    return 0.5 + 0.5 * math.sin(math.pi * (abs(z) - 0.5 * (zss + p.z_ba)) / (zss - p.z_ba))


def zdot(p: Any, region: int, z: float, v: float) -> float:
    """The 2002 state equation; ``alpha = 0`` before breakaway on the branch (``region`` elastic)."""
    a = 0.0 if region == ELASTIC else alpha(p, z, v)
    return v - a * p.sigma0 * abs(v) * z / f_ss(p, v)


def force(p: Any, region: int, z: float, v: float) -> float:
    return p.sigma0 * z + p.sigma1 * zdot(p, region, z, v) + p.sigma2 * v


def region_at_rest(p: Any, z: float, s: float) -> int:
    """Region at the start of a branch of direction ``s`` (``v = 0``)."""
    w = s * z
    if w <= p.z_ba:
        return ELASTIC
    return SATURATED if w >= f_ss(p, 0.0) / p.sigma0 else TRANSITION


def _crossing_events(p: Any, region: int, s: float, col_z: int, col_v: int) -> list[Callable]:
    """Terminal events: the breakaway crossing (elastic) and the saturation crossing (either way)."""
    def breakaway(_t: float, y: np.ndarray) -> float:
        return s * y[col_z] - p.z_ba if region == ELASTIC else -1.0

    def saturation(_t: float, y: np.ndarray) -> float:
        return s * y[col_z] - f_ss(p, y[col_v]) / p.sigma0 if region == TRANSITION else -1.0

    for ev in (breakaway, saturation):
        ev.terminal, ev.direction = True, 1.0
    return [breakaway, saturation]


def _next_region(region: int, which: int) -> int:
    return TRANSITION if which == 0 else SATURATED


def oscillator(p: Any, mass: float, v0: float, *, u: Optional[Callable[[float], float]] = None, t_end: float,
               times: np.ndarray = np.zeros(0), rtol: float = 1e-12, dissipation: bool = False) -> dict:
    """``m x'' = u(t) - F`` from ``x = 0``, ``z = 0``, speed ``v0`` up to ``t_end``.

    Returns the reversal rows ``(t, x, F)`` (F after the reversal, at ``v = 0``), the number of
    breakaway and first saturation crossings, and ``(x, v, F)`` at ``times``. With
    ``dissipation``, the rows carry a fourth column: the energy dissipated since ``t = 0``,
    integrated as a state from the power ``sigma0 z (v - z') + (sigma1 z' + sigma2 v) v`` (the
    friction power ``F v`` less the rate of the stored energy ``sigma0 z^2 / 2``).
    """
    uf = u or (lambda t: 0.0)
    s = 1.0 if v0 > 0 else -1.0
    y = np.array([0.0, v0, 0.0, 0.0] if dissipation else [0.0, v0, 0.0])
    t, region, rows, n_cross = 0.0, ELASTIC, [], [0, 0]
    zs, vs = p.Fc / p.sigma0, p.Fc / math.sqrt(mass * p.sigma0)  # the sizes of x and z, of v
    atol = 1e-3 * rtol * np.array([zs, max(vs, abs(v0)), zs, p.sigma0 * zs * zs][:y.size])
    dense_t, dense_y, dense_r = [], [], []
    while t < t_end:
        def rhs(tt: float, yy: np.ndarray, region: int = region) -> np.ndarray:
            F, zd = force(p, region, yy[2], yy[1]), zdot(p, region, yy[2], yy[1])
            power = p.sigma0 * yy[2] * (yy[1] - zd) + (p.sigma1 * zd + p.sigma2 * yy[1]) * yy[1]
            return np.array([yy[1], (uf(tt) - F) / mass, zd, power][:yy.size])

        def reversal(_t: float, yy: np.ndarray, s: float = s) -> float:
            return s * yy[1]

        reversal.terminal, reversal.direction = True, -1.0
        evs = [reversal, *_crossing_events(p, region, s, 2, 1)]
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=evs, dense_output=True)
        t1 = sol.t[-1]
        inside = times[(times >= t) & (times < t1 if sol.status == 1 else times <= t1)]
        if inside.size:
            dense_t.append(inside)
            dense_y.append(sol.sol(inside).T)
            dense_r += [region] * inside.size
        if sol.status != 1:
            break
        which = min((float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te))[1]
        t, y = t1, sol.y_events[which][0].copy()
        if which == 0:
            s, y[1] = -s, 0.0
            region = region_at_rest(p, y[2], s)
            rows.append((t, y[0], force(p, region, y[2], 0.0), *y[3:]))
        else:
            n_cross[which - 1] += 1
            region = _next_region(region, which - 1)
    out = {"reversals": np.array(rows).reshape(-1, y.size), "breakaways": n_cross[0], "saturations": n_cross[1]}
    if dense_t:
        tt, yy = np.concatenate(dense_t), np.vstack(dense_y)
        out["dense"] = np.column_stack([yy[:, 0], yy[:, 1], [force(p, r, z, v) for r, z, v in
                                                             zip(dense_r, yy[:, 2], yy[:, 1])]])
        out["dense_t"] = tt
    return out


def along(p: Any, t: np.ndarray, x: np.ndarray, rtol: float = 1e-12) -> np.ndarray:
    """Friction force [N] at the samples of the piecewise-linear motion ``x(t)`` (each sample's
    rate term at the velocity of the interval that ends there, of the first interval at ``t[0]``)."""
    v_int = np.diff(x) / np.diff(t)
    s = 1.0 if v_int[0] >= 0 else -1.0
    z, region = 0.0, ELASTIC
    F = [force(p, region, z, v_int[0])]
    for i, v in enumerate(v_int):
        if v != 0.0 and math.copysign(1.0, v) != s:
            s = -s
            region = region_at_rest(p, z, s)
        t0, t1 = t[i], t[i + 1]
        if region == TRANSITION and s * z >= f_ss(p, v) / p.sigma0:  # saturated at this interval's speed
            region = SATURATED
        while True:
            sol = solve_ivp(lambda _t, yy, region=region, v=v: [zdot(p, region, yy[0], v)], (t0, t1), [z],
                            method="DOP853", rtol=rtol, atol=1e-3 * rtol * p.Fc / p.sigma0, events=_along_events(p, region, s, v))
            z = float(sol.y[0, -1])
            if sol.status != 1:
                break
            which = min((float(te[0]), k) for k, te in enumerate(sol.t_events) if len(te))[1]
            t0, z = float(sol.t[-1]), float(sol.y_events[which][0][0])
            region = _next_region(region, which)
        F.append(force(p, region, z, v))
    return np.array(F)


def _along_events(p: Any, region: int, s: float, v: float) -> list[Callable]:
    """The crossing events for a state ``[z]`` at the constant velocity ``v``."""
    zss = f_ss(p, v) / p.sigma0

    def breakaway(_t: float, y: np.ndarray) -> float:
        return s * y[0] - p.z_ba if region == ELASTIC else -1.0

    def saturation(_t: float, y: np.ndarray) -> float:
        return s * y[0] - zss if region == TRANSITION else -1.0

    for ev in (breakaway, saturation):
        ev.terminal, ev.direction = True, 1.0
    return [breakaway, saturation]
