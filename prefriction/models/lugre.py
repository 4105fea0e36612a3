"""LuGre friction model (Canudas de Wit, Olsson, Astrom, Lischinsky 1995) through the protocol::

    zeta' = v (1 - s zeta / g(v)),   g = 1 + (Fs/Fc - 1) exp(-(v / vs~)^2),   F~ = zeta + sigma1~ zeta' + sigma2~ v

One bristle state, no flags, no events; rate-dependent. Its numbers in normalised units depend
on the mass (the velocity unit ``Fc / sqrt(m sigma0)``), so the model gives them through
:meth:`LuGre.runtime_params_for` from the system's :class:`prefriction.Scales`.
See :class:`LuGre`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Hashable, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel, Parameter
from prefriction.models.closed_form import expm1

if TYPE_CHECKING:  # units imports the models
    from prefriction.units import Scales

__all__ = ["LuGre"]


def _exp(x: Any) -> Any:
    """``exp`` of a float, a numpy array or a CasADi symbol."""
    if type(x) is float:
        return math.exp(x)
    if isinstance(x, (ca.SX, ca.MX, ca.DM)):
        return ca.exp(x)
    return np.exp(x)


@dataclass(frozen=True)
class LuGre(FrictionModel):
    """LuGre dynamic friction model with Stribeck effect and viscous friction.

    C. Canudas de Wit, H. Olsson, K. J. Astrom and P. Lischinsky, "A new model for control of
    systems with friction", IEEE Transactions on Automatic Control 40(3), 419-425, 1995,
    equations (1)-(3)::

        z' = v - sigma0 |v| z / g(v),      g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2),
        F  = sigma0 z + sigma1 z' + sigma2 v,

    with ``z`` the mean bristle deflection [m] and ``v`` the sliding velocity [m/s].

    Parameters
    ----------
    sigma0 : float
        Bristle (rest) stiffness [N/m], ``0 < sigma0 < inf``; the ``sigma`` of the normalised units.
    sigma1 : float
        Bristle damping [N s/m], ``0 <= sigma1 < inf``.
    sigma2 : float
        Viscous friction coefficient [N s/m], ``0 <= sigma2 < inf``.
    Fc : float
        Coulomb friction force [N], ``0 < Fc < inf``; the force unit of the normalised units.
    Fs : float
        Static (stiction) friction force [N], ``Fc <= Fs < inf``.
    vs : float
        Stribeck velocity [m/s], ``0 < vs < inf``.

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it, its value and the range).
    TypeError
        If an argument is not a real number.

    Notes
    -----
    Protocol (``docs/models.md``): one state, the normalised bristle force
    ``zeta = sigma0 z / Fc``. On a branch of direction ``s`` (``|v| = s v``) the right-hand side
    is smooth, so the kink of ``|v|`` at ``v = 0`` is a reversal; the default reverse keeps ``zeta``
    (the deflection is continuous). In normalised units (:mod:`prefriction.units`)::

        zeta' = v (1 - s zeta / g),   g = 1 + (Fs / Fc - 1) exp(-(v / vs~)^2),
        F~    = zeta + sigma1~ zeta' + sigma2~ v,

    with ``sigma1~ = sigma1 V / Fc``, ``sigma2~ = sigma2 V / Fc`` and ``vs~ = vs / V``, where
    ``V = Fc / sqrt(m sigma0)`` is the velocity unit: the numbers depend on the mass ``m``.
    Run-time numbers (:meth:`runtime_params_for`): ``q = [sigma1~, sigma2~, Fs / Fc - 1, vs~]``;
    every instance shares one compiled plant.

    The model is stiff in gross sliding: the bristle state relaxes with the time constant
    ``g(v) / (sigma0 |v|)``, against ``sqrt(m / sigma0)`` of the stuck mass.

    ``F0`` of :func:`prefriction.simulate` is the bristle force ``sigma0 z`` at the start (the
    friction force of a resting mass), :meth:`initial_state`.
    """

    sigma0: float
    sigma1: float
    sigma2: float
    Fc: float
    Fs: float
    vs: float

    parameters = (
        Parameter("sigma0", "N/m", 0.0, math.inf, low_open=True),
        Parameter("sigma1", "N s/m", 0.0, math.inf),
        Parameter("sigma2", "N s/m", 0.0, math.inf),
        Parameter("Fc", "N", 0.0, math.inf, low_open=True),
        Parameter("Fs", "N", 0.0, math.inf, low_open=True),
        Parameter("vs", "m/s", 0.0, math.inf, low_open=True),
    )
    rate_independent = False
    n_states = 1

    def __post_init__(self) -> None:
        self._validate()
        if not self.Fs >= self.Fc:
            raise ValueError(
                f"Fs must be finite and >= Fc = {self.Fc!r}, got {self.Fs!r} (allowed range: Fc <= Fs < inf [N]: "
                f"the static force is at least the Coulomb force)"
            )

    @property
    def sigma(self) -> float:  # type: ignore[override]
        """Reference stiffness of the normalised units: ``sigma0`` [N/m]."""
        return self.sigma0

    @property
    def max_hysteretic_force(self) -> float:  # type: ignore[override]
        """The static force ``Fs`` [N]: the bristle force ``sigma0 z`` stays within
        ``[-g(v), g(v)]`` for a bristle state that starts there, and ``g(v) <= Fs``."""
        return self.Fs

    def structure_key(self) -> Hashable:
        return ("LuGre", "one bristle state")

    def runtime_params_for(self, scales: "Scales") -> np.ndarray:
        """``q = [sigma1 V / Fc, sigma2 V / Fc, Fs / Fc - 1, vs / V]`` with the velocity unit
        ``V = scales.v = Fc / sqrt(m sigma0)`` of the system."""
        V = scales.v
        return np.array([self.sigma1 * V / self.Fc, self.sigma2 * V / self.Fc, self.Fs / self.Fc - 1.0, self.vs / V])

    def runtime_params(self) -> np.ndarray:
        """The numbers :meth:`runtime_params_for` gives for a unit mass (``m = 1 kg``)."""
        return self.runtime_params_for(_UnitMass(self.Fc / math.sqrt(self.sigma0)))

    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """Bristle force ``zeta = f0`` (the friction force of the mass at rest)."""
        return [float(f0)], []

    def stribeck(self, v: Any, q: Any) -> Any:
        """Normalised steady-state friction ``g(v) / Fc = 1 + (Fs / Fc - 1) exp(-(v / vs~)^2)``."""
        r = v / q[3]
        return 1.0 + q[2] * _exp(-(r * r))

    def velocity_scale(self, q: Any) -> Any:
        """The normalised Stribeck velocity ``vs~ = q[3]`` (:meth:`FrictionModel.velocity_scale`)."""
        return q[3]

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        return [v * (1.0 - s * z[0] / self.stribeck(v, q))]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        dz = self.rate(z, m, v, s, q)[0]
        return z[0] + q[0] * dz + q[1] * v

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """Exact step over ``dt`` at the constant velocity ``v``: ``zeta' = v - (s v / g) zeta`` is
        linear, ``zeta(dt) = zeta + (s g - zeta) (1 - exp(-s v dt / g))``
        (``docs/along.md#exact-steps``)."""
        g = self.stribeck(v, q)
        return [z[0] - (s * g - z[0]) * expm1(-s * v * dt / g)], []

    def steady_force(self, v: Any) -> Any:
        """Steady-state friction [N] at the constant velocity ``v`` [m/s] (numpy):
        ``sign(v) g(v) + sigma2 v``."""
        v = np.asarray(v, dtype=float)
        return np.sign(v) * (self.Fc + (self.Fs - self.Fc) * np.exp(-(v / self.vs) ** 2)) + self.sigma2 * v


@dataclass(frozen=True)
class _UnitMass:
    """The velocity unit of a unit-mass system (all :meth:`LuGre.runtime_params_for` reads)."""

    v: float
