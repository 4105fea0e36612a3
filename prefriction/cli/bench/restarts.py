"""The Dahl oscillator by scipy DOP853 with a restart at every reversal and saturation.

The reference of the rows against independent references (``docs/bench.md#reference-rows``)
and the peer of ``prefriction bench --sweep``: :func:`scipy_reversals` integrates the
normalised equations (``docs/mathematics.md#normalised-units``) branch by branch, each branch a
``solve_ivp`` call that ends at the next velocity reversal (or, for gamma < 1, at saturation
``|F~| = 1``), so no step crosses the kink at ``v = 0``.
"""

from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np


def _branch_rhs(gamma: float, s: float, saturated: bool, u: Optional[Callable[[float], float]]) -> Callable:
    """Right-hand side ``(x~, v~, F~)' `` on a branch of direction ``s`` (``F~' = 0`` once saturated)."""
    if saturated:
        return lambda t, z: [z[1], (u(t) if u else 0.0) - z[2], 0.0]
    return lambda t, z: [z[1], (u(t) if u else 0.0) - z[2], z[1] * max(1.0 - s * z[2], 0.0) ** gamma]


def _branch_events(gamma: float, s: float, saturated: bool) -> list[Callable]:
    """Terminal events of a branch: the reversal ``s v~ = 0`` and, for gamma < 1, saturation.

    Both have ``direction = -1``: after a restart exactly at ``v~ = 0`` (or ``|F~| = 1``) the
    indicator starts at 0 and grows, so the event does not fire at the start of the branch.
    """

    def reversal(t: float, z: np.ndarray) -> float:
        return s * z[1]

    reversal.terminal, reversal.direction = True, -1.0
    events = [reversal]
    if gamma < 1.0 and not saturated:

        def saturation(t: float, z: np.ndarray) -> float:
            return 1.0 - s * z[2]

        saturation.terminal, saturation.direction = True, -1.0
        events.append(saturation)
    return events


def _initial_direction(v0: float, f0: float, u: Optional[Callable[[float], float]]) -> float:
    """Branch direction at the start: ``sign(v0)``, else that of the net force (just after 0)."""
    if v0 != 0.0:
        return math.copysign(1.0, v0)
    if u is None:
        return -math.copysign(1.0, f0) if f0 != 0.0 else 1.0
    for h in (0.0, 1e-9, 1e-6, 1e-3):
        net = u(h) - f0
        if net != 0.0:
            return math.copysign(1.0, net)
    return 1.0


def scipy_reversals(gamma: float, v0: float, rtol: float, *, n: Optional[int] = None,
                    t_end: Optional[float] = None, u: Optional[Callable[[float], float]] = None,
                    f0: float = 0.0) -> np.ndarray:
    """Reversals of the Dahl oscillator by scipy DOP853 with a restart at every event (normalised).

    Integrates ``x~' = v~``, ``v~' = u~(t~) - F~``, ``F~' = v~ (1 - s F~)^gamma`` from
    ``x~ = 0``; ``s`` is the direction of the current branch. Each velocity reversal ends a
    ``solve_ivp`` call; the next starts on the reversed branch at ``v~ = 0`` exactly. For
    ``gamma < 1`` reaching ``|F~| = 1`` is an event too, after which ``F~`` stays at ``s``
    until the next reversal.

    Parameters
    ----------
    gamma : float
        Dahl shape factor, ``>= 0``.
    v0 : float
        Initial normalised velocity ``v~``.
    rtol : float
        Relative tolerance of DOP853; ``atol = rtol / 100``.
    n : int, optional
        Stop after this many reversals.
    t_end : float, optional
        Stop at this normalised time. At least one of ``n`` and ``t_end`` is required.
    u : callable, optional
        Normalised input force ``u~(t~)``; None for the unforced oscillator.
    f0 : float, optional
        Initial normalised friction force, default 0.

    Returns
    -------
    numpy.ndarray
        Shape ``(k, 3)``: normalised time, position and force of each reversal.

    Raises
    ------
    ValueError
        If neither ``n`` nor ``t_end`` is given.
    RuntimeError
        If ``solve_ivp`` fails.
    """
    from scipy.integrate import solve_ivp

    if n is None and t_end is None:
        raise ValueError("give n (reversals) or t_end (normalised end time) or both")
    s, saturated = _initial_direction(v0, f0, u), False
    y, t0, out = np.array([0.0, v0, f0]), 0.0, []
    t_stop = math.inf if t_end is None else t_end
    span = 64.0 + 4.0 * abs(v0) + 2.0 * v0 * v0
    while (n is None or len(out) < n) and t0 < t_stop:
        sol = solve_ivp(_branch_rhs(gamma, s, saturated, u), (t0, min(t0 + span, t_stop)), y,
                        method="DOP853", rtol=rtol, atol=rtol * 1e-2,
                        events=_branch_events(gamma, s, saturated))
        if sol.status == 1 and len(sol.t_events[0]):  # reversal: restart on the reversed branch
            t0, y = float(sol.t_events[0][0]), np.array(sol.y_events[0][0])
            y[1] = 0.0
            out.append((t0, y[0], y[2]))
            s, saturated = -s, False
        elif sol.status == 1:  # saturation |F~| = 1
            t0, y = float(sol.t_events[1][0]), np.array(sol.y_events[1][0])
            y[2], saturated = s, True
        elif sol.status == 0:
            t0, y = float(sol.t[-1]), sol.y[:, -1]
        else:
            raise RuntimeError(f"solve_ivp DOP853 failed at t~ = {t0}: {sol.message}")
    return np.array(out, dtype=float).reshape(-1, 3)
