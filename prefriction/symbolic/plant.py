"""The simulator's plant over one step as a CasADi Function: :func:`plant_step`."""

from __future__ import annotations

import math
from typing import Any, Optional

import casadi as ca
import numpy as np

from prefriction._validation import check_bool
from prefriction.errors import SolverError
from prefriction.models import FrictionModel, Oscillator
from prefriction.signals import Constant
from prefriction.simulation.compiled import compiled
from prefriction.simulation.simulate import _CAL  # eps = rtol * _CAL * sqrt(active / all states), as simulate
from prefriction.simulation.plant import EPS_TOUCH, Layout, PlantSpec, build_integrator, has_potential

__all__ = ["plant_step"]

_NSTOP = 1e9  # no reversal limit within a step
RTOL_RANGE = (1e-13, 1e-2)
"""The tolerances a numeric call of :func:`plant_step` accepts (as :func:`prefriction.simulate`)."""


class PlantStep(ca.Function):
    """The Function of :func:`plant_step`; a call with numbers has its arguments checked first.

    With numeric arguments (floats, lists, numpy arrays, ``DM``) a state of the wrong size or
    with a non-finite entry, non-finite numbers ``q`` or force ``u``, a step ``h`` that is
    negative or not finite, or ``rtol`` outside :data:`RTOL_RANGE` is a ``ValueError`` naming
    the argument, and an integrator failure inside the step (e.g. more events than one step
    can hold) a :class:`prefriction.SolverError` saying what helps. Symbolic calls (``SX``,
    ``MX``, inside an NLP) go to CasADi unchanged.
    """

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        values = _numbers(self, args, kwargs)
        if values is None:
            return super().__call__(*args, **kwargs)
        _check_call(values, self.size1_in(0), self.size1_in(1))
        try:
            return super().__call__(*args, **kwargs)
        except RuntimeError as exc:
            last = str(exc).strip().splitlines()[-1]
            raise SolverError(
                f"plant_step failed inside the step of h = {values['h']!r} (normalised time) from y0 = "
                f"{np.asarray(values['y0']).ravel().tolist()!r}: {last}. Take shorter steps (a step holds at most a "
                f"few reversals and model events; a half-period of the free motion is about pi) or a looser rtol"
            ) from exc


def _numbers(fun: ca.Function, args: tuple, kwargs: dict) -> Optional[dict]:
    """The arguments of a call by name as float arrays, or None if any is symbolic or not a number."""
    names = fun.name_in()
    if kwargs and (args or set(kwargs) - set(names)):
        return None
    given = dict(zip(names, args)) if args else kwargs
    if len(given) != len(names):
        return None
    out = {}
    for name, value in given.items():
        if isinstance(value, (ca.SX, ca.MX)) or (isinstance(value, (list, tuple))
                                                 and any(isinstance(v, (ca.SX, ca.MX)) for v in value)):
            return None
        try:
            out[name] = np.asarray(value.full() if isinstance(value, ca.DM) else value, dtype=float)
        except (TypeError, ValueError):
            return None
    return out


def _check_call(values: dict, n_y: int, n_q: int) -> None:
    """``ValueError`` naming the first argument of a numeric :class:`PlantStep` call out of its range."""
    y0, q = values["y0"].ravel(), values["q"].ravel()
    if y0.size != n_y or not np.all(np.isfinite(y0)):
        raise ValueError(f"y0 must be {n_y} finite numbers [x~, v~, z..., s, m...], got {y0.tolist()!r}")
    if q.size != n_q or not np.all(np.isfinite(q)):
        raise ValueError(f"q must be the model's {n_q} finite run-time numbers, got {q.tolist()!r}")
    for name in ("u", "h", "rtol"):
        if values[name].size != 1:
            raise ValueError(f"{name} must be one number, got {values[name].ravel().tolist()!r}")
    u, h, rtol = (float(values[k].ravel()[0]) for k in ("u", "h", "rtol"))
    if not math.isfinite(u):
        raise ValueError(f"u must be a finite normalised force (u [N] / Fc), got {u!r}")
    if not (math.isfinite(h) and h >= 0.0):
        raise ValueError(f"h must be a finite step >= 0 (normalised time), got {h!r}")
    if not RTOL_RANGE[0] <= rtol <= RTOL_RANGE[1]:
        raise ValueError(f"rtol must lie in [{RTOL_RANGE[0]:g}, {RTOL_RANGE[1]:g}], got {rtol!r}")


def plant_step(model: Any, *, jit: bool = False) -> ca.Function:
    """The compiled plant of :func:`prefriction.simulate` over one step of constant force, as a
    CasADi Function: every reversal and model event inside the step is located and handled.

    The Function works in the normalised units of :class:`prefriction.Scales`
    (``x~ = x sigma / Fc``, ``v~ = v sqrt(m sigma) / Fc``, ``F~ = F / Fc``,
    ``t~ = t sqrt(sigma / m)``) and is built once per model *structure*: the model's numbers,
    the force, the step and the tolerance are all run-time inputs::

        y1, reversals, ok = step(y0, q, u, h, rtol)

    - ``y0``, ``y1``: the state ``[x~, v~, z..., s, m...]`` at the start and the end of the
      step: position, velocity, the model's continuous states ``z`` (``n_states``), the branch
      direction ``s = +-1`` and the model's flags ``m`` (``n_flags``). A state at a force
      ``F0`` [N] at rest is ``model.initial_state(F0 / Fc, s)``;
    - ``q``: the model's run-time numbers, ``model.runtime_params_for(pf.Scales.of(system))``;
    - ``u``: the applied force over the step, normalised (``u [N] / Fc``);
    - ``h``: the duration of the step, normalised (``h [s] / sqrt(m / sigma)``), ``>= 0``;
    - ``rtol``: the tolerance, relative to the motion (as ``simulate``'s ``rtol``);
    - ``reversals``: the number of velocity reversals inside the step;
    - ``ok``: 1, or 0 if the velocity changed sign twice inside one integrator step (the state
      is then that at the least speed, not at ``h``: take shorter steps).

    A mass at rest (``v~ = 0``) whose net force ``|u~ - F~|`` is below the touch threshold
    stays at rest. It can be called with numbers, ``SX`` or ``MX`` (inside an NLP): CasADi
    differentiates the integrator through its forward sensitivities.

    Parameters
    ----------
    model : FrictionModel or Oscillator
        The friction model (of a system: its friction model).
    jit : bool, default False
        Compile the Function with gcc (cached on disk like the simulator's plants) for fast
        numeric calls, e.g. a hardware-in-the-loop or Monte Carlo loop. A compiled Function has
        no derivatives: keep ``jit=False`` inside an NLP.

    Returns
    -------
    casadi.Function
        ``plant_step(y0, q, u, h, rtol) -> (y1, reversals, ok)`` (a :class:`PlantStep`: numeric
        calls are checked, ``ValueError`` naming an argument out of range).

    Examples
    --------
    >>> import prefriction as pf
    >>> step = pf.symbolic.plant_step(pf.Dahl(sigma=1e4, Fc=1.0))
    >>> y1, n, ok = step([0.0, 1.0, 0.0, 1.0], [1.0], 0.0, 3.0, 1e-10)   # v~ = 1, no force, t~ = 3
    >>> int(n), int(ok)                                                   # one reversal on the way
    (1, 1)
    """
    if isinstance(model, Oscillator):
        model = model.friction
    if not isinstance(model, FrictionModel):
        raise TypeError(f"model must be a prefriction.FrictionModel or Oscillator, got {model!r} of type "
                        f"{type(model).__name__}")
    spec = PlantSpec.of(model, Constant(0.0), K=2, n_out=1, method="erk")
    L = Layout(spec)
    integ = build_integrator(spec)
    nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
    y0, q = ca.MX.sym("y0", 3 + nz + nm), ca.MX.sym("q", nq)
    u, h, rtol = ca.MX.sym("u"), ca.MX.sym("h"), ca.MX.sym("rtol")
    x, v, s = y0[0], y0[1], y0[2 + nz]
    z = [y0[2 + i] for i in range(nz)]
    m = [y0[3 + nz + i] for i in range(nm)]
    F = model.force(z, m, v, s, q)
    # states scaled by the amplitude of the motion times the tolerance (absolute error control,
    # docs/simulator.md); the scales are constants for differentiation (the result does not depend
    # on them, and the amplitude's kink at rest would give NaN derivatives)
    A = ca.stop_diff(ca.fmax(ca.fmax(ca.sqrt(v * v + F * F), ca.fabs(u)), 1e-150), 1)
    eps = ca.stop_diff(rtol, 1) * _CAL * math.sqrt(L.n_active / L.nx)
    scale = {"Ax": eps * ca.fmax(ca.fmax(A, 0.5 * A * A), ca.stop_diff(ca.fmin(ca.fabs(x), 1.0), 1)), "Av": eps * A,
             "AF": eps * ca.fmin(A, 1.0), "AE": eps * A * A}
    st = {"xh": 0.0, "vh": v / scale["Av"], "s": s, "n": 0.0, "armed": 1.0, "Wh": 0.0, "tmiss": 0.0,
          "rest": ca.if_else(ca.logic_and(v == 0.0, ca.fabs(u - F) <= EPS_TOUCH * scale["Av"]), 1.0, 0.0)}
    st.update({f"z{i}": z[i] / scale["AF"] for i in range(nz)})
    st.update({f"m{i}": m[i] for i in range(nm)})
    potential = has_potential(model)
    if potential:  # the branch's mechanical energy from here (the speed at model events)
        st["Ebh"] = (0.5 * v * v + model.branch_potential(z, m, s, q)) / scale["AE"]
    X0 = ca.vertcat(*[st.get(name, 0.0) for name in sorted(L.state, key=L.state.get)], ca.MX.zeros(L.nx - len(L.state)))
    par = dict(scale, xref=x, Efref=0.0, nstop=_NSTOP, snap=rtol, tunit=1.0, xunit=1.0, Fc=1.0, eps=eps, ecorr=1.0)
    P = ca.vertcat(*[par[name] for name in sorted(L.param, key=L.param.get)], q, ca.MX.zeros(L.np - L.q.stop))
    ctl = {"dur": h, "t0": 0.0}
    U = ca.vertcat(*[ctl[name] for name in sorted(L.control, key=L.control.get)], 0.0, u, 0.0)
    Xf = integ(x0=X0, p=P, u=U)["xf"]
    out = {k: Xf[i] for k, i in L.state.items()}
    y1 = ca.vertcat(x + scale["Ax"] * out["xh"], scale["Av"] * out["vh"], *[scale["AF"] * out[f"z{i}"] for i in range(nz)],
                    out["s"], *[out[f"m{i}"] for i in range(nm)])
    ok = ca.if_else(out["tmiss"] > 0.5, 0.0, 1.0)
    fun = ca.Function("plant_step", [y0, q, u, h, rtol], [y1, out["n"], ok],
                      ["y0", "q", "u", "h", "rtol"], ["y1", "reversals", "ok"])
    if not check_bool("jit", jit):
        return PlantStep(fun)
    return PlantStep(compiled(fun, f"{type(model).__name__} plant over a step")[0])
