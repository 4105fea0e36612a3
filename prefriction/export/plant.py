"""The stage with friction over one sample period, every reversal located, as C99 (hardware in the loop).

The period is the one of the compiled sampled loop (:mod:`prefriction.simulation.loops`,
``docs/controllers.md#compiled-loop``): the force ``u`` [N] held over ``[t_k, t_k + Ts]``, a mass
at rest that the net force moves leaves rest (a reversal if it leaves backwards), and CasADi's
``erk`` integrator of the event-locating plant (:func:`prefriction.simulation.plant.build_integrator`)
carries ``m x'' = u - F`` over the period with each reversal and model event located.

Two forms of one period: :func:`plant_function` is CasADi's ``erk`` integrator of it (the period
stops after two reversals, the plant's register; :func:`prefriction.export.evaluate_plant` runs
it), and :func:`plant_source` writes the simulator's own native driver
(:mod:`prefriction.export.native_plant`: the same Dormand-Prince 5(4) with dense-output event
location, the step size carried from period to period) with the system's numbers as constants;
it resolves up to ``CAP`` (48) reversals per period and reports more as status 1 (a shorter
``Ts``, or a model stiffer than the loop can follow, is the cure: in a stable loop that does
not happen).
"""

from __future__ import annotations

from typing import Any, Optional

import casadi as ca
import numpy as np

from prefriction._safe_files import output_dir
from prefriction._validation import check_positive
from prefriction.models import Oscillator

from ._codegen import check_name, check_sample_time, comment_text, write_export
from .native_plant import CAP, plant_body, run_width
from .period import Period
from .source import CSource

__all__ = ["plant_function", "plant_initial_state", "plant_source"]

def _system(system: Any) -> Oscillator:
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator (mass and friction model), got {type(system).__name__}")
    if system.forced:
        raise ValueError("system must have no input force (system.u = None): the exported plant takes the force u "
                         "as its input at each sample")
    return system


def plant_function(system: Oscillator, Ts: float, *, rtol: float = 1e-8,
                   force_scale: Optional[float] = None) -> ca.Function:
    """The stage over one sample period with a held force, as a CasADi ``Function`` (module notes).

    ``(w, u, k) -> (w_next, y)``: the loop state ``w`` (normalised, :class:`prefriction.simulation.loops.compiled_loop.LoopLayout`),
    the force ``u`` [N] held over the period ``[k Ts, (k + 1) Ts]`` (``k`` the sample index), the
    state at its end and ``y = [x, v, F, reversals, complete]``: position [m], velocity [m/s] and
    friction force [N] at ``(k + 1) Ts``, the reversals in the period, and ``1`` if the period
    was integrated to its end (``0``: more than two reversals, the state is where the plant stopped).

    Parameters
    ----------
    system : prefriction.Oscillator
        Mass [kg] and friction model, without an input force.
    Ts : float
        Sample period [s], ``0 < Ts < inf``.
    rtol : float, default 1e-8
        Tolerance of the plant, as in :func:`prefriction.simulate`, ``0 < rtol < 1``.
    force_scale : float, optional
        Typical size of the applied force [N] (the error control is relative to the motion's
        amplitude, ``docs/simulator.md``); default the friction's ``Fc``.

    Returns
    -------
    casadi.Function
        The period (an ``MX`` Function around CasADi's ``erk`` integrator with events).

    Raises
    ------
    ValueError
        If ``Ts``, ``rtol`` or ``force_scale`` is out of range, or the system has an input force.
    TypeError
        If ``system`` is not a :class:`prefriction.Oscillator`.
    """
    return _period(system, Ts, rtol, force_scale).function()


def plant_initial_state(system: Oscillator, Ts: float, x0: float = 0.0, v0: float = 0.0, *, F0: float = 0.0,
                        rtol: float = 1e-8, force_scale: Optional[float] = None) -> np.ndarray:
    """The state ``w`` of :func:`plant_function` at ``t = 0`` (what ``<name>_reset`` sets).

    Parameters
    ----------
    system : prefriction.Oscillator
        Mass [kg] and friction model, without an input force.
    Ts : float
        Sample period [s].
    x0, v0 : float, default 0.0
        Initial position [m] and velocity [m/s].
    F0 : float, default 0.0
        Initial friction force [N] (the model's state at rest with that force).
    rtol, force_scale : float
        As in :func:`plant_function`.

    Returns
    -------
    numpy.ndarray
        The loop state (normalised).
    """
    return _period(system, Ts, rtol, force_scale).initial(float(x0), float(v0), float(F0))


def _period(system: Any, Ts: Any, rtol: Any, force_scale: Any) -> Period:
    system = _system(system)
    Ts = check_sample_time(Ts)
    rtol = check_positive("rtol", rtol)
    if not rtol < 1.0:
        raise ValueError(f"rtol must be in (0, 1), got {rtol!r}")
    scale = system.friction.Fc if force_scale is None else check_positive("force_scale", force_scale)
    return Period(system, Ts, rtol, scale)


_HEADER = """\
/* {name}.h: {what}.
 * Generated by prefriction.export.plant_source; C99, depends on libm only (link with -lm).
 *
 *   {name}_state s;
 *   {name}_reset(&s, x0, v0);        position x0 [m], velocity v0 [m/s] at t = 0
 *   status = {name}_step(&s, u);     hold the force u [N] over one period Ts = {Ts!r} s
 *   s.x, s.v, s.F                    position [m], velocity [m/s], friction force [N] after it
 *
 * status: 0 the period was integrated to its end; 1 the plant stopped after {cap} reversals
 * inside the period (s is where it stopped, not the period's end: use a shorter Ts);
 * 2 the integrator failed (s is unchanged).
 * The friction starts at F0 = {F0!r} N (fixed at export). s.w is the normalised loop state,
 * s.run the integrator's run state (the step size carried from period to period), s.k the
 * sample index, s.reversals the reversals in the last period.
 */
#ifndef {guard}
#define {guard}

#ifdef __cplusplus
extern "C" {{
#endif

typedef struct {{
  double w[{n}];
  double run[{nrun}];
  double k;
  double x, v, F;
  double reversals;
}} {name}_state;

void {name}_reset({name}_state *s, double x0, double v0);
int {name}_step({name}_state *s, double u);

#ifdef __cplusplus
}}
#endif

#endif
"""

_WRAPPER = """
/* ---- {name}: the interface around the generated period ---- */
#include "{name}.h"

void {name}_reset({name}_state *s, double x0, double v0) {{
  const double *arg[{sz_arg}];
  double *res[{sz_res}];
  long iw[{sz_iw0}];
  double work[{sz_w0}];
  double y[3];
  arg[0] = &x0;
  arg[1] = &v0;
  res[0] = s->w;
  res[1] = y;
  {name}_initial(arg, res, iw, work, 0);
  s->k = 0.0;
  s->x = y[0];
  s->v = y[1];
  s->F = y[2];
  s->reversals = 0.0;
}}

int {name}_step({name}_state *s, double u) {{
  long iw[{sz_iw1}];
  double work[{sz_w1}];
  const double *arg[{sz_arg1}];
  double *res[{sz_res1}];
  double next[{n}];
  double y[5];
  int i;
  arg[0] = s->w;
  arg[1] = &u;
  arg[2] = &s->k;
  res[0] = next;
  res[1] = y;
  if ({name}_period(arg, res, iw, work, 0) != 0) return 2;
  for (i = 0; i < {n}; ++i) s->w[i] = next[i];
  s->k += 1.0;
  s->x = y[0];
  s->v = y[1];
  s->F = y[2];
  s->reversals = y[3];
  return y[4] > 0.5 ? 0 : 1;
}}
"""


def plant_source(system: Oscillator, name: str, directory: Any, *, Ts: float, F0: float = 0.0, rtol: float = 1e-8,
                 force_scale: Optional[float] = None) -> CSource:
    """Write ``<name>.h`` and ``<name>.c``: the stage over one sample period, for hardware in the loop.

    The header defines ``<name>_state`` (the loop state ``w``, the integrator's run state
    ``run``, the sample index ``k`` and, after each period, ``x`` [m], ``v`` [m/s], ``F`` [N])
    and declares ``void <name>_reset(<name>_state *s, double x0, double v0)`` and
    ``int <name>_step(<name>_state *s, double u)``: the force ``u`` [N] held over one period
    ``Ts``, every reversal and model event located (module notes); it returns 0, or 1 if the
    period held more than ``CAP`` (48) reversals (the state is then where the plant stopped), or
    2 if the integrator failed (the state unchanged). The code is the simulator's native driver
    (:mod:`prefriction.export.native_plant`), the period of :func:`plant_function` integrated
    with the step size carried over; the numbers of the system are constants.

    Parameters
    ----------
    system : prefriction.Oscillator
        Mass [kg] and friction model, without an input force.
    name : str
        C identifier: the file names and the prefix of every symbol.
    directory : str or pathlib.Path
        Where to write the two files (created if missing).
    Ts : float
        Sample period [s], ``0 < Ts < inf``.
    F0 : float, default 0.0
        Friction force [N] of the state ``<name>_reset`` sets (fixed at export), within the
        model's ``max_hysteretic_force``.
    rtol : float, default 1e-8
        Tolerance of the plant, as in :func:`prefriction.simulate`.
    force_scale : float, optional
        Typical size of the applied force [N] (see :func:`plant_function`).

    Returns
    -------
    CSource
        The paths, the kind ``"plant"`` and the period Function the code came from.

    Raises
    ------
    ValueError
        If ``name`` is no C identifier or a number is out of its range.
    TypeError
        If ``system`` is not a :class:`prefriction.Oscillator` or ``directory`` is no path.
    """
    name = check_name(name)
    per = _period(system, Ts, rtol, force_scale)
    F0 = float(F0)
    if not abs(F0) <= system.friction.max_hysteretic_force:
        raise ValueError(f"F0 must be within +-{system.friction.max_hysteretic_force!r} N (the model's largest force "
                         f"at rest), got {F0!r}")
    fun = per.function()
    initial = _initial_function(per, F0)
    path = output_dir(directory)
    n = per.LL.nS
    what = comment_text(f"{type(system.friction).__name__} stage of {system.mass:.6g} kg, Ts = {Ts!r} s, "
                        f"rtol = {rtol!r}, period with every reversal located")
    header = _HEADER.format(name=name, what=what, Ts=Ts, cap=CAP, F0=F0, guard=f"{name.upper()}_H", n=n,
                            nrun=run_width(per))
    body = f'#include "{name}.h"\n' + plant_body(per, initial, per.cfg, name)
    h_path, c_path, digest = write_export(path, name, header, body)
    options = {"Ts": per.Ts, "F0": F0, "rtol": rtol, "force_scale": force_scale}
    return CSource(name, h_path, c_path, "plant", what, fun, n, system, options, digest)


def _initial_function(per: Period, F0: float) -> ca.Function:
    """``(x0, v0) -> (w, [x, v, F])``: the loop state at ``t = 0`` (the direction from the sign of
    ``v0``, else opposing ``F0``; at rest if ``v0 = 0``)."""
    x0, v0 = ca.SX.sym("x0"), ca.SX.sym("v0")
    states = {sgn: ca.DM(per.initial(0.0, sgn, F0)) for sgn in (-1.0, 1.0)}
    rest = ca.DM(per.initial(0.0, 0.0, F0))
    ix, sc = per.LL.state, per.sc
    w = ca.if_else(v0 > 0.0, states[1.0], ca.if_else(v0 < 0.0, states[-1.0], rest))
    w[ix["x"]] = x0 / sc.x
    w[ix["v"]] = v0 / sc.v
    return ca.Function("initial", [x0, v0], [w, ca.vertcat(*per.outputs(w))])
