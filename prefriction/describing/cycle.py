"""Describing functions from one settled cycle, for any friction model of the protocol.

Two blocks are analysed, both by the first harmonic of one settled period:

- :func:`friction_describing_function`: the friction model alone under the prescribed
  displacement ``x = A sin(omega t)``; output the friction force. Integrated with scipy's
  ``solve_ivp`` on the model's own numeric equations (normalised units, restarts at the two
  reversals of each period and at every model event), the harmonic integrals
  ``int F sin``, ``int F cos`` carried as extra states, cycles repeated until two successive
  ones agree (the cycle has settled);
- :func:`plant_describing_function`: the mass with its friction under the prescribed force
  ``u = U sin(omega t)``; output the position. Simulated with :func:`prefriction.simulate`
  (every reversal, stick and slip located), harmonic of the velocity from its dense samples
  over the last period, periods added until two successive ones agree. This is the block
  whose describing function sees stick-slip (``docs/describing.md#plant-block``).
"""

from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np
from scipy.integrate import solve_ivp

from prefriction._validation import check_count, check_interval, check_positive
from prefriction.errors import SolverError
from prefriction.models import Oscillator, check_oscillator
from prefriction.units import Scales

__all__ = ["friction_describing_function", "plant_describing_function"]

_MAX_CYCLES = 400  # refused beyond: a cycle that has not settled after this many periods


def _half_cycle(model: Any, q: list, z: list, m: list, s: float, A: float, w: float, rtol: float,
                method: str, th0: float) -> tuple[list, list, float, float]:
    """Integrate ``theta`` over ``[th0, th0 + pi]`` on the branch of direction ``s``.

    Returns the state at the end (before the reversal) and the two harmonic integrals
    ``int F sin(theta) dtheta``, ``int F cos(theta) dtheta`` over the half-cycle (normalised).
    """
    nz = model.n_states
    th, th1 = th0, th0 + math.pi
    y = np.array([*z, 0.0, 0.0])
    m = list(m)
    while True:
        mm = list(m)

        def rhs(t: float, y: np.ndarray, mm: list = mm) -> np.ndarray:
            v = A * w * math.cos(t)  # x~ = A sin(theta), dx~/dt~ = A w cos(theta)
            zz = y[:nz].tolist()
            F = model.force(zz, mm, v, s, q)
            dz = [r / w for r in model.rate(zz, mm, v, s, q)]  # d/dtheta = (1/w) d/dt~
            return np.array([*dz, F * math.sin(t), F * math.cos(t)])

        evs = []
        for k in range(model.n_events):
            def ev(t: float, y: np.ndarray, k: int = k, mm: list = mm) -> float:
                return model.events(y[:nz].tolist(), mm, A * w * math.cos(t), s, q)[k]
            ev.terminal, ev.direction = True, -1.0
            evs.append(ev)
        sol = solve_ivp(rhs, (th, th1), y, method=method, rtol=rtol, atol=rtol * 1e-3, events=evs or None)
        if sol.status < 0:
            raise SolverError(
                f"friction_describing_function: scipy {method} failed at theta = {sol.t[-1]!r} rad "
                f"(state {sol.y[:, -1]!r}): {sol.message}; try a looser rtol or method='Radau'"
            )
        if sol.status == 0:
            y = sol.y[:, -1]
            return y[:nz].tolist(), m, float(y[nz]), float(y[nz + 1])
        k, te = min((float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te))[::-1]
        th = te
        y = sol.y_events[k][0].copy()
        zn, m = model.on_event(k, y[:nz].tolist(), m, s, q)
        y[:nz] = [float(v) for v in zn]


def friction_describing_function(system: Oscillator, A: float, omega: float = 1.0, *, rtol: float = 1e-10,
                                 tol: float = 1e-8, max_cycles: int = 200,
                                 method: Optional[str] = None) -> complex:
    """Describing function ``N(A, omega)`` [N/m] of the friction model alone, from a settled cycle.

    The friction model of ``system`` is driven by the displacement ``x = A sin(omega t)`` (the
    mass plays no part, it only fixes the normalised units of models whose numbers depend on
    it, such as LuGre). The first harmonic ``b1 sin + a1 cos`` of the settled force gives
    ``N = (b1 + i a1) / A`` (python-control's convention). Rate-independent models give the
    same ``N`` at every ``omega``.

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model (any :class:`prefriction.FrictionModel`); no input force.
    A : float
        Displacement amplitude [m], ``0 < A < inf``.
    omega : float, default 1.0
        Angular frequency [rad/s], ``0 < omega < inf``.
    rtol : float, default 1e-10
        Relative tolerance of ``solve_ivp``, ``1e-13 <= rtol <= 1e-4``.
    tol : float, default 1e-8
        The cycle has settled when the harmonic of two successive periods differs by less than
        ``tol |N|`` (``1e-14 <= tol <= 1e-2``).
    max_cycles : int, default 200
        Periods integrated at most, ``1 <= max_cycles <= 400``; not settled by then raises.
    method : str, optional
        ``solve_ivp`` method; default ``"DOP853"`` for rate-independent models, ``"LSODA"``
        otherwise (LuGre is stiff in gross sliding; LSODA switches to BDF there and is 30-100
        times faster than Radau at the same ``N`` to 1e-9).

    Returns
    -------
    complex
        ``N`` [N/m].

    Raises
    ------
    ValueError
        Arguments out of range, or the cycle has not settled within ``max_cycles``.
    SolverError
        If scipy's integration fails (the message gives the phase and the state).
    """
    model = check_oscillator(system, "friction_describing_function")
    if system.u is not None:
        raise ValueError("friction_describing_function: system must have no input force (system.u is None)")
    A = check_positive("A", A)
    omega = check_positive("omega", omega)
    rtol = check_interval("rtol", rtol, 1e-13, 1e-4)
    tol = check_interval("tol", tol, 1e-14, 1e-2)
    max_cycles = check_count("max_cycles", max_cycles)
    if max_cycles > _MAX_CYCLES:
        raise ValueError(f"max_cycles must be <= {_MAX_CYCLES} (each period is one scipy integration), got {max_cycles}")
    method = method or ("DOP853" if model.rate_independent else "LSODA")
    sc = Scales.of(system)
    q = [float(v) for v in model.runtime_params_for(sc)]
    An, wn = A / sc.x, omega * sc.t
    # warm start at x = -A on the Dahl (gamma = 1) symmetric cycle: F = -Fc tanh(A~)
    z, m = model.initial_state(-math.tanh(An), 1.0)
    z, m = list(z), list(m)
    prev, settled = None, 0
    for _ in range(max_cycles):
        b1 = a1 = 0.0
        for s, th0 in ((1.0, -0.5 * math.pi), (-1.0, 0.5 * math.pi)):
            z, m, bs, ac = _half_cycle(model, q, z, m, s, An, wn, rtol, method, th0)
            b1, a1 = b1 + bs, a1 + ac
            z, m = model.reverse(z, m, -s, q, 1e-12)
            z, m = [float(v) for v in z], list(m)
        N = complex(b1, a1) / (math.pi * An) * (sc.F / sc.x)
        if prev is not None and abs(N - prev) <= tol * abs(N):
            settled += 1
            if settled == 2:
                return N
        else:
            settled = 0
        prev = N
    raise ValueError(
        f"friction_describing_function: the cycle at A = {A!r} m, omega = {omega!r} rad/s has not settled "
        f"after max_cycles = {max_cycles} periods (last change {abs(N - prev) / abs(N):.3g} relative, tol = {tol!r}); "
        "raise max_cycles or tol"
    )


def plant_describing_function(system: Oscillator, U: float, omega: float, *, rtol: float = 1e-9,
                              tol: float = 1e-6, periods: int = 4, max_periods: int = 64,
                              samples: int = 512) -> complex:
    """Describing function ``X1 / U`` [m/N] of the mass with its friction under ``u = U sin(omega t)``.

    The oscillator ``m x'' = u - F`` (``system``'s mass and friction model) starts at rest at
    ``x = 0``, ``F = 0`` and is simulated by :func:`prefriction.simulate` (every reversal,
    stick and slip located) for ``periods`` periods, doubled until the first harmonic of the
    velocity over the last two periods agrees within ``tol``. The harmonic of the position
    follows as ``X1 = V1 / (i omega)`` (a drift of the mean position does not enter).

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model; no input force of its own.
    U : float
        Force amplitude [N], ``0 < U < inf``.
    omega : float
        Angular frequency [rad/s], ``0 < omega < inf``.
    rtol : float, default 1e-9
        Tolerance of :func:`prefriction.simulate`.
    tol : float, default 1e-6
        Settling test between the last two periods (relative to ``|X1|``), ``1e-12 <= tol <= 1e-2``.
    periods : int, default 4
        Periods of the first try, ``2 <= periods``.
    max_periods : int, default 64
        Periods at most, ``<= 1024``; not settled by then raises ``ValueError``.
    samples : int, default 512
        Dense samples per period (trapezoidal harmonic; ``64 <= samples <= 8192``).

    Returns
    -------
    complex
        ``X1 / U`` [m/N] (python-control's convention, phasors relative to ``sin``).
    """
    from prefriction.signals import Sine
    from prefriction.simulation.simulate import simulate

    model = check_oscillator(system, "plant_describing_function")
    if system.u is not None:
        raise ValueError("plant_describing_function: system must have no input force (system.u is None)")
    U = check_positive("U", U)
    omega = check_positive("omega", omega)
    tol = check_interval("tol", tol, 1e-12, 1e-2)
    periods = check_count("periods", periods, minimum=2)
    max_periods = check_count("max_periods", max_periods, minimum=periods)
    samples = check_count("samples", samples, minimum=64)
    if max_periods > 1024 or samples > 8192:
        raise ValueError(f"max_periods must be <= 1024 and samples <= 8192, got {max_periods} and {samples}")
    forced = Oscillator(model, system.mass, u=Sine(U, omega / (2.0 * math.pi)))
    T = 2.0 * math.pi / omega
    theta = 2.0 * math.pi * np.arange(samples) / samples
    while True:
        t = T * np.arange(periods * samples + 1) / samples
        res = simulate(forced, 0.0, t_end=t[-1], dense=t, rtol=rtol)
        harm = []
        for p in (periods - 2, periods - 1):
            v = res.v[p * samples:(p + 1) * samples]
            V1 = 2.0 * complex(np.mean(v * np.sin(theta)), np.mean(v * np.cos(theta)))
            harm.append(V1 / (1j * omega) / U)
        if abs(harm[1] - harm[0]) <= tol * abs(harm[1]):
            return harm[1]
        if periods * 2 > max_periods:
            raise ValueError(
                f"plant_describing_function: the response to U = {U!r} N at omega = {omega!r} rad/s has not settled "
                f"after {periods} periods (change {abs(harm[1] - harm[0]) / abs(harm[1]):.3g} relative, "
                f"tol = {tol!r}); raise max_periods or tol"
            )
        periods *= 2
