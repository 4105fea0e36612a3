"""Peers of :func:`prefriction.simulate` on the Dahl cases, in normalised units.

scipy ``solve_ivp`` with a terminal event at ``v = 0`` and a restart on the reversed branch;
scipy without events on the ``|v|`` form ``F' = sigma (v - |v| F / Fc)`` (reversals located
afterwards on the dense output); python-control ``input_output_response`` of the ``|v|`` form
(reversals on its output grid). All integrate the normalised equations
(``docs/mathematics.md#normalised-units``) with ``rtol = tol`` and ``atol = tol / 100`` and
return the reversal times [s], positions [m] and forces [N] (``docs/bench.md#peers``).
"""

from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np

from prefriction.cli.bench.cases import N_REV, Case
from prefriction.units import Scales

SCIPY_METHODS = ["RK45", "DOP853", "LSODA", "Radau", "BDF"]


def scipy_events(case: Case, tol: float, method: str, n: int = N_REV) -> tuple[np.ndarray, ...]:
    """solve_ivp with a terminal event at ``s v = 0`` (direction -1) and a restart on the new branch.

    Parameters
    ----------
    case : Case
        The oscillator and its initial state.
    tol : float
        ``rtol``; ``atol = tol / 100``.
    method : str
        A ``solve_ivp`` method.
    n : int, optional
        Reversals to find, default 50.

    Returns
    -------
    (t, x, F) : tuple of numpy.ndarray
        Reversal times [s], positions [m] and forces [N].

    Raises
    ------
    RuntimeError
        If ``solve_ivp`` fails.
    """
    from scipy.integrate import solve_ivp

    sc = Scales.of(case.system)
    g = case.gamma
    y = np.array([0.0, case.v0 / sc.v, case.F0 / sc.F])
    s = 1.0 if y[1] > 0 else (-1.0 if y[1] < 0 else -math.copysign(1.0, y[2]))
    t0 = 0.0
    out = []

    def make_event(s: float) -> Callable:
        def event(t: float, z: np.ndarray) -> float:
            return s * z[1]

        event.terminal = True
        event.direction = -1.0  # after a restart at v = 0 the indicator starts at 0 and grows
        return event

    span = 64.0 + 4.0 * abs(y[1]) + 2.0 * abs(y[1]) ** 2
    while len(out) < n:
        rhs = lambda t, z, s=s: [z[1], -z[2], z[1] * max(1.0 - s * z[2], 0.0) ** g]  # noqa: E731
        sol = solve_ivp(rhs, (t0, t0 + span), y, method=method, rtol=tol, atol=tol * 1e-2,
                        events=make_event(s))
        if sol.status == 1:
            t0 = float(sol.t_events[0][0])
            y = np.array(sol.y_events[0][0])
            out.append((t0, y[0], y[2]))
            s = -s
        elif sol.status == 0:
            t0, y = float(sol.t[-1]), sol.y[:, -1]
        else:
            raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    R = np.array(out)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def locate(t: np.ndarray, x: Callable, v: np.ndarray, F: Callable, vfun: Optional[Callable], n: int) -> np.ndarray:
    """Reversals ``(t, x, F)`` at the sign changes of ``v`` on a grid, refined by ``vfun`` if given.

    Parameters
    ----------
    t, v : numpy.ndarray
        Grid times and velocities.
    x, F : callable
        Position and force at a time.
    vfun : callable or None
        Velocity at a time (``brentq`` on it); None: linear interpolation on the grid.
    n : int
        Most reversals returned.

    Returns
    -------
    numpy.ndarray
        Shape ``(k, 3)``, ``k <= n``.
    """
    from scipy.optimize import brentq

    idx = np.nonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)[0][:n]
    out = []
    for i in idx:
        if vfun is None:
            tr = t[i] - v[i] * (t[i + 1] - t[i]) / (v[i + 1] - v[i])
        else:
            tr = brentq(vfun, t[i], t[i + 1], xtol=1e-15, rtol=1e-15)
        out.append((tr, x(tr), F(tr)))
    return np.array(out).reshape(-1, 3)


def _abs_form_span(case: Case) -> float:
    """Normalised time span that holds the first 50 reversals (gamma = 1)."""
    sc = Scales.of(case.system)
    return 1.15 * N_REV * 3.6 + 4.0 * abs(case.v0 / sc.v)


def scipy_noevents(case: Case, tol: float, method: str) -> tuple[np.ndarray, ...]:
    """solve_ivp without events on the ``|v|`` form; the first 50 reversals from the dense output.

    Parameters and returns as :func:`scipy_events` (gamma = 1 only).
    """
    from scipy.integrate import solve_ivp

    sc = Scales.of(case.system)
    rhs = lambda t, z: [z[1], -z[2], z[1] - abs(z[1]) * z[2]]  # noqa: E731
    span = _abs_form_span(case)
    sol = solve_ivp(rhs, (0.0, span), [0.0, case.v0 / sc.v, case.F0 / sc.F], method=method,
                    rtol=tol, atol=tol * 1e-2, dense_output=True)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    R = locate(sol.t, lambda tr: sol.sol(tr)[0], sol.y[1], lambda tr: sol.sol(tr)[2],
               lambda tr: sol.sol(tr)[1], N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F


def control_abs_form(case: Case, tol: float) -> tuple[np.ndarray, ...]:
    """python-control ``input_output_response`` of the ``|v|`` form (no events), reversals on its grid.

    Parameters and returns as :func:`scipy_events` (gamma = 1 only; 20 grid points per
    normalised time unit).
    """
    import control as ct

    sc = Scales.of(case.system)
    sys_ = ct.NonlinearIOSystem(
        lambda t, z, u, params: np.array([z[1], -z[2], z[1] - abs(z[1]) * z[2]]),
        lambda t, z, u, params: z, inputs=1, outputs=3, states=3, name="dahl",
    )
    span = _abs_form_span(case)
    T = np.linspace(0.0, span, int(span * 20) + 1)
    resp = ct.input_output_response(sys_, T, 0.0, X0=[0.0, case.v0 / sc.v, case.F0 / sc.F],
                                    solve_ivp_kwargs={"rtol": tol, "atol": tol * 1e-2})
    y = np.asarray(resp.outputs)
    R = locate(resp.time, lambda tr: np.interp(tr, resp.time, y[0]), y[1],
               lambda tr: np.interp(tr, resp.time, y[2]), None, N_REV)
    return R[:, 0] * sc.t, R[:, 1] * sc.x, R[:, 2] * sc.F
