"""The pre-sliding oscillator (2.1) that a friction model acts in."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from prefriction._validation import check_positive
from prefriction.models.base import FrictionModel
from prefriction.signals import as_signal

__all__ = ["Oscillator", "check_oscillator", "check_dahl_oscillator"]


@dataclass(frozen=True, eq=False)
class Oscillator:
    """Pre-sliding hysteresis oscillator (2.1): ``m x'' + F = u(t)``.

    Parameters
    ----------
    friction : FrictionModel
        The hysteretic restoring (friction) force ``f[x]``: :class:`prefriction.Dahl` or any
        model implementing :class:`prefriction.FrictionModel`.
    mass : float, default 1.0
        Moving mass ``m`` [kg], ``0 < mass < inf``.
    u : None, float, Signal, (t, u) samples or callable, default None
        External force [N]. ``None`` is the unforced system (2.1) of the paper. A float is a
        :class:`prefriction.signals.Constant`; a :class:`prefriction.signals.Signal`
        (``Sine``, ``Step``, ``Ramp``, ``Chirp``, ``Samples``, sums) compiles once per kind and
        takes its numbers at run time; samples ``(t, u)`` are linear in between; a callable
        ``u(t)`` of time [s] must accept a CasADi symbol and compiles once per function object.
    """

    friction: FrictionModel
    mass: float = 1.0
    u: Any = field(default=None)

    def __post_init__(self) -> None:
        if not isinstance(self.friction, FrictionModel):
            raise TypeError(
                f"friction must be a FrictionModel such as prefriction.Dahl, got {self.friction!r} "
                f"of type {type(self.friction).__name__}"
            )
        object.__setattr__(self, "mass", check_positive("mass", self.mass))
        object.__setattr__(self, "u", as_signal(self.u, "u", "N"))

    @property
    def forced(self) -> bool:
        """True if an external force ``u`` acts on the mass."""
        return self.u is not None


def check_oscillator(system: Any, purpose: str, *, rate_independent: bool = False) -> FrictionModel:
    """Return the friction model of ``system``, or raise ``TypeError`` naming what was passed.

    Parameters
    ----------
    system : Any
        Must be an :class:`Oscillator`.
    purpose : str
        What needs it, for the message (e.g. ``"simulate"``).
    rate_independent : bool, default False
        Also require a rate-independent model (the energy analysis (2.3)-(2.12)).
    """
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
    if rate_independent and not system.friction.rate_independent:
        raise TypeError(f"{purpose} needs a rate-independent friction model, got {type(system.friction).__name__}")
    return system.friction


def check_dahl_oscillator(system: Any, purpose: str) -> Any:
    """Return the Dahl model of ``system``, or raise ``TypeError`` naming what was passed.

    Parameters
    ----------
    system : Any
        Must be an :class:`Oscillator` whose friction is a :class:`prefriction.Dahl` model.
    purpose : str
        What needs the Dahl model, for the message (e.g. ``"exact_reversals"``).
    """
    from prefriction.models.dahl import Dahl

    friction = check_oscillator(system, purpose)
    if not isinstance(friction, Dahl):
        raise TypeError(
            f"{purpose} is Dahl-only: it needs system.friction to be a prefriction.Dahl model, got "
            f"{friction!r} of type {type(friction).__name__}"
        )
    return friction
