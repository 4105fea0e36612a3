"""Normalised units that make the unforced Dahl oscillator parameter-free.

``x~ = x sigma / Fc``, ``F~ = F / Fc``, ``t~ = t sqrt(sigma / m)``, ``v~ = v sqrt(m sigma) / Fc``,
``E~ = E sigma / Fc^2``. In these units ``x~' = v~``, ``v~' = u~ - F~`` and
``F~' = v~ (1 - s F~)^gamma``: every sigma, Fc and m is the same problem
(``docs/mathematics.md#normalised-units``).
"""

from __future__ import annotations

import math
from typing import Any
from dataclasses import dataclass

import numpy as np

from prefriction._validation import check_positive

_TINY = 2.2250738585072014e-308  # smallest normal double
_LABELS = {"x": "Fc/sigma", "F": "Fc", "t": "sqrt(m/sigma)", "v": "Fc/sqrt(m sigma)", "E": "Fc^2/sigma"}


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

    def __post_init__(self) -> None:
        for name in ("x", "F", "t", "v", "E"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))

    @classmethod
    def of(cls, system: Any) -> "Scales":
        """Scales of ``system`` (its friction model's ``sigma``, ``Fc`` and its mass).

        Raises
        ------
        TypeError
            If ``system`` is not a :class:`prefriction.Oscillator`.
        ValueError
            If a unit is not a finite normal double (``sigma``, ``Fc`` and ``mass`` too far apart,
            e.g. ``sigma = 1e308`` N/m with ``Fc = 1e-308`` N): the simulator and the exact
            references divide by them.
        """
        # an Oscillator (read, not imported: the models import these units)
        if not all(hasattr(system, name) for name in ("friction", "mass", "u")):
            raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
        sigma, Fc, m = system.friction.sigma, system.friction.Fc, system.mass
        for name, value in (("sigma", sigma), ("Fc", Fc)):  # a user model's numbers are unchecked
            if not (isinstance(value, (int, float, np.floating, np.integer)) and 0.0 < value < math.inf):
                raise ValueError(f"the friction model's {name} must be a finite number > 0 (the {name} of "
                                 f"{type(system.friction).__name__} sets the normalised units), got {value!r}")
        with_units = {
            "x": Fc / sigma,
            "F": Fc,
            "t": math.sqrt(m / sigma),
            "v": Fc / math.sqrt(m * sigma) if math.isfinite(m * sigma) else Fc / math.sqrt(m) / math.sqrt(sigma),
            "E": Fc / sigma * Fc,
        }
        bad = [f"{_LABELS[k]} = {u!r}" for k, u in with_units.items() if not (math.isfinite(u) and u >= _TINY)]
        if bad:
            raise ValueError(
                f"sigma = {sigma!r} N/m, Fc = {Fc!r} N and mass = {m!r} kg are out of range together: the units "
                f"Fc/sigma [m], Fc [N], sqrt(m/sigma) [s], Fc/sqrt(m sigma) [m/s] and Fc^2/sigma [J] must be "
                f"finite doubles >= {_TINY!r}, got {', '.join(bad)}"
            )
        return cls(**with_units)
