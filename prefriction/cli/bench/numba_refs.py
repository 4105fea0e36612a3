"""Numba references of ``prefriction bench --native``: the short integrators a performance-minded user writes.

One ``numba.njit`` function integrates the forced oscillator ``m x'' = u(t) - F`` with a Dahl
(gamma = 1) or LuGre model, written from the equations (``docs/mathematics.md``):

- Dahl: ``F' = sigma v (1 - s F / Fc)``;
- LuGre: ``z' = v - sigma0 |v| z / g(v)``, ``g = Fc + (Fs - Fc) exp(-(v / vs)^2)``,
  ``F = sigma0 z + sigma1 z' + sigma2 v``;

with the Dormand-Prince 5(4) pair of :class:`scipy.integrate.RK45` (its coefficients, its
quartic dense output, its error norm and step control), every velocity reversal located on the
dense output (Illinois regula falsi) and the branch direction ``s`` switched there. Inputs: a
sine, samples linear in between (the steps broken at the sample times, the piece read from
the arrays), or a continuous PID loop around the stage (:data:`PID`: ``u = kp e + ki xi +
kd / tau (e - xf)``, ``xi' = e``, ``xf' = (e - xf) / tau``, ``e = r - x`` with a sine reference
``r``; the controller's states integrated with the stage's). Optional samples at requested
times from the dense output. numba is an optional
extra (the benchmark's peer rows only): :func:`available` says whether it is installed.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

__all__ = ["DAHL", "LUGRE", "PID", "SINE", "SAMPLES", "available", "forced_run", "maxwell_slip_along", "pid_loop"]

DAHL, LUGRE = 0, 1
SINE, SAMPLES = 0, 1
PID = 3  # a continuous PID loop (the kind of forced_run): up = (r amplitude [m], r angular frequency [rad/s], kp, ki, kd / tau, 1 / tau)


def available() -> bool:
    """True if numba can be imported."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


@functools.lru_cache(maxsize=1)
def _kernel() -> Any:
    import numba
    from scipy.integrate._ivp.rk import RK45

    C, A, B, E, P = (np.array(a, dtype=float) for a in (RK45.C, RK45.A, RK45.B, RK45.E, RK45.P))

    @numba.njit(cache=False)
    def u_at(t: float, kind: int, up: np.ndarray, ts: np.ndarray, us: np.ndarray, k: int) -> float:
        if kind == 0:
            return up[0] * np.sin(up[1] * t)
        if kind == 2:  # held (a sampled loop's force)
            return up[0]
        if k < 0:
            return us[0]
        if k >= ts.size - 1:
            return us[ts.size - 1]
        return us[k] + (us[k + 1] - us[k]) * (t - ts[k]) / (ts[k + 1] - ts[k])

    @numba.njit(cache=False)
    def rhs(t: float, y: np.ndarray, s: float, model: int, mp: np.ndarray, kind: int, up: np.ndarray,
            ts: np.ndarray, us: np.ndarray, k: int, dy: np.ndarray) -> float:
        v = y[1]
        if kind == 3:  # the continuous PID loop: states y[3] (integral of e), y[4] (filter of e)
            e = up[0] * np.sin(up[1] * t) - y[0]
            u = up[2] * e + up[3] * y[3] + up[4] * (e - y[4])
            dy[3] = e
            dy[4] = (e - y[4]) * up[5]
        else:
            u = u_at(t, kind, up, ts, us, k)
        if model == 0:  # Dahl, gamma = 1: mp = (sigma, Fc, m)
            F = y[2]
            dy[2] = mp[0] * v * (1.0 - s * F / mp[1])
            m = mp[2]
        else:  # LuGre: mp = (sigma0, sigma1, sigma2, Fc, Fs, vs, m)
            g = mp[3] + (mp[4] - mp[3]) * np.exp(-(v / mp[5]) ** 2)
            zd = v - mp[0] * abs(v) * y[2] / g
            F = mp[0] * y[2] + mp[1] * zd + mp[2] * v
            dy[2] = zd
            m = mp[6]
        dy[0] = v
        dy[1] = (u - F) / m
        return F

    @numba.njit(cache=False)
    def dense(y0: np.ndarray, K: np.ndarray, h: float, th: float, out: np.ndarray) -> None:
        for i in range(y0.size):
            acc = 0.0
            for j in range(7):
                pj = th * (P[j, 0] + th * (P[j, 1] + th * (P[j, 2] + th * P[j, 3])))
                acc += K[j, i] * pj
            out[i] = y0[i] + h * acc

    @numba.njit(cache=False)
    def advance(model: int, mp: np.ndarray, kind: int, up: np.ndarray, ts: np.ndarray, us: np.ndarray,
                y: np.ndarray, s: float, t: float, t_end: float, h: float, rtol: float, atol: np.ndarray,
                td: np.ndarray, rev: np.ndarray, dout: np.ndarray, nrev: int, jd: int, K: np.ndarray) -> tuple:
        """From (t, y, s) to t_end with the step size h; returns (s, h, nrev, jd, steps)."""
        n = y.size
        ynew = np.empty(n)
        ytmp = np.empty(n)
        k = -1  # sample interval index: [ts[k], ts[k+1]]
        if kind == 1:
            while k + 1 < ts.size and ts[k + 1] <= t:
                k += 1
        rhs(t, y, s, model, mp, kind, up, ts, us, k, K[0])
        steps = 0
        while t < t_end:
            t_lim = t_end
            if kind == 1 and k + 1 < ts.size and ts[k + 1] < t_lim:
                t_lim = ts[k + 1]
            clipped = False
            hs = h
            if t + h >= t_lim:
                h = t_lim - t
                clipped = True
            for j in range(1, 6):
                for i in range(n):
                    acc = y[i]
                    for l in range(j):
                        acc += h * A[j, l] * K[l, i]
                    ytmp[i] = acc
                rhs(t + C[j] * h, ytmp, s, model, mp, kind, up, ts, us, k, K[j])
            for i in range(n):
                acc = y[i]
                for l in range(6):
                    acc += h * B[l] * K[l, i]
                ynew[i] = acc
            rhs(t + h, ynew, s, model, mp, kind, up, ts, us, k, K[6])
            err = 0.0
            for i in range(n):
                e = 0.0
                for l in range(7):
                    e += K[l, i] * E[l]
                sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
                err += (h * e / sc) ** 2
            err = np.sqrt(err / n)
            if err > 1.0:
                h *= max(0.2, 0.9 * err ** -0.2)
                continue
            steps += 1
            fac = 10.0 if err == 0.0 else min(10.0, max(0.2, 0.9 * err ** -0.2))
            if s * ynew[1] < 0.0:  # a reversal in the step: locate it on the dense output
                a, b, ga, gb = 0.0, 1.0, s * y[1], s * ynew[1]
                side = 0
                for _ in range(100):
                    th = (a * gb - b * ga) / (gb - ga)
                    dense(y, K, h, th, ytmp)
                    gc = s * ytmp[1]
                    if gc <= 0.0:
                        b, gb = th, gc
                        if side == -1:
                            ga *= 0.5
                        side = -1
                    else:
                        a, ga = th, gc
                        if side == 1:
                            gb *= 0.5
                        side = 1
                    if b - a < 1e-14:
                        break
                te = t + b * h
                while jd < td.size and td[jd] <= te:
                    dense(y, K, h, (td[jd] - t) / h, ytmp)
                    dout[0, jd], dout[1, jd], dout[2, jd] = ytmp[0], ytmp[1], ytmp[2]
                    jd += 1
                dense(y, K, h, b, y)
                y[1] = 0.0
                t = te
                F = rhs(t, y, s, model, mp, kind, up, ts, us, k, K[0])
                if nrev < rev.shape[1]:
                    rev[0, nrev], rev[1, nrev], rev[2, nrev] = t, y[0], F
                nrev += 1
                s = -s
                rhs(t, y, s, model, mp, kind, up, ts, us, k, K[0])
                h = hs
                continue
            while jd < td.size and td[jd] <= t + h:
                dense(y, K, h, (td[jd] - t) / h, ytmp)
                dout[0, jd], dout[1, jd], dout[2, jd] = ytmp[0], ytmp[1], ytmp[2]
                jd += 1
            for i in range(n):
                y[i] = ynew[i]
                K[0, i] = K[6, i]
            if clipped:
                t = t_lim
                h = max(h * fac, hs)
                if kind == 1 and k + 1 < ts.size and t >= ts[k + 1]:
                    k += 1
                    rhs(t, y, s, model, mp, kind, up, ts, us, k, K[0])
            else:
                t += h
                h *= fac
        return s, h, nrev, jd, steps

    @numba.njit(cache=False)
    def run(model: int, mp: np.ndarray, kind: int, up: np.ndarray, ts: np.ndarray, us: np.ndarray,
            y0in: np.ndarray, s0: float, t_end: float, rtol: float, atol: np.ndarray, td: np.ndarray,
            rev: np.ndarray, dout: np.ndarray) -> tuple:
        y = y0in.copy()
        K = np.empty((7, y.size))
        s, h, nrev, jd, steps = advance(model, mp, kind, up, ts, us, y, s0, 0.0, t_end, 1e-6, rtol, atol, td, rev,
                                        dout, 0, 0, K)
        return nrev, jd, steps

    @numba.njit(cache=False)
    def loop(model: int, mp: np.ndarray, Ad: np.ndarray, Bd: np.ndarray, Cd: np.ndarray, Dd: float, Ts: float,
             r: np.ndarray, y0in: np.ndarray, rtol: float, atol: np.ndarray, xs: np.ndarray, rev: np.ndarray) -> tuple:
        """The sampled loop: u_k = C xc + D (r_k - x_k) held over [k Ts, (k+1) Ts], xc += ..."""
        y = y0in.copy()
        K = np.empty((7, y.size))
        xc = np.zeros(Ad.shape[0])
        xn = np.empty(Ad.shape[0])
        up = np.zeros(2)
        none = np.zeros(0)
        dnone = np.zeros((3, 1))
        s, h, nrev, steps = 1.0, 1e-7, 0, 0
        for kk in range(r.size - 1):
            e = r[kk] - y[0]
            xs[kk] = y[0]
            u = Dd * e
            for i in range(xc.size):
                u += Cd[i] * xc[i]
            for i in range(xc.size):
                acc = Bd[i] * e
                for j in range(xc.size):
                    acc += Ad[i, j] * xc[j]
                xn[i] = acc
            xc[:] = xn
            up[0] = u
            if kk == 0:
                s = 1.0 if u > 0 else -1.0
            s, h, nrev, jd, st = advance(model, mp, 2, up, none, none, y, s, kk * Ts, (kk + 1) * Ts, h, rtol, atol,
                                         none, rev, dnone, nrev, 0, K)
            steps += st
        xs[r.size - 1] = y[0]
        return nrev, steps

    return run, loop


def forced_run(model: int, mp: np.ndarray, kind: int, up: np.ndarray, ts: np.ndarray, us: np.ndarray,
               y0: np.ndarray, s0: float, t_end: float, rtol: float, atol: np.ndarray,
               td: np.ndarray, max_rev: int = 100_000) -> tuple[np.ndarray, np.ndarray, int]:
    """One run of the numba reference.

    Parameters
    ----------
    model : int
        :data:`DAHL` (``mp = (sigma, Fc, m)``, state ``(x, v, F)``) or :data:`LUGRE`
        (``mp = (sigma0, sigma1, sigma2, Fc, Fs, vs, m)``, state ``(x, v, z)``); SI units.
    kind : int
        :data:`SINE` (``up = (amplitude [N], angular frequency [rad/s])``), :data:`SAMPLES`
        (``ts`` [s], ``us`` [N]) or :data:`PID` (``up`` as there; the state has the controller's
        two states after the stage's).
    y0, s0, t_end, rtol, atol : initial state, branch direction, end time [s], tolerances.
    td : numpy.ndarray
        Requested sample times [s] (empty: none).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, int)
        Reversals ``(t, x, F)`` as rows, samples ``(x, v, state 2)`` as rows, accepted steps.
    """
    run = _kernel()[0]
    rev = np.empty((3, max_rev))
    dout = np.empty((3, max(td.size, 1)))
    y0 = np.asarray(y0, dtype=float)
    nrev, nd, steps = run(model, mp, kind, up, ts, us, y0, s0, t_end, rtol, atol, td, rev, dout)
    return rev[:, :min(nrev, max_rev)], dout[:, :nd], int(steps)


def pid_loop(model: int, mp: np.ndarray, Ad: np.ndarray, Bd: np.ndarray, Cd: np.ndarray, Dd: float, Ts: float, r: np.ndarray,
             rtol: float, atol: np.ndarray, max_rev: int = 100_000) -> tuple[np.ndarray, np.ndarray, int]:
    """The sampled loop around a stage (``model``, ``mp`` as in :func:`forced_run`) from rest: a discrete
    controller ``(Ad, Bd, Cd, Dd)`` (SI) with the reference samples ``r`` [m] at ``k Ts``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, int)
        Positions at the sample instants [m], the reversals ``(t, x, F)`` as rows, accepted steps.
    """
    loop = _kernel()[1]
    xs = np.empty(r.size)
    rev = np.empty((3, max_rev))
    nrev, steps = loop(model, mp, np.ascontiguousarray(Ad, dtype=float), np.ascontiguousarray(Bd, dtype=float).ravel(),
                       np.ascontiguousarray(Cd, dtype=float).ravel(), float(Dd), Ts, r, np.zeros(3), rtol, atol, xs, rev)
    return xs, rev[:, :min(nrev, max_rev)], int(steps)


@functools.lru_cache(maxsize=1)
def _ms_kernel() -> Any:
    import numba

    @numba.njit(cache=False)
    def along(x: np.ndarray, k: np.ndarray, f: np.ndarray, F: np.ndarray) -> None:
        w = np.full(k.size, x[0])  # anchors: every element relaxed at the start
        for j in range(x.size):
            total = 0.0
            for i in range(k.size):
                Fi = k[i] * (x[j] - w[i])
                if Fi > f[i]:
                    Fi = f[i]
                    w[i] = x[j] - f[i] / k[i]
                elif Fi < -f[i]:
                    Fi = -f[i]
                    w[i] = x[j] + f[i] / k[i]
                total += Fi
            F[j] = total

    return along


def maxwell_slip_along(x: np.ndarray, k: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Force [N] of Maxwell-slip elements (stiffness ``k`` [N/m], slip force ``f`` [N]) along the
    positions ``x`` [m] from the relaxed state: each element elastic, ``k (x - w)``, its anchor
    ``w`` dragged along while it slips (``|k (x - w)| = f``); exact for a piecewise-linear motion."""
    F = np.empty(x.size)
    _ms_kernel()(np.ascontiguousarray(x, dtype=float), np.asarray(k, dtype=float), np.asarray(f, dtype=float), F)
    return F
