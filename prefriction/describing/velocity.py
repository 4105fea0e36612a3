"""Friction as a nonlinearity of the velocity: ``F = N_v(A_v, omega) v`` in a positioning loop.

The input of a dynamic friction model such as LuGre is the velocity. With ``m x'' = u - F`` and
``u = -C(s) x`` (deviations about the set point), the velocity obeys ``v = -G(s) F`` with

    ``G(s) = s / (m s^2 + C(s))``; for a PID ``G(s) = s^2 / (m s^3 + kd s^2 + kp s + ki)``,

so the friction block sits in negative feedback around ``G``. Its describing function for the
velocity input ``v = A_v sin(omega t)`` follows from the displacement one of
:func:`prefriction.describing.friction_describing_function` (``x = -(A_v / omega) cos(omega t)``):

    ``N_v(A_v, omega) = N_x(A_v / omega, omega) / (i omega)``.

``Re N_v`` is the equivalent damping [N s/m] (the energy dissipated per cycle is
``pi A_v^2 Re N_v / omega``), ``-omega Im N_v`` the equivalent stiffness [N/m]. The harmonic
balance ``1 + G(i omega) N_v = 0`` is the same equation as ``1 + H(i omega) N_x = 0`` of
:func:`prefriction.describing.friction_loop`; only the picture changes
(``docs/describing.md#velocity``).
"""

from __future__ import annotations

from typing import Any, Optional

import control
import numpy as np

from prefriction.describing.cycle import friction_describing_function
from prefriction.describing.dahl import dahl_describing_function
from prefriction.describing.nonlinearity import BLOCK_OPTIONS, _Block
from prefriction.models import Dahl, Oscillator, check_oscillator

__all__ = ["VelocityDescribingFunction", "controller_tf", "velocity_loop"]


def controller_tf(controller: Any) -> control.TransferFunction:
    """Continuous SISO transfer function of ``controller`` (anything with ``.tf()`` or an LTI)."""
    if hasattr(controller, "tf") and not isinstance(controller, control.LTI):
        C = controller.tf()
    elif isinstance(controller, control.LTI):
        C = control.tf(controller)
    else:
        raise TypeError(f"controller must be a controllers.PID or a python-control LTI object, got {controller!r}")
    if not C.isctime() or C.ninputs != 1 or C.noutputs != 1:
        raise ValueError(f"controller must be continuous-time and SISO, got dt = {C.dt!r}, "
                         f"{C.ninputs} inputs, {C.noutputs} outputs")
    return C


def velocity_loop(system: Oscillator, controller: Any) -> control.TransferFunction:
    """``G(s) = s / (m s^2 + C(s))`` [m/(N s)]: friction force to velocity in the loop ``u = -C x``.

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model.
    controller : controllers.PID or control.LTI
        Continuous SISO controller from the position error [m] to the force [N].

    Returns
    -------
    control.TransferFunction
        ``G`` with input ``F`` [N] and output ``v`` [m/s]; the loop is ``v = -G F``.
    """
    check_oscillator(system, "velocity_loop")
    C = controller_tf(controller)
    num, den = np.asarray(C.num[0][0], float), np.asarray(C.den[0][0], float)
    return control.tf(np.polymul(den, [1.0, 0.0]), np.polyadd(np.polymul([system.mass, 0.0, 0.0], den), num),
                      inputs="F", outputs="v", name="G")


class VelocityDescribingFunction(_Block):
    """Friction model alone, velocity in [m/s], force out [N]: ``N_v(A_v, omega)`` [N s/m].

    Evaluated from the settled displacement cycle, ``N_v = N_x(A_v / omega, omega) / (i omega)``
    (Dahl with gamma = 1 in closed form, any other model by :func:`friction_describing_function`).
    Even a rate-independent model has a frequency-dependent ``N_v``, so the block always
    needs ``omega``; :func:`prefriction.describing.predict_limit_cycle` iterates on it. In the loop
    ``u = -C(s) x`` it sits in negative feedback around :func:`velocity_loop`.

    Parameters
    ----------
    system : Oscillator
        Mass [kg] (fixes the units of mass-dependent models) and friction model.
    omega : float, optional
        Angular frequency [rad/s]; required before evaluating (or use ``.at(omega)``).
    **options
        Passed to :func:`friction_describing_function` (``rtol``, ``tol``, ``max_cycles``, ``method``);
        defaults ``BLOCK_OPTIONS`` (``rtol=1e-8, tol=1e-6``).
    """

    def __init__(self, system: Oscillator, omega: Optional[float] = None, **options: Any) -> None:
        super().__init__(system, omega, options)
        f = system.friction
        self._closed = isinstance(f, Dahl) and f.gamma == 1.0 and not options

    def _evaluate(self, A: float) -> complex:
        w = self._need_omega()
        f = self.system.friction
        if self._closed:
            Nx = complex(dahl_describing_function(A / w, f.sigma, f.Fc))
        else:
            Nx = friction_describing_function(self.system, A / w, w, **{**BLOCK_OPTIONS, **self._options})
        return Nx / (1j * w)
