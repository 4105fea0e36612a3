"""Dahl friction model (3.2) through the friction-model protocol::

    dF/dx = sigma (1 - s F / Fc)^gamma,   s = sign(x');   normalised: f' = s v (1 - f)^gamma, f = s F~

gamma is a run-time number of the compiled plant; the structure only distinguishes the
saturating case (gamma < 1: branch-distance state, a saturation event and flag) from
gamma >= 1 (log-gap state). See :class:`Dahl` and ``docs/models.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Hashable, Optional, Sequence

import casadi as ca
import numpy as np

from prefriction.models.dahl_branch import branch_potential
from prefriction.models.base import FrictionModel, Parameter
from prefriction.models.closed_form import exp, log1p_ratio, pick

__all__ = ["Dahl", "distance_of_log_gap", "force_of_p", "p_of_force"]

def _sym(*xs: Any) -> bool:
    """True if any argument is a CasADi symbol (floats take the fast numeric path)."""
    for x in xs:
        if type(x) is not float and isinstance(x, (ca.SX, ca.MX)):
            return True
    return False


def force_of_p(p: Any, gamma: Any) -> Any:
    """Normalised branch force ``f = s F / Fc`` at the branch distance ``p`` for gamma < 1
    (float or CasADi): ``f = 1 - (1 - e p)^(1/e)``, ``e = 1 - gamma > 0``.

    Past saturation ``p > 1 / e`` (before the event stops the force) ``f`` continues
    symbolically as ``1 - cos(pi / e) (e p - 1)^(1/e)``: the polynomial ``1 - (1 - e p)^(1/e)``
    where ``1/e`` is an integer (gamma = 0, 1/2, 2/3, ...), so the step across saturation keeps
    its order; floats return 1 there.
    """
    e = 1.0 - gamma
    q = e * p
    if _sym(p, gamma):
        # fmax: no branch force below -1 (|F| <= Fc; an unreachable state, e.g. a trial point of
        # a fit, would overflow for gamma near 1); fmin past saturation likewise
        inside = -ca.expm1(ca.log1p(-ca.fmin(ca.fmax(q, 1.0 - 2.0 ** e), 1.0 - 1e-16)) / e)
        # fmax: pow(0, y) with a symbolic y has a NaN derivative in y (log 0 * 0)
        past = 1.0 - ca.cos(math.pi / e) * ca.fmin(ca.fmax(q - 1.0, 1e-300), 1.0) ** (1.0 / e)
        return ca.if_else(q < 1.0, inside, past)
    if q >= 1.0:
        return 1.0
    return -math.expm1(math.log1p(-q) / e)


def p_of_force(f: Any, gamma: Any) -> Any:
    """Branch distance ``p = (1 - (1 - f)^e) / e`` of the branch force ``f`` for gamma < 1
    (inverse of :func:`force_of_p`; ``1 / e`` at saturation ``f >= 1``)."""
    e = 1.0 - gamma
    if _sym(f, gamma):  # if_else: log1p(-1) = -inf would make the derivative at saturation inf * 0
        return ca.if_else(f < 1.0, -ca.expm1(e * ca.log1p(-f)) / e, 1.0 / e)
    if f >= 1.0:
        return 1.0 / e
    return -math.expm1(e * math.log1p(-f)) / e


def distance_of_log_gap(L: float, gamma: float) -> float:
    """Branch distance ``p = (exp(k L) - 1) / k``, ``k = gamma - 1 >= 0``, of the log-gap
    ``L = -ln(1 - f)`` (``dp/dL = exp(k L)``; ``p = L`` for gamma = 1); floats."""
    k = gamma - 1.0
    return L if k == 0.0 else math.expm1(k * L) / k


@dataclass(frozen=True)
class Dahl(FrictionModel):
    """Dahl friction model (3.2): ``dF/dx = sigma * (1 - s F / Fc)^gamma``, ``s = sign(x')``.

    Parameters
    ----------
    sigma : float
        Rest stiffness [N/m], ``0 < sigma < inf``.
    Fc : float
        Coulomb friction force [N], ``0 < Fc < inf``; ``|F| <= Fc`` always.
    gamma : float, default 1.0
        Shape factor [-], ``0 <= gamma < inf``. ``gamma = 1`` is the form analysed in the
        paper (3.3)-(3.14); ``gamma = 0`` is the Prandtl stop (elastic-perfectly-plastic).

    Raises
    ------
    ValueError
        If ``sigma`` or ``Fc`` is not finite and positive, or ``gamma`` is negative or not finite.
    TypeError
        If an argument is not a real number.

    Notes
    -----
    Protocol (``docs/models.md``): one state. For gamma >= 1 the log-gap ``L = -ln(1 - f)``,
    ``f = s F / Fc = 1 - exp(-L)``, ``L' = s v exp(-(gamma - 1) L)`` (one ``expm1`` and one ``exp``
    per evaluation, full relative accuracy for small forces, no stiffness in gross sliding). For
    gamma < 1 the branch distance ``p`` (``p' = s v``), a flag ``sat`` (``|F| = Fc``, ``p' = 0``
    until the next reversal) and one event, saturation, with indicator ``1 - (1 - gamma) p``. A reversal keeps the force and recomputes ``p`` on the new
    branch; a reversal within ``snap`` of saturation is one at saturation (gamma = 0 reaches both
    at once in its undamped oscillation; resolving their order by round-off would bleed energy).
    Run-time number: ``q = [gamma]``.
    """

    sigma: float
    Fc: float
    gamma: float = 1.0

    parameters = (
        Parameter("sigma", "N/m", 0.0, math.inf, low_open=True),
        Parameter("Fc", "N", 0.0, math.inf, low_open=True),
        Parameter("gamma", "-", 0.0, math.inf),
    )
    rate_independent = True
    n_states = 1

    @property
    def saturates(self) -> bool:
        """True if a branch reaches ``|F| = Fc`` at a finite distance (gamma < 1)."""
        return self.gamma < 1.0

    @property
    def tracks_position(self) -> bool:  # type: ignore[override]
        """Without saturation ``x - x_start = s (p - p_start)`` on a branch."""
        return not self.saturates

    @property
    def n_flags(self) -> int:
        return 1 if self.saturates else 0

    @property
    def n_events(self) -> int:
        return 1 if self.saturates else 0

    def structure_key(self) -> Hashable:
        return ("Dahl", "gamma < 1, saturating" if self.saturates else "gamma >= 1")

    def runtime_params(self) -> np.ndarray:
        return np.array([self.gamma])

    def slope(self, f: Any) -> Any:
        """Normalised tangent stiffness ``(1 - f)^gamma`` (3.2) for ``f = s F / Fc <= 1``."""
        if self.gamma == 0.0:
            return 1.0 + 0.0 * f
        return (1.0 - f) ** self.gamma

    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        if s * f0 >= 1.0 and not self.saturates:
            raise ValueError(
                f"F0 = {f0 * self.Fc!r} is the Coulomb force Fc in the direction of motion, which the Dahl "
                f"branch reaches only asymptotically for gamma = {self.gamma!r} >= 1; use |F0| < Fc"
            )
        if self.saturates:
            sat = s * f0 >= 1.0
            return [p_of_force(min(s * f0, 1.0), self.gamma)], [1.0 if sat else 0.0]
        return [-math.log1p(-s * f0)], []

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        if self.saturates:
            return [s * v * (1.0 - m[0])]
        k = q[0] - 1.0  # dL/dx = (1 - f)^(gamma - 1) = exp(-(gamma - 1) L)
        return [s * v * (ca.exp(-k * z[0]) if _sym(z[0], k) else math.exp(-k * z[0]))]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        z0 = z[0]
        if self.saturates:
            return s * force_of_p(z0, q[0])
        return -s * (math.expm1(-z0) if type(z0) is float else ca.expm1(-z0))

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        if not self.saturates:
            return []
        ind = 1.0 - (1.0 - q[0]) * z[0]
        return [ca.if_else(m[0] > 0.5, 1.0, ind) if _sym(ind) else (1.0 if m[0] > 0.5 else ind)]

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        return [1.0 / (1.0 - q[0])], [1.0]

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        s_old = -s_new
        F = self.force(z, m, 0.0, s_old, q)
        if self.saturates:
            near = 1.0 - (1.0 - q[0]) * z[0] < snap
            F = ca.if_else(near, s_old, F) if _sym(F, near) else (s_old if near else F)
            return [p_of_force(s_new * F, q[0])], [0.0]
        return [-(math.log1p(-s_new * F) if type(F) is float else ca.log1p(-s_new * F))], []

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """Exact step over ``dt`` at the constant velocity ``v`` (``docs/along.md#exact-steps``).

        With the travel ``xi = s v dt`` along the branch: for gamma < 1 the branch distance
        ``p + xi``, stopped at saturation ``1 / (1 - gamma)`` (the event, located inside the
        interval); for gamma >= 1, ``dL/dxi = exp(-k L)`` (``k = gamma - 1``) gives
        ``L + xi e^(-k L) log(1 + y) / y`` with ``y = k xi e^(-k L)`` (``L + xi`` for gamma = 1).
        """
        xi = s * v * dt
        if self.saturates:
            e = 1.0 - q[0]
            p1 = z[0] + xi * (1.0 - m[0])
            hit = 1.0 - e * p1 <= 0.0
            return [pick(hit, 1.0 / e, p1)], [pick(hit, 1.0, m[0])]
        k = q[0] - 1.0
        a = xi * exp(-k * z[0])
        return [z[0] + a * log1p_ratio(k * a)], []

    @property
    def has_free_branch(self) -> bool:  # type: ignore[override]
        """Closed-form branches exist for gamma = 0 only (:meth:`free_branch`)."""
        return self.gamma == 0.0

    def free_branch(self, z: Sequence[float], m: Sequence[float], v: float, s: float, q: Any,
                    horizon: float) -> Optional[tuple[float, float, list[float], list[float], float, int]]:
        """gamma = 0 below saturation: the linear oscillator, in closed form (see
        :meth:`FrictionModel.free_branch`).

        There ``f = s F~ = p``, ``(s v~)' = -f`` and ``f' = s v~``, so the point ``(s v~, f)`` turns
        on the circle of radius ``a = hypot(s v~, f)`` (``docs/mathematics.md#prandtl-stop``):
        ``f = a sin(t~ + theta)``, ``theta = atan2(f, s v~)``; the reversal comes at
        ``t~ = pi/2 - theta`` with ``f = a``, below saturation if ``a <= 1`` (at ``a = 1``
        saturation coincides with the reversal). Integrated, the error of every step drifted
        the energy (300x rtol over 1e4 reversals). ``None`` (integrate) for gamma > 0, a
        saturated state, a mass at rest or ``a > 1``.
        """
        if q[0] != 0.0 or m[0] > 0.5:
            return None
        w, f = s * v, z[0]  # force_of_p(p, 0) = p
        a = math.hypot(w, f)
        if not 0.0 < a <= 1.0 + 4e-16:
            return None
        theta = math.atan2(f, w)
        to_rev = 0.5 * math.pi - theta
        if to_rev < horizon:
            f1 = min(a, 1.0)
            return to_rev, 0.0, [f1], [0.0], s * (f1 - f), 0
        phase = horizon + theta
        f1 = a * math.sin(phase)
        return horizon, s * a * math.cos(phase), [f1], [0.0], s * (f1 - f), 0

    def branch_potential(self, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> Any:
        """gamma < 1 before saturation: ``H(p) = int_0^p f dp = p + ((1 - e p)^(1/e + 1) - 1) / (1 + e)``,
        ``e = 1 - gamma`` (``docs/mathematics.md#saturation``); ``None`` for gamma >= 1 (no events)."""
        if not self.saturates:
            return None
        p, e = z[0], 1.0 - q[0]
        if _sym(p, e):
            return p + (ca.fmax(1.0 - e * p, 0.0) ** (1.0 / e + 1.0) - 1.0) / (1.0 + e)
        return p + (max(1.0 - e * p, 0.0) ** (1.0 / e + 1.0) - 1.0) / (1.0 + e)

    def travel(self, z0: Sequence[float], z1: Sequence[float], s: float, q: Any) -> float:
        """``s (p1 - p0)`` with the branch distances of the log-gaps ``z0``, ``z1`` (gamma >= 1)."""
        g = q[0]
        return s * (distance_of_log_gap(z1[0], g) - distance_of_log_gap(z0[0], g))

    def branch_energy_of_force(self, F: np.ndarray, s: Any) -> np.ndarray:
        """``H_gamma(s F~)`` (:func:`prefriction.models.dahl_branch.branch_potential`), (3.9) for gamma = 1."""
        return np.asarray(branch_potential(np.clip(s * np.asarray(F, dtype=float), -1.0, 1.0), self.gamma), dtype=float)
