"""The reference both stiff-GMS test files use: scipy's Radau on the GMS equations in SI, restarted
at every reversal, slip and crossing of the narrow Stribeck band."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp


def gms_reversals(p: dict, mass: float, y0: np.ndarray, u: Callable[[float], float] | None = None,
                  t_end: float | None = None, n_rev: int | None = None) -> np.ndarray:
    """Reversals (t, x, F) [s, m, N] of ``m x'' = u(t) - sum F_i`` (``u`` omitted: no force) from
    ``y0 = (x, v, F_1 .. F_n)`` with the first motion in +x; GMS elements (``p`` the model's
    numbers): sticking ``F_i' = k_i v``, slipping ``F_i' = s C (1 - s F_i / (alpha_i S(v)))``,
    ``S(v) = Fc + (Fs - Fc) exp(-(v/vs)^2)``; an element slips from ``s F_i = alpha_i S(v)`` on; at
    a reversal every element sticks again. Runs to ``t_end`` [s], or (``t_end`` None) until
    ``n_rev`` reversals, each branch then integrated at most 10 s."""
    k, alpha = np.array(p["k"]), np.array(p["alpha"])
    Fc, Fs, vs, C = p["Fc"], p["Fs"], p["vs"], p["C"]
    S = lambda v: Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))  # noqa: E731
    net = (lambda tt, F: -F) if u is None else (lambda tt, F: u(tt) - F)  # noqa: E731
    n = len(k)
    s, slip, t, y, rows = 1.0, np.zeros(n, bool), 0.0, np.array(y0, dtype=float), []
    inside = y[1] == 0.0  # within 5 vs of v = 0 (toggled by the band's events)
    while (t < t_end) if t_end is not None else (len(rows) < n_rev):
        sl = slip.copy()

        def rhs(tt, yy, s=s, sl=sl):
            dF = np.where(sl, s * C * (1.0 - s * yy[2:] / (alpha * S(yy[1]))), k * yy[1])
            return np.r_[yy[1], net(tt, yy[2:].sum()) / mass, dF]

        def jac(_t, yy, s=s, sl=sl):
            J = np.zeros((n + 2, n + 2))
            J[0, 1] = 1.0
            J[1, 2:] = -1.0 / mass
            Sv = S(yy[1])
            dS = -2.0 * yy[1] / vs**2 * (Sv - Fc)
            for i in range(n):
                if sl[i]:
                    J[2 + i, 2 + i] = -C / (alpha[i] * Sv)
                    J[2 + i, 1] = C * yy[2 + i] / alpha[i] * dS / Sv**2
                else:
                    J[2 + i, 1] = k[i]
            return J

        # (at v = 0 exactly, e.g. from rest, the reversal's event is not taken at the start)
        events = [lambda _t, yy, s=s: s * yy[1] + (1e-30 if yy[1] == 0.0 else 0.0)]
        for j in range(n):
            events.append(lambda _t, yy, j=j, s=s, sl=sl: 1.0 if sl[j] else alpha[j] * S(yy[1]) - s * yy[2 + j])
        # the Stribeck curve is narrow (vs = 1 mm/s against 5 cm/s): within 5 vs of v = 0 the
        # steps are at most vs / 20 of speed (Radau's steps would jump over it)
        events.append(lambda _t, yy, s=s, inside=inside: (5 * vs - s * yy[1]) if inside else (s * yy[1] - 5 * vs))
        for ev in events:
            ev.terminal, ev.direction = True, -1.0
        sol = solve_ivp(rhs, (t, t_end if t_end is not None else t + 10.0), y, method="Radau", jac=jac, rtol=1e-10,
                        atol=np.r_[1e-19, 1e-17, np.full(n, 1e-16)], events=events,
                        max_step=0.05 * vs * mass / max(abs(net(t, y[2:].sum())), 1e-3) if inside else np.inf)
        assert sol.status >= 0
        if sol.status == 0:
            assert t_end is not None, "no reversal, slip or band crossing within 10 s"
            break
        te, i = min((float(e[0]), i) for i, e in enumerate(sol.t_events) if len(e))
        t, y = te, sol.y_events[i][0].copy()
        if i == n + 1:
            inside = not inside
            continue
        if i == 0:
            s, slip[:], y[1], inside = -s, False, 0.0, True
            rows.append((t, y[0], y[2:].sum()))
        else:
            slip[i - 1] = True
    return np.array(rows)
