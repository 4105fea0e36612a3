"""Elasto-plastic friction model (Dupont, Hayward, Armstrong, Altpeter 2002) on the contract.

Mathematics first (normalised units of :mod:`prefriction.units`, ``w = s zeta``, ``s = sign(v)``)::

    zeta' = v (1 - alpha(w, v) w / g(v)),      g(v) = 1 + (Fs/Fc - 1) exp(-(v / vs~)^2),
    F~    = zeta + sigma1~ zeta' + sigma2~ v,
    alpha = 0                                          w <= b        (elastic, or unloading)
          = (1 + sin(pi (w - (g + b)/2) / (g - b))) / 2    b < w < g     (transition)
          = 1                                          w >= g        (saturated: LuGre)

with ``b = sigma0 z_ba / Fc``. ``alpha`` is C1 at ``w = b`` and ``w = g`` but not C2, so the
first crossing of each on a branch is an event (flags ``broke``, ``sat``): until then the
right-hand side is analytic. See :class:`ElastoPlastic`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Hashable, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel, Parameter
from prefriction.models.closed_form import exp, pick, symbolic
from prefriction.models.lugre import LuGre
from prefriction.units import Scales

__all__ = ["ElastoPlastic", "TRANSITION_STEPS", "alpha"]

TRANSITION_STEPS = 8
"""Runge-Kutta steps of :meth:`ElastoPlastic.advance` over the transition part of an interval."""


def _and(a: Any, b: Any) -> Any:
    return ca.logic_and(a, b) if symbolic(a, b) else bool(a) and bool(b)


def _or(a: Any, b: Any) -> Any:
    return ca.logic_or(a, b) if symbolic(a, b) else bool(a) or bool(b)


def _not(a: Any) -> Any:
    return ca.logic_not(a) if symbolic(a) else not a


def _sin(x: Any) -> Any:
    return ca.sin(x) if symbolic(x) else math.sin(x)


def alpha(w: Any, g: Any, b: Any) -> Any:
    """The transition ``(1 + sin(pi (w - (g + b) / 2) / (g - b))) / 2`` of ``alpha`` for ``b < w < g``
    (Dupont et al. 2002, eq. (9)): 0 at ``w = b``, 1 at ``w = g``, zero slope at both."""
    return 0.5 + 0.5 * _sin(math.pi * (w - 0.5 * (g + b)) / (g - b))


@dataclass(frozen=True)
class ElastoPlastic(FrictionModel):
    """Single-state elasto-plastic friction model with breakaway displacement.

    P. Dupont, V. Hayward, B. Armstrong, F. Altpeter, "Single state elastoplastic friction
    models", IEEE Transactions on Automatic Control 47(5), 787-792, 2002, eqs. (7)-(9)::

        z' = v - alpha(z, v) sigma0 |v| z / f_ss(v),  f_ss(v) = Fc + (Fs - Fc) exp(-(v / vs)^2),
        F  = sigma0 z + sigma1 z' + sigma2 v,

    ``alpha = 0`` for ``|z| <= z_ba`` or ``sign(z) != sign(v)`` (elastic: no drift under forces
    below breakaway), the sine transition between ``z_ba`` and ``z_ss(v) = f_ss(v) / sigma0``,
    and 1 beyond (LuGre).

    Parameters
    ----------
    sigma0 : float
        Bristle (rest) stiffness [N/m], ``0 < sigma0 < inf``; the ``sigma`` of the normalised units.
    sigma1 : float
        Bristle damping [N s/m], ``0 <= sigma1 < inf``.
    sigma2 : float
        Viscous friction coefficient [N s/m], ``0 <= sigma2 < inf``.
    Fc : float
        Coulomb friction force [N], ``0 < Fc < inf``; the force unit.
    Fs : float
        Static friction force [N], ``Fc <= Fs < inf``.
    vs : float
        Stribeck velocity [m/s], ``0 < vs < inf``.
    z_ba : float
        Breakaway displacement [m], ``0 < z_ba < Fc / sigma0`` (below every ``z_ss(v)``).
    crossings : bool, default True
        Locate the breakaway and saturation crossings as events (flags ``broke``, ``sat``).
        ``False``: ``alpha`` straight from its definition inside the right-hand side (C1 kinks
        that the integrators' error control steps over; no flags and no events).

    Raises
    ------
    ValueError, TypeError
        If a parameter is out of its range or not a real number (the message names it).

    Notes
    -----
    State ``zeta = sigma0 z / Fc``; flags ``broke`` (``w`` has passed ``b`` on this branch) and
    ``sat`` (``w`` has reached ``g(v)`` on this branch). Events: 0, breakaway (indicator
    ``b - w``); 1, saturation (``g(v) - w``; ``w`` reaches ``g`` only where ``g`` falls, as the
    speed grows when ``Fs > Fc``: at constant ``g`` the approach is exponential). Once
    saturated, ``alpha`` is the paper's ``w >= g ? 1 : transition``, which is C1 where ``w``
    drops below ``g`` again as the speed falls before a reversal: that crossing is not an
    event, since ``w`` and ``g`` touch to round-off at constant speed and an event there would
    chatter. A reversal keeps ``zeta`` and sets ``broke`` if ``s_new zeta > b`` (a motion back
    before the bristle has unloaded), clears ``sat``. Run-time numbers
    ``q = [sigma1~, sigma2~, Fs/Fc - 1, vs~, b]`` (those of :class:`prefriction.LuGre` and ``b``).
    """

    sigma0: float
    sigma1: float
    sigma2: float
    Fc: float
    Fs: float
    vs: float
    z_ba: float
    crossings: bool = True

    parameters = LuGre.parameters + (Parameter("z_ba", "m", 0.0, math.inf, low_open=True),)
    rate_independent = False
    n_states = 1
    sigma = LuGre.sigma
    max_hysteretic_force = LuGre.max_hysteretic_force
    steady_force = LuGre.steady_force

    def __post_init__(self) -> None:
        LuGre.__post_init__(self)  # type: ignore[arg-type]  # LuGre's parameters, Fc <= Fs
        if not self.z_ba < self.Fc / self.sigma0:
            raise ValueError(f"z_ba must lie in (0, Fc / sigma0) = (0, {self.Fc / self.sigma0!r}) [m] (breakaway "
                             f"before the steady-state deflection), got {self.z_ba!r}")

    @property
    def n_flags(self) -> int:  # type: ignore[override]
        return 2 if self.crossings else 0

    @property
    def n_events(self) -> int:  # type: ignore[override]
        return 2 if self.crossings else 0

    def structure_key(self) -> Hashable:
        return ("ElastoPlastic", "crossings as events" if self.crossings else "crossings in the right-hand side")

    def runtime_params_for(self, scales: Scales) -> np.ndarray:
        """``q = [sigma1 V/Fc, sigma2 V/Fc, Fs/Fc - 1, vs/V, sigma0 z_ba/Fc]``, ``V = scales.v``."""
        V = scales.v
        return np.array([self.sigma1 * V / self.Fc, self.sigma2 * V / self.Fc, self.Fs / self.Fc - 1.0,
                         self.vs / V, self.sigma0 * self.z_ba / self.Fc])

    def runtime_params(self) -> np.ndarray:
        """:meth:`runtime_params_for` of a unit mass (``V = Fc / sqrt(sigma0)``)."""
        return self.runtime_params_for(SimpleNamespace(v=self.Fc / math.sqrt(self.sigma0)))  # type: ignore[arg-type]

    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """Bristle force ``zeta = f0`` at rest; past breakaway if ``s f0 > b``, saturated if ``s f0 >= Fs/Fc``."""
        w, b = s * f0, self.sigma0 * self.z_ba / self.Fc
        if not self.crossings:
            return [float(f0)], []
        return [float(f0)], [1.0 if w > b else 0.0, 1.0 if w >= self.Fs / self.Fc else 0.0]

    @staticmethod
    def stribeck(v: Any, q: Any) -> Any:
        """Normalised steady-state force ``g(v) = f_ss(v) / Fc``."""
        r = v / q[3]
        return 1.0 + q[2] * exp(-(r * r))

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        g, w = self.stribeck(v, q), s * z[0]
        t = alpha(w, g, q[4])
        if not self.crossings:
            a = pick(w <= q[4], 0.0, pick(w >= g, 1.0, t))
        else:
            a = m[0] * (m[1] * pick(w >= g, 1.0, t) + (1.0 - m[1]) * t)
        return [v * (1.0 - a * w / g)]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        return z[0] + q[0] * self.rate(z, m, v, s, q)[0] + q[1] * v

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        if not self.crossings:
            return []
        w, g = s * z[0], self.stribeck(v, q)
        breakaway = pick(m[0] > 0.5, 1.0, q[4] - w)
        saturation = pick(m[0] > 0.5, pick(m[1] > 0.5, 1.0, g - w), 1.0)
        return [breakaway, saturation]

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """``zeta`` kept (``alpha`` is continuous at both crossings: no jump of the state, so a state
        already past ``b`` or ``g``, such as a Motion fit's shooting node, takes its flags at once);
        breakaway sets ``broke``, saturation ``sat``."""
        return [z[0]], ([1.0, 0.0] if k == 0 else [1.0, 1.0])

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        """``zeta`` kept; ``broke`` if ``s_new zeta > b`` (the bristle has not unloaded), ``sat`` cleared."""
        if not self.crossings:
            return [z[0]], []
        return [z[0]], [pick(s_new * z[0] > q[4], 1.0, 0.0), 0.0]

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """State after ``dt`` at the constant velocity ``v`` (``docs/along.md#exact-steps``), with
        the travel ``xi = s v dt``: the elastic stretch ``w + xi`` exactly, the breakaway located
        inside the interval; saturated (``w >= g``, ``g`` constant at constant speed) the LuGre
        relaxation ``g + (w - g) exp(-xi / g)`` exactly; the transition ``dw/dxi = 1 - alpha w / g``
        by :data:`TRANSITION_STEPS` Runge-Kutta steps of the remaining travel (error about
        ``(xi / TRANSITION_STEPS / (g - b))^4`` relative). At constant ``g`` the transition
        approaches ``g`` without reaching it, so no saturation falls inside an interval; one at
        its start (``g`` lower at the new speed) is taken there."""
        g, b, w0, xi = self.stribeck(v, q), q[4], s * z[0], s * v * dt
        broke = m[0] > 0.5 if self.crossings else w0 > b
        elastic = _and(_not(broke), w0 + xi <= b)
        w_start = pick(broke, w0, b)
        rest = pick(broke, xi, w0 + xi - b)
        sat = _or(m[1] > 0.5, w_start >= g) if self.crossings else True
        relax = g + (w_start - g) * exp(-rest / g)
        slope = lambda w: 1.0 - pick(sat, pick(w >= g, 1.0, alpha(w, g, b)), alpha(w, g, b)) * w / g  # noqa: E731
        w_rk, h = w_start, rest / TRANSITION_STEPS
        for _ in range(TRANSITION_STEPS):
            k1 = slope(w_rk)
            k2 = slope(w_rk + 0.5 * h * k1)
            k3 = slope(w_rk + 0.5 * h * k2)
            k4 = slope(w_rk + h * k3)
            w_rk = w_rk + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        w1 = pick(elastic, w0 + xi, pick(_and(sat, w_start >= g), relax, w_rk))
        if not self.crossings:
            return [s * w1], []
        return [s * w1], [pick(elastic, m[0], 1.0), pick(elastic, m[1], pick(sat, 1.0, 0.0))]
