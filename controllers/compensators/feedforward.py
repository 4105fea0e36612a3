"""Model-based feedforward: the friction of an identified model along the reference motion, plus inertia."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Hashable

import casadi as ca
import numpy as np

from prefriction._validation import check_count
from prefriction.identify.stepping import interval_function
from prefriction.models import Oscillator
from prefriction.models.base import FrictionModel
from prefriction.units import Scales

from ._base import Compensator

__all__ = ["Feedforward"]


@dataclass(frozen=True)
class _Structure:
    """Compiled structure of a feedforward: the model's structure and the sub-steps."""

    model_key: Hashable
    n_sub: int
    model: FrictionModel = field(compare=False, hash=False, repr=False)

    @property
    def n_state(self) -> int:
        return self.model.n_states + self.model.n_flags + 2

    @property
    def n_param(self) -> int:
        return len(self.model.runtime_params()) + 5

    def function(self) -> ca.Function:
        model = self.model
        nX, nq = model.n_states + model.n_flags, len(model.runtime_params())
        c, meas, ref, p = (ca.SX.sym(n, k) for n, k in (("c", self.n_state), ("meas", 2), ("ref", 4),
                                                          ("par", self.n_param)))
        X, s_prev, F_k = c[:nX], c[nX], c[nX + 1]
        q = p[:nq]
        xunit, Funit, tunit, mass, Ts = (p[nq + i] for i in range(5))
        r, rn, vr, vrn = (ref[i] for i in range(4))
        vunit = xunit / tunit
        v = (rn - r) / Ts / vunit  # the mean velocity over [t_k, t_k+1] (normalised)
        s = ca.if_else(v > 0.0, 1.0, ca.if_else(v < 0.0, -1.0, s_prev))
        step = interval_function(model, self.n_sub)
        X_next, F_next = step(X, v, Ts / tunit, s_prev, s, vrn / vunit, q)
        force = mass * (vrn - vr) / Ts + Funit * 0.5 * (F_k + F_next)
        return ca.Function("feedforward", [c, meas, ref, p], [ca.vertcat(X_next, s, F_next), force])


@dataclass(frozen=True)
class Feedforward(Compensator):
    """Feedforward of the friction of ``model`` along the reference motion, plus inertia.

    The model is driven along the reference samples (the motion the stage should follow), one
    sample period at a time with :func:`prefriction.identify.stepping.interval_function`: over
    ``[t_k, t_{k+1}]`` the mean velocity ``(r_{k+1} - r_k) / Ts`` and the direction of motion
    (a reversal where it changes sign), the model's exact step (Dahl, Maxwell-slip, LuGre, GMS)
    or ``n_sub`` Runge-Kutta sub-steps for other models, events applied. The force held over
    the period is

        u_ff,k = m (r'_{k+1} - r'_k) / Ts + (F_k + F_{k+1}) / 2,

    the mean inertial force of the period (it gives the reference's velocity change exactly)
    and the trapezoidal mean of the model's friction ``F_k``, ``F_{k+1}`` along the reference
    at the two ends. On the nominal model and a well-sampled motion this is the force that
    moves the stage along the reference; the controller corrects what is left (sample-hold,
    model mismatch, disturbances). It uses no measurement: it cannot destabilise the loop.

    Parameters
    ----------
    model : FrictionModel
        The identified friction model (Dahl, LuGre, Maxwell-slip, GMS, ...), in SI units.
    n_sub : int, default 2
        Runge-Kutta sub-steps per sample period for models without an exact step,
        ``1 <= n_sub <= 64``.

    Examples
    --------
    >>> import prefriction as pf
    >>> from prefriction import controllers
    >>> ff = controllers.Feedforward(pf.Dahl(sigma=1e6, Fc=1.0))
    >>> params, state0 = ff.numbers(mass=1.0, Ts=1e-4, x0=0.0)
    >>> ff.update_function().n_in(), len(state0)
    (4, 3)
    """

    model: FrictionModel
    n_sub: int = 2

    def __post_init__(self) -> None:
        if not isinstance(self.model, FrictionModel):
            raise TypeError(f"model must be a prefriction friction model, got {self.model!r} of type "
                            f"{type(self.model).__name__}")
        object.__setattr__(self, "n_sub", check_count("n_sub", self.n_sub, 1, 64))

    def structure(self) -> _Structure:
        """The compiled structure: the model's structure key and ``n_sub``."""
        return _Structure(self.model.structure_key(), self.n_sub, self.model)

    def numbers(self, mass: float, Ts: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
        """``params = [q, Fc/sigma, Fc, sqrt(m/sigma), m, Ts]`` (the model's normalised numbers
        and units for the stage's mass) and the virgin state (no direction yet, zero force)."""
        sc = Scales.of(Oscillator(self.model, mass=mass))
        q = np.asarray(self.model.runtime_params_for(sc), dtype=float)
        z, m = self.model.initial_state(0.0, 1.0)
        params = np.concatenate([q, [sc.x, sc.F, sc.t, mass, Ts]])
        return params, np.array([*z, *m, 0.0, 0.0], dtype=float)

    def __str__(self) -> str:
        return f"Feedforward({type(self.model).__name__})"
