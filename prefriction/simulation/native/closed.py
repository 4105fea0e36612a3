"""Closed linear feedback on the forced native driver: a continuous controller in C.

A continuous :class:`~prefriction.simulation.feedback.LinearFeedback` (``Ts=None``) runs inside
``pf_forced_fb`` (forced.c, ``docs/simulator.md#native``): its states ``xc`` are integrated with
the plant by the same Runge-Kutta step, in SI units on normalised time,

    xc' = An xc + Bn e + kaw (u - w),   w = Cn xc + Dn e,   u = clip(w, -umax, umax),
    e = r(t) - x                                                     (normalised x, r, u)

with ``An = A t_unit``, ``Bn = B t_unit x_unit``, ``Cn = C / Fc``, ``Dn = D x_unit / Fc``,
``umax = u_max / Fc`` and ``kaw = k_aw t_unit Fc`` (the parameters of the CasADi plant,
:mod:`prefriction.simulation.plant`). While the mass rests the plant is frozen and the controller
keeps integrating; the end of the rest (``|u - F|`` above the rest threshold) and the clip's
switches (``w = +-umax``) are events located on the step's dense output. The error of a controller
state is held to a force error of ``eps`` (``eps / |Cn_i|``), as in the CasADi plant.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.simulation.native.forced import FHEAD, ForcedDriver, forced_driver

if TYPE_CHECKING:
    from prefriction.simulation.plant import PlantSpec
    from prefriction.simulation.run import Run

__all__ = ["closed_driver", "controller_numbers"]


def closed_driver(model: FrictionModel, spec: "PlantSpec") -> tuple[Optional[ForcedDriver], float]:
    """The forced native driver of ``model`` with the continuous controller of ``spec``
    (``spec.fb == "continuous"``, ``spec.n_c`` states, the reference ``spec.r_sig``); an
    unforced system gets the zero input. ``(None, 0)`` where the native driver cannot be used."""
    from prefriction.signals import Constant, compiled_form

    u_sig = spec.u_sig if spec.u_sig is not None else compiled_form(Constant(0.0))
    return forced_driver(model, u_sig, spec.r_sig, spec.n_c)


def controller_numbers(run: "Run", state: np.ndarray, pcr: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Write the controller states and the clip's mode of ``run`` into the driver's run state
    ``state`` and return the arguments ``fbp, thr, pcr`` of ``pf_forced_fb`` (``pcr``: the
    reference's per-interval numbers, rows as the input's)."""
    fb, sc, nc = run.fb, run.sc, run.spec.n_c
    k = FHEAD + run.model.n_states + run.model.n_flags
    state[k:k + nc] = np.asarray(run.st["xc"], dtype=float)
    state[k + nc] = run._clip_mode()
    Cn = fb.C[0] / sc.F
    xs = np.where(Cn != 0.0, 1.0 / np.where(Cn == 0.0, 1.0, np.abs(Cn)), 1.0)
    umax = 1e300 if fb.u_max is None else fb.u_max / sc.F
    fbp = np.concatenate(((fb.A * sc.t).ravel(), fb.B[:, 0] * sc.t * sc.x, Cn, [fb.D[0, 0] * sc.x / sc.F, umax],
                          fb.k_aw * sc.t * sc.F, xs))
    thr = np.ascontiguousarray(_params(run.spec.r_sig), dtype=float)
    return np.ascontiguousarray(fbp), thr if thr.size else np.zeros(1), np.ascontiguousarray(pcr, dtype=float)


def _params(sig: Any) -> np.ndarray:
    return np.zeros(0) if sig is None else np.asarray(sig.params(), dtype=float)
