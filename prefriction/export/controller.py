"""A compensated positioning controller at a fixed sample time, as C99.

One sample of the sampled loop of :func:`prefriction.controllers.simulate_loop` on the
controller's side (``docs/controllers.md#compiled-loop``): from the measured position ``y_k``
[m] and the reference samples ``r_k, r_{k+1}`` [m], ``r'_k, r'_{k+1}`` [m/s],

- the error ``e_k = r_k - y_k``, the linear controller's output ``v_k = C xc_k + D e_k`` [N]
  (the controller discretised with ``control.c2d`` as ``simulate_loop`` does);
- the compensator's force ``c_k`` (its per-sample update, ``(state, [y_k, u_{k-1}],
  [r_k, r_{k+1}, r'_k, r'_{k+1}], numbers) -> (state_next, c_k)``);
- the applied force ``u_k = clip(v_k + c_k, -u_max, u_max)`` [N], held over the period;
- the update ``xc_{k+1} = A xc_k + B e_k + Ts k_aw (u_k - v_k - c_k)`` (back-calculation
  anti-windup of a :class:`prefriction.controllers.PID` with ``u_max``).

The numbers (controller matrices, compensator numbers, limits) are constants of the code.
"""

from __future__ import annotations

from typing import Any, Optional

import casadi as ca
import numpy as np

from prefriction._safe_files import output_dir
from prefriction._validation import check_finite, check_positive

from ._codegen import c_text, check_name, check_sample_time, comment_text, work_sizes, write_export
from .source import CSource

__all__ = ["controller_function", "controller_initial_state", "controller_source"]


class _Law:
    """The discretised controller, its limit and the compensator's numbers (module notes)."""

    def __init__(self, controller: Any, Ts: float, compensator: Any, mass: Optional[float], x0: float,
                 discretization: str) -> None:
        import control

        from prefriction.controllers._linear import _sample_time, as_lti
        from prefriction.controllers._pid import PID

        C = as_lti(controller)
        dt = _sample_time(C)
        if dt is None:
            C = control.c2d(C, Ts, method=discretization)
        elif not abs(dt - Ts) <= 1e-12 * Ts:
            raise ValueError(f"Ts={Ts!r} differs from the discrete controller's sample time dt={dt!r}")
        self.A, self.B = np.atleast_2d(C.A), np.atleast_2d(C.B)
        self.C, self.D = np.atleast_2d(C.C), float(np.atleast_2d(C.D)[0, 0])
        self.n = self.A.shape[0] if self.A.size else 0
        pid = isinstance(controller, PID)
        self.u_max = controller.u_max if pid and controller.u_max is not None else None
        self.k_aw = controller.back_calculation_gain() if self.u_max is not None else np.zeros(self.n)
        self.Ts = Ts
        self.comp = compensator
        if compensator is not None:
            if not (hasattr(compensator, "update_function") and hasattr(compensator, "numbers")):
                raise TypeError(f"compensator must be a controllers compensator (Feedforward, LuGreObserver, "
                                f"FrictionObserver, DisturbanceObserver), got {type(compensator).__name__}")
            if mass is None:
                raise ValueError("mass [kg] is required with a compensator (its inertia term and observer model), "
                                 "0 < mass < inf")
            params, state0 = compensator.numbers(mass, Ts, x0)
            self.c_params = np.asarray(params, dtype=float).ravel()
            self.c_state0 = np.asarray(state0, dtype=float).ravel()
        else:
            self.c_params, self.c_state0 = np.zeros(0), np.zeros(0)

    @property
    def n_state(self) -> int:
        return self.n + self.c_state0.size + 1

    def function(self) -> ca.Function:
        """``(w, y, ref) -> (w_next, u)`` with ``w = [xc, c, u_prev]``, ``ref = [r_k, r_{k+1}, r'_k, r'_{k+1}]``."""
        n, nc = self.n, self.c_state0.size
        w, y, ref = ca.SX.sym("w", self.n_state), ca.SX.sym("y"), ca.SX.sym("ref", 4)
        xc, cs, u_prev = w[:n], w[n:n + nc], w[n + nc]
        if self.comp is not None:
            cs_next, comp = self.comp.update_function()(cs, ca.vertcat(y, u_prev), ref, ca.DM(self.c_params))
        else:
            cs_next, comp = cs, 0.0
        e = ref[0] - y
        raw = (ca.mtimes(ca.DM(self.C), xc) if n else 0.0) + self.D * e + comp
        u = raw if self.u_max is None else ca.fmin(ca.fmax(raw, -self.u_max), self.u_max)
        parts = []
        if n:
            parts.append(ca.mtimes(ca.DM(self.A), xc) + ca.DM(self.B) * e + self.Ts * ca.DM(self.k_aw) * (u - raw))
        parts += [cs_next, u]
        return ca.Function("controller", [w, y, ref], [ca.vertcat(*parts), u], ["w", "y", "ref"], ["w_next", "u"])

    def initial(self) -> np.ndarray:
        return np.concatenate([np.zeros(self.n), self.c_state0, [0.0]])


def _law(controller: Any, Ts: Any, compensator: Any, mass: Any, x0: Any, discretization: Any) -> _Law:
    Ts = check_sample_time(Ts)
    if mass is not None:
        mass = check_positive("mass", mass)
    x0 = check_finite("x0", x0)
    if discretization not in ("zoh", "foh", "tustin", "bilinear", "euler", "backward_diff", "gbt", "impulse", "matched"):
        raise ValueError(f"discretization must be a control.c2d method such as 'zoh' or 'tustin', got {discretization!r}")
    return _Law(controller, Ts, compensator, mass, x0, discretization)


def controller_function(controller: Any, *, Ts: float, compensator: Any = None, mass: Optional[float] = None,
                        x0: float = 0.0, discretization: str = "zoh") -> ca.Function:
    """One sample of the compensated controller as a CasADi ``Function`` (module notes).

    ``(w, y, ref) -> (w_next, u)``: the state ``w = [xc, c, u_prev]`` (controller states,
    compensator states, the force applied over the previous period [N]), the measured position
    ``y`` [m], the reference samples ``ref = [r_k, r_{k+1}, r'_k, r'_{k+1}]`` [m, m, m/s, m/s], the
    next state and the force ``u`` [N] to hold over the period.

    Parameters
    ----------
    controller : controllers.PID or control.TransferFunction or control.StateSpace
        From the error [m] to the force [N]; a continuous one is discretised with
        ``control.c2d(controller, Ts, method=discretization)``, a discrete one must have ``dt = Ts``.
        A :class:`prefriction.controllers.PID` with ``u_max`` limits the force with back-calculation.
    Ts : float
        Sample time [s], ``0 < Ts < inf``.
    compensator : controllers compensator, optional
        ``Feedforward``, ``LuGreObserver``, ``FrictionObserver`` or ``DisturbanceObserver``
        (``docs/compensation.md``); ``None``: the controller alone.
    mass : float, optional
        Stage mass [kg] the compensator's numbers use; required with a compensator.
    x0 : float, default 0.0
        Initial position [m] of the stage (at rest), for the compensator's initial state.
    discretization : str, default "zoh"
        ``control.c2d`` method for a continuous controller.

    Returns
    -------
    casadi.Function
        ``(w, y, ref) -> (w_next, u)``, an ``SX`` Function with the numbers as constants.

    Raises
    ------
    ValueError
        If ``Ts``, ``mass`` or ``discretization`` is out of range, or a compensator is given without ``mass``.
    TypeError
        If ``controller`` or ``compensator`` is of no accepted kind.
    """
    return _law(controller, Ts, compensator, mass, x0, discretization).function()


def controller_initial_state(controller: Any, *, Ts: float, compensator: Any = None, mass: Optional[float] = None,
                             x0: float = 0.0, discretization: str = "zoh") -> np.ndarray:
    """The state ``w`` of :func:`controller_function` at the start (what ``<name>_reset`` sets).

    Parameters
    ----------
    controller, Ts, compensator, mass, x0, discretization
        As for :func:`controller_function`.

    Returns
    -------
    numpy.ndarray
        Zero controller states, the compensator's initial state, ``u_prev = 0``.
    """
    return _law(controller, Ts, compensator, mass, x0, discretization).initial()


_HEADER = """\
/* {name}.h: {what}.
 * Generated by prefriction.export.controller_source; C99, depends on libm only (link with -lm).
 *
 *   {name}_state s;
 *   {name}_reset(&s);                                      initial state (stage at rest at x0 = {x0!r} m)
 *   u = {name}_update(&s, y, r, r_next, v_ref, v_ref_next);
 *
 * Once per sample period Ts = {Ts!r} s: the measured position y [m], the reference r [m] at
 * this sample and r_next at the next one, its velocity v_ref, v_ref_next [m/s]; returns the
 * force u [N] to hold until the next sample{limit}.
 */
#ifndef {guard}
#define {guard}

#ifdef __cplusplus
extern "C" {{
#endif

typedef struct {{
  double w[{n}];
}} {name}_state;

void {name}_reset({name}_state *s);
double {name}_update({name}_state *s, double y, double r, double r_next, double v_ref, double v_ref_next);

#ifdef __cplusplus
}}
#endif

#endif
"""

_WRAPPER = """
/* ---- {name}: the interface around the generated sample ---- */
#include "{name}.h"

static const double {name}_initial[{n}] = {{{initial}}};

void {name}_reset({name}_state *s) {{
  int i;
  for (i = 0; i < {n}; ++i) s->w[i] = {name}_initial[i];
}}

double {name}_update({name}_state *s, double y, double r, double r_next, double v_ref, double v_ref_next) {{
  const double *arg[{sz_arg}];
  double *res[{sz_res}];
  long iw[{sz_iw}];
  double work[{sz_w}];
  double next[{n}];
  double ref[4];
  double u = 0.0;
  int i;
  ref[0] = r;
  ref[1] = r_next;
  ref[2] = v_ref;
  ref[3] = v_ref_next;
  arg[0] = s->w;
  arg[1] = &y;
  arg[2] = ref;
  res[0] = next;
  res[1] = &u;
  {name}_sample(arg, res, iw, work, 0);
  for (i = 0; i < {n}; ++i) s->w[i] = next[i];
  return u;
}}
"""


def controller_source(controller: Any, name: str, directory: Any, *, Ts: float, compensator: Any = None,
                      mass: Optional[float] = None, x0: float = 0.0, discretization: str = "zoh") -> CSource:
    """Write ``<name>.h`` and ``<name>.c``: the compensated controller at a fixed sample time, in C99.

    The header defines ``<name>_state`` and declares ``void <name>_reset(<name>_state *s)`` and
    ``double <name>_update(<name>_state *s, double y, double r, double r_next, double v_ref,
    double v_ref_next)``, called once per sample with the measured position ``y`` [m] and the
    reference samples; it returns the force [N] to hold until the next sample, as the sampled
    loop of :func:`prefriction.controllers.simulate_loop` (with ``compensator=``) computes it.
    Generated from :func:`controller_function`.

    Parameters
    ----------
    controller : controllers.PID or control.TransferFunction or control.StateSpace
        See :func:`controller_function`.
    name : str
        C identifier: the file names and the prefix of every symbol.
    directory : str or pathlib.Path
        Where to write the two files (created if missing).
    Ts : float
        Sample time [s], ``0 < Ts < inf``.
    compensator : controllers compensator, optional
        See :func:`controller_function`.
    mass : float, optional
        Stage mass [kg]; required with a compensator.
    x0 : float, default 0.0
        Initial position [m] of the stage (the compensator's initial state, fixed at export).
    discretization : str, default "zoh"
        ``control.c2d`` method for a continuous controller.

    Returns
    -------
    CSource
        The paths, the kind ``"controller"`` and the Function the code came from.

    Raises
    ------
    ValueError
        If ``name`` is no C identifier or a number is out of range.
    TypeError
        If an argument is of no accepted kind.
    """
    name = check_name(name)
    law = _law(controller, Ts, compensator, mass, x0, discretization)
    fun = law.function()
    path = output_dir(directory)
    n = law.n_state
    sz = work_sizes(fun)
    comp = "no compensator" if compensator is None else type(compensator).__name__
    kind = str(controller) if "\n" not in str(controller) else f"{type(controller).__name__} of order {law.n}"
    what = comment_text(f"{kind} at Ts = {Ts!r} s with {comp}")
    limit = "" if law.u_max is None else f", limited to +-{law.u_max!r} N"
    header = _HEADER.format(name=name, what=what, x0=float(x0), Ts=Ts, limit=limit, guard=f"{name.upper()}_H", n=n)
    initial = ", ".join(repr(float(v)) for v in law.initial())
    body = c_text({f"{name}_sample": fun}, f"{name}_casadi") + _WRAPPER.format(
        name=name, n=n, initial=initial, sz_arg=max(sz[0], 3), sz_res=max(sz[1], 2), sz_iw=max(sz[2], 1),
        sz_w=max(sz[3], 1))
    h_path, c_path, digest = write_export(path, name, header, body)
    options = {"Ts": Ts, "compensator": compensator, "mass": mass, "x0": float(x0), "discretization": discretization}
    return CSource(name, h_path, c_path, "controller", what, fun, n, controller, options, digest)
