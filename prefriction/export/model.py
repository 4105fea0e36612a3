"""A friction model sampled along measured positions, as C99: ``force = <name>_force(state, x)``.

One call moves the model from the previous position to ``x`` [m] with the interval step of
:func:`prefriction.friction_along` and :class:`prefriction.FrictionStream`
(:func:`prefriction.along.step.interval_function`: the model's exact step at constant velocity
where it has one, Dahl, Maxwell-slip, LuGre, GMS, Viscous and sums; Runge-Kutta sub-steps
otherwise), at the constant velocity ``(x - x_prev) / Ts`` over the interval, and returns the
force at ``x`` (its rate-dependent part at that velocity, as ``friction_along`` by default). The interval's direction is the sign of ``x - x_prev`` (the previous one where
the position does not change, ``+1`` before the first move); a change of direction is a
reversal (the model's ``reverse``). Rate-dependent models (LuGre, GMS) need the fixed sample
time ``Ts``; rate-independent ones (Dahl, Maxwell-slip) depend on the positions alone.

Before the first move the state is virgin (force 0) and its force is returned unchanged, as
:class:`prefriction.FrictionStream` does; ``friction_along`` takes the rate-dependent part of
its first sample from the first interval's velocity, which a stream does not know yet.

The step is one CasADi ``SX`` Function (:func:`sample_function`) whose constants (the model's
parameters, the units, ``Ts``) are literals; :func:`c_source` writes its code with a small
wrapper that holds the state.
"""

from __future__ import annotations

import math
from typing import Any, Optional

import casadi as ca

from prefriction._safe_files import output_dir
from prefriction._validation import check_count
from prefriction.along.step import has_exact_step, interval_function
from prefriction.models.base import FrictionModel

from ._codegen import c_text, check_name, check_sample_time, comment_text, work_sizes, write_export
from .source import CSource

__all__ = ["c_source", "sample_function"]

MAX_SUBSTEPS = 64
"""Largest number of Runge-Kutta sub-steps per sample (as :func:`prefriction.friction_along`)."""


def _model(model: Any) -> FrictionModel:
    if not isinstance(model, FrictionModel):
        raise TypeError(f"model must be a prefriction.FrictionModel (Dahl, LuGre, MaxwellSlip, GMS, ...), "
                        f"got {type(model).__name__}")
    return model


def _sample_time(model: FrictionModel, Ts: Optional[float]) -> Optional[float]:
    if Ts is None:
        if not model.rate_independent:
            raise ValueError(
                f"Ts is required for {type(model).__name__}: the model is rate-dependent (its force depends on "
                f"the velocity, which the C code takes as (x - x_prev) / Ts); give the fixed sample time Ts "
                f"[s], 0 < Ts < inf"
            )
        return None
    return check_sample_time(Ts)


def sample_function(model: FrictionModel, *, Ts: Optional[float] = None, n_sub: int = 16) -> ca.Function:
    """The model's step from one measured position to the next, as a CasADi ``Function``.

    ``(w, x) -> (w_next, F)``: the state ``w = [z, m, s_prev, x_prev]`` (the model's normalised
    states ``z`` and flags ``m``, ``docs/models.md#state``; the direction of the last move,
    ``0`` before the first one; the last position [m]), the new position ``x`` [m], the state
    after the move and the friction force ``F`` [N] at ``x``. The model's numbers and ``Ts`` are
    constants of the Function. The C code of :func:`c_source` is generated from it.

    Parameters
    ----------
    model : FrictionModel
        Any model of the toolbox or a user model through the protocol.
    Ts : float, optional
        Fixed sample time [s], ``0 < Ts < inf``; required for rate-dependent models (LuGre, GMS),
        whose velocity over an interval is ``(x - x_prev) / Ts``. ``None`` for a rate-independent
        model: each interval then takes one time unit (the force depends on the positions alone).
    n_sub : int, default 16
        Runge-Kutta sub-steps per sample interval for a model without an exact step, 1 to 64
        (as ``substeps`` of :func:`prefriction.friction_along`); unused for the others.

    Returns
    -------
    casadi.Function
        ``(w, x) -> (w_next, F)``, an ``SX`` Function.

    Raises
    ------
    ValueError
        If ``Ts`` is missing for a rate-dependent model or not positive, or ``n_sub`` is out of range.
    TypeError
        If ``model`` is not a :class:`prefriction.FrictionModel`.
    """
    model = _model(model)
    Ts = _sample_time(model, Ts)
    n_sub = check_count("n_sub", n_sub, 1, MAX_SUBSTEPS, "Runge-Kutta sub-steps per sample")
    nz, nm = model.n_states, model.n_flags
    w = ca.SX.sym("w", nz + nm + 2)
    x = ca.SX.sym("x")
    X, s_prev, x_prev = w[: nz + nm], w[nz + nm], w[nz + nm + 1]
    dx = x - x_prev
    s_last = ca.if_else(s_prev == 0.0, 1.0, s_prev)
    s = ca.if_else(dx > 0.0, 1.0, ca.if_else(dx < 0.0, -1.0, s_last))
    if Ts is None:
        v, dt = dx * (model.sigma / model.Fc), 1.0    # normalised displacement in one time unit
    else:  # the units of a unit mass (runtime_params()), as friction_along computes them
        dt = Ts / (1.0 / math.sqrt(model.sigma))
        v = dx / Ts / (model.Fc / math.sqrt(model.sigma))
    step = interval_function(model, n_sub)
    X1, F = step(X, v, dt, s_prev, s, v, ca.DM(model.runtime_params()))
    w1 = ca.vertcat(X1, ca.if_else(dx == 0.0, s_prev, s), x)
    return ca.Function("sample", [w, x], [w1, model.Fc * F], ["w", "x"], ["w_next", "F"], {"cse": True})


def virgin_state(model: FrictionModel, x0: float) -> list[float]:
    """The state ``w`` of :func:`sample_function` for the virgin model at the position ``x0`` [m]."""
    z, m = model.initial_state(0.0, 1.0)
    return [*map(float, z), *map(float, m), 0.0, float(x0)]


_HEADER = """\
/* {name}.h: {what}.
 * Generated by prefriction.export.c_source; C99, depends on libm only (link with -lm).
 *
 *   {name}_state s;
 *   {name}_reset(&s, x0);            virgin state at the position x0 [m]
 *   F = {name}_force(&s, x);         move to the position x [m], the friction force F [N]
 *
 * {sampling}
 * The state: w[0..{nz1}] the model's normalised states and flags, w[{i_s}] the direction of the
 * last move (0 before the first), w[{i_x}] the last position [m].
 */
#ifndef {guard}
#define {guard}

#ifdef __cplusplus
extern "C" {{
#endif

typedef struct {{
  double w[{n}];
}} {name}_state;

void {name}_reset({name}_state *s, double x0);
double {name}_force({name}_state *s, double x);

#ifdef __cplusplus
}}
#endif

#endif
"""

_WRAPPER = """
/* ---- {name}: the fixed interface around the generated step ---- */
#include "{name}.h"

static const double {name}_virgin[{n}] = {{{virgin}}};

void {name}_reset({name}_state *s, double x0) {{
  int i;
  for (i = 0; i < {n}; ++i) s->w[i] = {name}_virgin[i];
  s->w[{i_x}] = x0;
}}

double {name}_force({name}_state *s, double x) {{
  const double *arg[{sz_arg}];
  double *res[{sz_res}];
  long iw[{sz_iw1}];
  double work[{sz_w1}];
  double next[{n}];
  double F = 0.0;
  int i;
  arg[0] = s->w;
  arg[1] = &x;
  res[0] = next;
  res[1] = &F;
  {step}(arg, res, iw, work, 0);
  for (i = 0; i < {n}; ++i) s->w[i] = next[i];
  return F;
}}
"""


def c_source(model: FrictionModel, name: str, directory: Any, *, Ts: Optional[float] = None,
             n_sub: int = 16) -> CSource:
    """Write ``<name>.h`` and ``<name>.c``: the model sampled along measured positions, in C99.

    The header defines ``typedef struct {...} <name>_state;`` and declares
    ``void <name>_reset(<name>_state *s, double x0)`` (the virgin state at the position ``x0``
    [m]) and ``double <name>_force(<name>_state *s, double x)`` (move to the position ``x`` [m],
    return the friction force [N]); the streaming form of the friction along a measured motion.
    The code is generated from :func:`sample_function` (CasADi's code generator), with the
    model's parameters and ``Ts`` as constants; it needs ``<math.h>`` and nothing else.

    Parameters
    ----------
    model : FrictionModel
        The friction model (its parameter values are written into the code).
    name : str
        C identifier: the file names and the prefix of every symbol.
    directory : str or pathlib.Path
        Where to write the two files (created if missing; existing files of that name are replaced).
    Ts : float, optional
        Fixed sample time [s]; required for rate-dependent models (LuGre, GMS), see :func:`sample_function`.
    n_sub : int, default 16
        Runge-Kutta sub-steps per sample for a model without an exact step (:func:`sample_function`).

    Returns
    -------
    CSource
        The paths, the kind ``"model"`` and the Function the code came from.

    Raises
    ------
    ValueError
        If ``name`` is no C identifier, ``Ts`` is missing for a rate-dependent model or not
        positive, or ``n_sub`` is out of range.
    TypeError
        If ``model`` is not a :class:`prefriction.FrictionModel` or ``directory`` is no path.
    """
    name = check_name(name)
    fun = sample_function(model, Ts=Ts, n_sub=n_sub)
    path = output_dir(directory)
    n = fun.size1_in(0)
    nz1 = model.n_states + model.n_flags - 1
    sz_arg, sz_res, sz_iw, sz_w = work_sizes(fun)
    step = f"{name}_step"
    sampling = (f"Sample time Ts = {Ts!r} s: the velocity over an interval is (x - x_prev) / Ts."
                if Ts is not None else "Rate-independent: the force depends on the positions alone.")
    stepping = "exact step" if has_exact_step(model) else f"{n_sub} RK4 sub-steps"
    what = comment_text(f"{_describe(model)}, {'Ts = %r s' % Ts if Ts is not None else 'rate-independent'}, {stepping}")
    header = _HEADER.format(name=name, what=what, sampling=sampling, nz1=nz1, i_s=n - 2, i_x=n - 1,
                            guard=f"{name.upper()}_H", n=n)
    virgin = ", ".join(repr(v) for v in virgin_state(model, 0.0))
    body = c_text({step: fun}, f"{name}_casadi") + _WRAPPER.format(
        name=name, n=n, virgin=virgin, i_x=n - 1, sz_arg=max(sz_arg, 2), sz_res=max(sz_res, 2),
        sz_iw1=max(sz_iw, 1), sz_w1=max(sz_w, 1), step=step)
    h_path, c_path, digest = write_export(path, name, header, body)
    return CSource(name, h_path, c_path, "model", what, fun, n, model, {"Ts": Ts, "n_sub": n_sub}, digest)


def _describe(model: FrictionModel) -> str:
    if not type(model).parameters:  # a sum of models: its own repr names the terms
        return repr(model)
    pars = ", ".join(f"{p.name}={_short(getattr(model, p.name))}" for p in type(model).parameters)
    return f"{type(model).__name__}({pars})"


def _short(value: Any) -> str:
    try:
        return f"{float(value):.6g}"
    except TypeError:
        return "[" + ", ".join(f"{float(v):.4g}" for v in value) + "]"
