"""The friction stage as a python-control nonlinear I/O system (``control.NonlinearIOSystem``).

For users who want ``control.interconnect`` and python-control's own simulation
(``control.input_output_response``). The plant is the |v| form of the Dahl model (3.2),

    x' = v,   m v' = u - F,   F' = sigma v w(s F / Fc),   s = sign(v),

with ``w(f) = max(1 - f, 0)^gamma`` (``gamma = 0``: 1 below saturation, 0 at it), written for
every ``v`` at once. Its right-hand side is not smooth at ``v = 0``, and python-control's
integrator (scipy ``solve_ivp``) neither locates the velocity reversals nor restarts there: it
steps across each kink, so its accuracy is limited there whatever the tolerance.
:func:`controllers.simulate_loop` lands on every reversal instead. The shortfall measured on
the stage example is printed by ``python -m prefriction.controllers.benchmark``.
"""

from __future__ import annotations

import math
from typing import Any, Optional

import control
import numpy as np
from scipy.integrate import solve_ivp

from prefriction._validation import check_positive
from prefriction.models import Dahl, Oscillator
from prefriction.units import Scales

from ._linear import _check_system


def _dahl_rhs(system: Oscillator):
    """Right-hand side ``f(state, u)`` of the |v|-form Dahl stage in SI units."""
    fr = system.friction
    if not isinstance(fr, Dahl):
        raise TypeError(f"plant_iosys needs a prefriction.Dahl friction model, got {fr!r}")
    m, sigma, Fc, gamma = system.mass, fr.sigma, fr.Fc, fr.gamma

    def rhs(state: np.ndarray, u: float) -> np.ndarray:
        _, v, F = state
        w = 1.0 - math.copysign(1.0, v) * F / Fc if v != 0.0 else 1.0
        if gamma == 0.0:
            slope = 1.0 if w > 0.0 else 0.0
        else:
            slope = max(w, 0.0) ** gamma
        return np.array([v, (u - F) / m, sigma * v * slope])

    return rhs


def plant_iosys(
    system: Oscillator, *, Ts: Optional[float] = None, solve_ivp_kwargs: Optional[dict[str, Any]] = None
) -> control.NonlinearIOSystem:
    """The Dahl friction stage as a ``control.NonlinearIOSystem`` (input force, output position).

    Parameters
    ----------
    system : prefriction.Oscillator
        Stage with :class:`prefriction.Dahl` friction (3.2); its own input force ``u`` is ignored
        (the I/O system's input replaces it).
    Ts : float, optional
        ``None``: continuous-time system for ``control.interconnect`` with continuous controllers.
        ``Ts > 0`` [s]: the sampled plant with zero-order-hold input, a discrete-time system
        (``dt = Ts``) whose update integrates the |v| form over one sample with scipy
        ``solve_ivp``; python-control cannot interconnect a continuous plant with a discrete
        controller, so this is how its ``input_output_response`` runs a sampled-data loop.
    solve_ivp_kwargs : dict, optional
        Only with ``Ts``: options of the per-sample ``solve_ivp`` (default ``method="RK45"``,
        ``rtol=1e-9``, ``atol`` = 1e-9 of the scales ``Fc/sigma``, ``Fc/sqrt(m sigma)``, ``Fc``).

    Returns
    -------
    control.NonlinearIOSystem
        States ``x`` [m], ``v`` [m/s], ``F`` [N]; input ``u`` [N]; output ``x`` [m].

    Notes
    -----
    Accuracy falls short of :func:`controllers.simulate_loop`: the |v| form is not smooth at
    ``v = 0`` and no reversal is located, so each reversal costs the integrator a local error
    that tolerances only partly control. For the continuous system pass state-scaled absolute
    tolerances to ``input_output_response(..., solve_ivp_kwargs={"rtol": ..., "atol": ...})``:
    the default ``atol = 1e-6`` is as large as the whole pre-sliding range ``Fc/sigma`` of a
    typical stage. python-control also interpolates a sampled input linearly (no zero-order
    hold): give it the reference, not a sampled force.
    """
    _check_system(system)
    rhs = _dahl_rhs(system)
    io = dict(inputs="u", outputs="x", states=["x", "v", "F"], name="stage")
    if Ts is None:
        if solve_ivp_kwargs is not None:
            raise TypeError("solve_ivp_kwargs is only used with Ts; for the continuous system pass it to "
                            "control.input_output_response")
        return control.nlsys(
            lambda t, x, u, params: rhs(x, float(u[0])),
            lambda t, x, u, params: x[:1],
            **io,
        )
    Ts = check_positive("Ts", Ts)
    sc = Scales.of(system)
    opts: dict[str, Any] = {"method": "RK45", "rtol": 1e-9, "atol": 1e-9 * np.array([sc.x, sc.v, sc.F])}
    if solve_ivp_kwargs is not None:
        opts.update(solve_ivp_kwargs)

    def update(t: float, x: np.ndarray, u: np.ndarray, params: Any) -> np.ndarray:
        uk = float(u[0])
        sol = solve_ivp(lambda _t, y: rhs(y, uk), (0.0, Ts), np.asarray(x, dtype=float), **opts)
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed in plant_iosys at t={t!r} s, state {x!r}: {sol.message}")
        return sol.y[:, -1]

    return control.nlsys(update, lambda t, x, u, params: x[:1], dt=Ts, **io)
