"""``prefriction bench --along``: time of :func:`prefriction.friction_along` per 100,000 samples and
its error against a scipy reference written from each model's equations.

For each model (Dahl gamma = 1 and gamma = 0.5, Maxwell-slip with 3 elements, GMS with 3 elements,
LuGre, Dahl + Viscous) on one multi-sine record of 100,000 samples (with minor loops): the warm
run time of ``friction_along`` (minimum of interleaved repeats), and on the same motion sampled
at :data:`N_REF` points (its 66 reversals kept) the largest error relative to the force range against a scipy
``solve_ivp`` (DOP853, rtol 1e-12) integration of the model's equations in SI units, restarted
at every sample interval and event, with its run time scaled to 100,000 samples. Target:
<= 0.5 s per 100,000 samples and error <= 1e-9 of the force range for every model
(``docs/along.md#speed``).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp

from prefriction.along.run import friction_along
from prefriction.models import GMS, Dahl, FrictionModel, LuGre, MaxwellSlip, Viscous

__all__ = ["N", "N_REF", "Row", "main", "record", "rows"]

N = 100_000
"""Samples of the timed record."""
N_REF = 2_000
"""Samples checked against the scipy reference (its time is scaled to :data:`N`)."""
TARGET_S = 0.5
TARGET_ERR = 1e-9


def record(n: int = N) -> tuple[np.ndarray, np.ndarray]:
    """The motion: 10 s at ``n`` samples, a 1 Hz sine of 30 µm with a 4.3 Hz sine of 12 µm."""
    t = np.linspace(0.0, 10.0, n)
    return t, 3e-5 * np.sin(2 * np.pi * t) + 1.2e-5 * np.sin(2 * np.pi * 4.3 * t + 0.4)


@dataclass(frozen=True)
class Row:
    """One model: warm seconds per 100,000 samples, error against scipy, scipy's scaled time."""

    name: str
    seconds: float
    error: float
    scipy_seconds: float

    @property
    def passed(self) -> bool:
        return self.seconds <= TARGET_S and self.error <= TARGET_ERR


def _integrate(rhs: Callable, y0: np.ndarray, t0: float, t1: float, events: list) -> tuple[float, np.ndarray, bool]:
    sol = solve_ivp(rhs, (t0, t1), y0, method="DOP853", rtol=1e-12, atol=1e-18, events=events or None)
    return float(sol.t[-1]), sol.y[:, -1], sol.status == 1


def _elements_reference(t: np.ndarray, x: np.ndarray, k: np.ndarray, limit: Callable[[float], np.ndarray],
                        slip_rate: Callable[[float, float, np.ndarray], np.ndarray]) -> np.ndarray:
    """Elements ``F_i`` in SI: sticking ``F_i' = k_i v`` up to ``s F_i = limit_i(v)``, then
    ``F_i' = slip_rate``; every element sticks again at a reversal (Maxwell-slip, GMS)."""
    Fi, slip, s, F = np.zeros(k.size), np.zeros(k.size, dtype=bool), 0.0, np.zeros(x.size)
    for i in range(1, x.size):
        v = (x[i] - x[i - 1]) / (t[i] - t[i - 1])
        if v != 0.0 and np.sign(v) != s:
            s, slip = float(np.sign(v)), np.zeros(k.size, dtype=bool)
        ta = t[i - 1]
        while True:
            slip |= ~slip & (s * Fi >= limit(v) * (1 - 1e-12))
            evs = []
            for j in np.flatnonzero(~slip):
                ev = (lambda j: lambda _t, y: limit(v)[j] - s * y[j])(j)
                ev.terminal, ev.direction = True, -1.0
                evs.append(ev)
            rhs = (lambda sl: lambda _t, y: np.where(sl, slip_rate(v, s, y), k * v))(slip.copy())
            ta, Fi, stopped = _integrate(rhs, Fi, ta, t[i], evs)
            if not stopped:
                break
        F[i] = Fi.sum()
    return F


def _dahl_reference(t: np.ndarray, x: np.ndarray, sigma: float, Fc: float, gamma: float) -> np.ndarray:
    """Dahl (3.2) in SI, ``F' = sigma v |1 - s F / Fc|^gamma``, restarted at intervals and saturation."""
    F, s = np.zeros(x.size), 0.0
    for i in range(1, x.size):
        v = (x[i] - x[i - 1]) / (t[i] - t[i - 1])
        s = float(np.sign(v)) if v != 0.0 else s
        if s * F[i - 1] >= Fc:
            F[i] = F[i - 1]
            continue
        sat = lambda _t, y: Fc - s * y[0]
        sat.terminal = True
        ta, y, stopped = _integrate(lambda _t, y: [sigma * v * max(1.0 - s * y[0] / Fc, 0.0) ** gamma],
                                    np.array([F[i - 1]]), t[i - 1], t[i], [sat] if gamma < 1.0 else [])
        F[i] = s * Fc if stopped else y[0]
    return F


def _lugre_reference(t: np.ndarray, x: np.ndarray, p: tuple) -> np.ndarray:
    """LuGre (1)-(3) in SI, the force at a sample with the velocity of the interval ending there."""
    s0, s1, s2, Fc, Fs, vs = p
    g = lambda v: Fc + (Fs - Fc) * math.exp(-(v / vs) ** 2)
    z, F = 0.0, np.zeros(x.size)
    v0 = (x[1] - x[0]) / (t[1] - t[0])
    F[0] = s1 * v0 + s2 * v0
    for i in range(1, x.size):
        v = (x[i] - x[i - 1]) / (t[i] - t[i - 1])
        rate = lambda _t, y: [v - s0 * abs(v) * y[0] / g(v)]
        _ta, y, _stop = _integrate(rate, np.array([z]), t[i - 1], t[i], [])
        z = y[0]
        F[i] = s0 * z + s1 * rate(0.0, [z])[0] + s2 * v
    return F


def _cases() -> list[tuple[str, FrictionModel, Callable[[np.ndarray, np.ndarray], np.ndarray]]]:
    k, w = np.array([6e4, 3e4, 1e4]), np.array([0.3, 0.4, 0.3])
    alpha, C, S = np.array([0.2, 0.3, 0.5]), 2e3, (lambda v: 1.0 + 0.5 * math.exp(-(v / 1e-4) ** 2))
    lugre = (1e5, 300.0, 0.5, 1.0, 1.5, 1e-4)
    return [
        ("Dahl gamma=1", Dahl(1e5, 1.0), lambda t, x: _dahl_reference(t, x, 1e5, 1.0, 1.0)),
        ("Dahl gamma=0.5", Dahl(1e5, 1.0, 0.5), lambda t, x: _dahl_reference(t, x, 1e5, 1.0, 0.5)),
        ("MaxwellSlip(3)", MaxwellSlip(k, w),
         lambda t, x: _elements_reference(t, x, k, lambda v: w, lambda v, s, y: 0.0 * y)),
        ("GMS(3)", GMS(k=k, alpha=alpha, Fc=1.0, Fs=1.5, vs=1e-4, C=C),
         lambda t, x: _elements_reference(t, x, k, lambda v: alpha * S(v),
                                          lambda v, s, y: s * C * (1.0 - s * y / (alpha * S(v))))),
        ("LuGre", LuGre(*lugre), lambda t, x: _lugre_reference(t, x, lugre)),
        ("Dahl + Viscous", Dahl(1e5, 1.0) + Viscous(3.0),
         lambda t, x: _dahl_reference(t, x, 1e5, 1.0, 1.0)
         + 3.0 * np.concatenate(([(x[1] - x[0]) / (t[1] - t[0])], np.diff(x) / np.diff(t)))),
    ]


def rows(repeats: int = 5, n: int = N, n_ref: int = N_REF) -> list[Row]:
    """Measure every model (module notes); progress on stderr."""
    t, x = record(n)
    t_ref_rec, x_ref_rec = record(n_ref)  # the same motion, fewer samples: every reversal, scipy affordable
    out = []
    cases = _cases()
    best = {name: math.inf for name, _m, _r in cases}
    for name, model, _ref in cases:  # build and compile once, outside the timing
        friction_along(model, t[:10], x[:10])
    for _ in range(repeats):  # interleaved rounds, minimum kept
        for name, model, _ref in cases:
            start = time.perf_counter()
            friction_along(model, t, x)
            best[name] = min(best[name], time.perf_counter() - start)
    for name, model, ref in cases:
        print(f"bench --along: scipy reference for {name} ({n_ref} samples)", file=sys.stderr, flush=True)
        F = friction_along(model, t_ref_rec, x_ref_rec).F
        start = time.perf_counter()
        F_ref = ref(t_ref_rec, x_ref_rec)
        t_ref = (time.perf_counter() - start) * n / n_ref
        out.append(Row(name, best[name] * N / n, float(np.max(np.abs(F - F_ref)) / np.ptp(F_ref)), t_ref * N / n))
    return out


def main(repeats: int | None = None, quick: bool = False) -> int:
    """Print the table and the verdict; 0 if every model passes both targets."""
    table = rows(repeats or (1 if quick else 5), n_ref=500 if quick else N_REF)
    print(f"friction_along: warm time per {N:,} samples and error against scipy (DOP853, rtol 1e-12, restarted "
          f"at every interval and event; the same motion at {500 if quick else N_REF} samples, scipy's time "
          f"scaled to {N:,})")
    print(f"  {'model':<16} {'time [s]':>9} {'error / range':>14} {'scipy [s]':>10} {'scipy / along':>14}")
    for r in table:
        print(f"  {r.name:<16} {r.seconds:9.3f} {r.error:14.2e} {r.scipy_seconds:10.1f} "
              f"{r.scipy_seconds / r.seconds:14.0f}   {'PASS' if r.passed else 'FAIL'}")
    ok = all(r.passed for r in table)
    print(f"target: <= {TARGET_S} s per {N:,} samples and error <= {TARGET_ERR:g} of the force range: "
          f"{'PASS' if ok else 'FAIL'}")
    return 0 if ok else 1
