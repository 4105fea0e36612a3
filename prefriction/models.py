"""Friction models and the pre-sliding oscillator (2.1) they act in.

Every model is immutable and validated on construction. A friction model states its
behaviour in the normalised units of :mod:`prefriction.units` (force in units of ``Fc``,
displacement in units of ``Fc / sigma``), so that one simulator and one energy analysis
serve every model.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any, Callable, Union


from ._validation import check_nonnegative, check_positive, check_signal

InputForce = Union[None, float, Callable[[Any], Any], tuple]


class FrictionModel(ABC):
    """Contract of a rate-independent, clockwise hysteresis friction model.

    A model has a rest stiffness ``sigma`` [N/m] and a Coulomb (saturation) force ``Fc`` [N],
    which define the normalised units. Between two velocity reversals the direction
    ``s = sign(v)`` is fixed, and the normalised force ``F~ = F / Fc`` obeys
    ``dF~/dx~ = slope(s * F~)`` with ``x~ = x sigma / Fc``.
    """

    sigma: float
    Fc: float

    @abstractmethod
    def slope(self, f: Any) -> Any:
        """Normalised tangent stiffness ``dF~/dx~`` on a branch, as a function of ``f = s F / Fc``.

        Must accept floats, numpy arrays and CasADi symbols. Equals 1 at ``f = 0`` (rest
        stiffness ``sigma``) and is >= 0 for ``f <= 1``.
        """


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
    """

    sigma: float
    Fc: float
    gamma: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "sigma", check_positive("sigma", self.sigma))
        object.__setattr__(self, "Fc", check_positive("Fc", self.Fc))
        object.__setattr__(self, "gamma", check_nonnegative("gamma", self.gamma))

    def slope(self, f: Any) -> Any:
        """Normalised tangent stiffness ``(1 - f)^gamma`` (3.2) for ``f = s F / Fc <= 1``."""
        if self.gamma == 0.0:
            return 1.0 + 0.0 * f
        return (1.0 - f) ** self.gamma


@dataclass(frozen=True, eq=False)
class Oscillator:
    """Pre-sliding hysteresis oscillator (2.1): ``m x'' + F = u(t)``.

    Parameters
    ----------
    friction : FrictionModel
        The hysteretic restoring (friction) force ``f[x]``, e.g. :class:`Dahl`.
    mass : float, default 1.0
        Moving mass ``m`` [kg], ``0 < mass < inf``.
    u : None, float, callable or (t, u) samples, default None
        External force [N]. ``None`` is the unforced system (2.1) of the paper. A float is a
        constant force; a callable ``u(t)`` takes time in seconds (and must accept a CasADi
        symbol, see :func:`prefriction.simulate`); samples ``(t, u)`` are two 1-D arrays with
        strictly increasing times [s], linear in between.
    """

    friction: FrictionModel
    mass: float = 1.0
    u: InputForce = field(default=None)

    def __post_init__(self) -> None:
        if not isinstance(self.friction, FrictionModel):
            raise TypeError(
                f"friction must be a FrictionModel such as prefriction.Dahl, got {self.friction!r}"
            )
        object.__setattr__(self, "mass", check_positive("mass", self.mass))
        if self.u is not None:
            object.__setattr__(self, "u", check_signal("u", self.u, "N", "u"))

    @property
    def forced(self) -> bool:
        """True if an external force ``u`` acts on the mass."""
        return self.u is not None


def check_dahl_oscillator(system: Any, purpose: str) -> Dahl:
    """Return the Dahl model of ``system``, or raise ``TypeError`` naming what was passed.

    Parameters
    ----------
    system : Any
        Must be an :class:`Oscillator` whose friction is a :class:`Dahl` model.
    purpose : str
        What needs the Dahl model, for the message (e.g. ``"exact_reversals"``).
    """
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
    if not isinstance(system.friction, Dahl):
        raise TypeError(
            f"{purpose} needs system.friction to be a prefriction.Dahl model, got "
            f"{system.friction!r} of type {type(system.friction).__name__}"
        )
    return system.friction
