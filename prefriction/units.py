"""Normalised units that make the unforced Dahl oscillator parameter-free.

``x~ = x sigma / Fc``, ``F~ = F / Fc``, ``t~ = t sqrt(sigma / m)``, ``v~ = v sqrt(m sigma) / Fc``,
``E~ = E sigma / Fc^2``. In these units ``x~' = v~``, ``v~' = u~ - F~`` and
``F~' = v~ (1 - s F~)^gamma``: every sigma, Fc and m is the same problem
(``docs/mathematics.md#normalised-units``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from prefriction.models import Oscillator


@dataclass(frozen=True)
class Scales:
    """Reference quantities of the normalised units (SI value of one normalised unit).

    Attributes
    ----------
    x : float
        Displacement unit ``Fc / sigma`` [m].
    F : float
        Force unit ``Fc`` [N].
    t : float
        Time unit ``sqrt(m / sigma)`` [s].
    v : float
        Velocity unit ``Fc / sqrt(m sigma)`` [m/s].
    E : float
        Energy unit ``Fc^2 / sigma`` [J].
    """

    x: float
    F: float
    t: float
    v: float
    E: float

    @classmethod
    def of(cls, system: Oscillator) -> "Scales":
        """Scales of ``system`` (its friction model's ``sigma``, ``Fc`` and its mass)."""
        sigma, Fc, m = system.friction.sigma, system.friction.Fc, system.mass
        return cls(
            x=Fc / sigma,
            F=Fc,
            t=math.sqrt(m / sigma),
            v=Fc / math.sqrt(m * sigma),
            E=Fc * Fc / sigma,
        )
