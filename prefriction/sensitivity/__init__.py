"""Sensitivities of the reversal table and of loop measures to model and controller parameters.

- :func:`sensitivities`: derivatives of ``(t_i, x_i, F_i)`` and, for a PID loop, of the
  residual error and the settling time, through CasADi forward sensitivities of each branch
  with the implicit-function correction at every reversal (:mod:`prefriction.sensitivity.flow`);
- :func:`exact_sensitivities`, :func:`map_derivative`: the closed form for the unforced Dahl
  oscillator with gamma = 1 (the exact map's derivative).

See ``docs/sensitivities.md``.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from prefriction._validation import check_count, check_finite, check_interval, check_positive
from prefriction.models import Oscillator, check_oscillator
from prefriction.sensitivity.exact import exact_sensitivities, map_derivative
from prefriction.sensitivity.flow import _PID, _value, run_flow, settling
from prefriction.sensitivity.result import Sensitivities

__all__ = ["Sensitivities", "exact_sensitivities", "map_derivative", "sensitivities"]

_MAX_REVERSALS = 2000  # each reversal is a CasADi integration with sensitivities


def sensitivities(system: Oscillator, v0: float = 0.0, *, reversals: Optional[int] = None,
                  parameters: Optional[Sequence[str]] = None, controller: Any = None,
                  reference: float = 0.0, t_end: Optional[float] = None, band: float = 0.02,
                  rtol: float = 1e-10) -> Sensitivities:
    """Derivatives of the reversal table and of a PID loop's residual error and settling time.

    Unforced (no ``controller``): ``reversals`` reversals from ``x = 0``, ``F = 0``, velocity
    ``v0``. Loop: the PID ``controller`` with the constant reference ``reference`` [m] from
    rest (``v0`` allowed) until ``t_end``. The reversals are first found by
    :func:`prefriction.simulate` (at ``rtol``), then each branch is integrated again with
    CasADi's ``cvodes`` and forward sensitivities, each reversal located by Newton on
    ``v = 0`` and differentiated by the implicit function theorem (``docs/sensitivities.md``).

    Parameters
    ----------
    system : Oscillator
        Mass and friction model without flags or model events (Dahl with gamma >= 1, LuGre);
        no input force.
    v0 : float, default 0.0
        Initial velocity [m/s] (nonzero for an unforced run).
    reversals : int, optional
        Number of reversals of an unforced run, ``1..2000``.
    parameters : sequence of str, optional
        Names to differentiate by: the model's fields (``model.parameters``), ``"mass"``,
        ``"v0"``, and for a loop ``"kp"``, ``"ki"``, ``"kd"``, ``"tau"``. Default: all of them.
    controller : controllers.PID, optional
        Continuous PID (no force limit).
    reference : float, default 0.0
        Constant reference [m] of the loop (a step at ``t = 0``), nonzero.
    t_end : float, optional
        End of the loop run [s] (required with ``controller``).
    band : float, default 0.02
        Settling band relative to the final displacement, ``0 < band < 1``.
    rtol : float, default 1e-10
        Tolerance of the simulation and of ``cvodes``, ``1e-13 <= rtol <= 1e-6``.

    Returns
    -------
    Sensitivities
        Values and derivatives (``summary()``, ``relative(name)``).

    Raises
    ------
    ValueError, TypeError
        Bad arguments, an unknown parameter name, a model with flags or events.
    prefriction.SolverError
        A reversal or the settling crossing could not be located.
    """
    from prefriction.simulation.feedback import LinearFeedback
    from prefriction.simulation.simulate import simulate

    model = check_oscillator(system, "sensitivities")
    if system.u is not None:
        raise ValueError("sensitivities: system must have no input force (system.u is None); use a controller for loops")
    if model.n_flags or model.n_events:
        raise ValueError(
            f"sensitivities supports friction models without flags or events (Dahl with gamma >= 1, LuGre), got "
            f"{type(model).__name__} with {model.n_flags} flags and {model.n_events} events"
        )
    v0 = check_finite("v0", v0)
    rtol = check_interval("rtol", rtol, 1e-13, 1e-6)
    band = check_interval("band", band, 0.0, 1.0)
    if band == 0.0:
        raise ValueError("band must lie in (0, 1] (a settling band of 0 is never entered: the settling time "
                         "would be t_end), got 0.0")
    fields = tuple(p.name for p in model.parameters)
    gains = _PID if controller is not None else ()
    if controller is not None and getattr(controller, "ki", None) == 0.0:
        gains = tuple(g for g in gains if g != "ki")  # a PD has no integrator state to perturb
        if parameters is not None and "ki" in parameters:
            raise ValueError("parameters: 'ki' needs a controller with an integrator (ki > 0); this PD controller "
                             f"has none, so its loop has no derivative with respect to ki; allowed: "
                             f"{fields + ('mass', 'v0') + gains}")
    allowed = fields + ("mass", "v0") + gains
    if isinstance(parameters, str):
        raise TypeError(f"parameters must be a sequence of names, e.g. ({parameters!r},), got the string {parameters!r}")
    names = tuple(allowed if parameters is None else parameters)
    if not names:
        raise ValueError(f"parameters must name at least one of {allowed}, got an empty sequence")
    for n in names:
        if n not in allowed:
            raise ValueError(f"parameters: unknown name {n!r}; allowed: {allowed}")
    if controller is None:
        if reversals is None or t_end is not None:
            raise ValueError("sensitivities: an unforced run needs reversals (and no t_end); a loop needs a controller")
        reversals = check_count("reversals", reversals)
        if reversals > _MAX_REVERSALS:
            raise ValueError(f"reversals must be <= {_MAX_REVERSALS}, got {reversals}")
        if v0 == 0.0:
            raise ValueError("v0 must be nonzero for an unforced run (at rest at F = 0 nothing moves), got 0.0")
        table = simulate(system, v0, reversals=reversals, rtol=rtol).reversals
        out = run_flow(system, v0, names, table.t, rtol=rtol)
    else:
        if getattr(controller, "u_max", None) is not None or not hasattr(controller, "kp"):
            raise TypeError(f"controller must be a controllers.PID without a force limit, got {controller!r}")
        reference = check_finite("reference", reference)
        if reference == 0.0:
            raise ValueError("reference must be nonzero (a step from rest), got 0.0")
        t_end = check_positive("t_end", t_end)
        C = controller.ss()
        fb = LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, reference=reference)
        grid = np.linspace(0.0, t_end, 4001)
        sim = simulate(system, v0, t_end=t_end, rtol=rtol, dense=grid, feedback=fb)
        if len(sim.reversals) > _MAX_REVERSALS:
            raise ValueError(f"the loop has {len(sim.reversals)} reversals, more than {_MAX_REVERSALS}: shorten t_end")
        out = run_flow(system, v0, names, sim.reversals.t, pid=controller, reference=reference, t_end=t_end, rtol=rtol)
    rows = out["rows"]
    d = out["d"]
    kw: dict = {}
    if controller is not None:
        yf, S_end = out["end"]
        sc = out["flow"].sc
        kw = {"t_end": t_end, "residual_error": reference - sc.x * yf[0], "d_residual_error": -sc.x * S_end[0]}
        xf = sim.x[-1]
        outside = np.nonzero(np.abs(sim.x - xf) > band * abs(xf))[0]
        if outside.size and outside[-1] + 1 < grid.size:
            ts, dts = settling(out, float(grid[outside[-1]]), band)
            kw.update(settling_time=ts, d_settling_time=dts)
    values = np.array([_value(system, controller, v0, n) for n in names])
    return Sensitivities(
        parameters=names, values=values, t=rows[:, 0], x=rows[:, 1], F=rows[:, 2],
        dt=np.array([r[0] for r in d]).reshape(-1, len(names)), dx=np.array([r[1] for r in d]).reshape(-1, len(names)),
        dF=np.array([r[2] for r in d]).reshape(-1, len(names)), **kw,
    )
