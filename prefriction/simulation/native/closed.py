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
state is held to a force error of ``eps`` (``eps / |Cn_i|``), as in the CasADi plant. The run-time
numbers: :func:`prefriction.simulation.native.controller.controller_numbers`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Optional

from prefriction.models.base import FrictionModel
from prefriction.simulation.native.forced import ForcedDriver, forced_driver

if TYPE_CHECKING:
    from prefriction.simulation.plant import PlantSpec

__all__ = ["closed_driver"]


def closed_driver(model: FrictionModel, spec: "PlantSpec") -> tuple[Optional[ForcedDriver], float]:
    """The forced native driver of ``model`` with the continuous controller of ``spec``
    (``spec.fb == "continuous"``, ``spec.n_c`` states, the reference ``spec.r_sig``); an
    unforced system gets the zero input. ``(None, 0)`` where the native driver cannot be used."""
    from prefriction.signals import Constant, compiled_form

    u_sig = spec.u_sig if spec.u_sig is not None else compiled_form(Constant(0.0))
    return forced_driver(model, u_sig, spec.r_sig, spec.n_c)
