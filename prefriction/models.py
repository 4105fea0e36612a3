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

import numpy as np

from ._validation import check_nonnegative, check_positive

InputForce = Union[None, Callable[[Any], Any], tuple]


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


def _check_input_force(u: InputForce) -> InputForce:
    """Validate an input force: ``None``, a callable of time, or samples ``(t, u)``."""
    if u is None or callable(u):
        return u
    if isinstance(u, tuple) and len(u) == 2:
        t = np.asarray(u[0], dtype=float)
        val = np.asarray(u[1], dtype=float)
        if t.ndim != 1 or val.shape != t.shape or t.size < 2:
            raise ValueError(
                "u samples must be a pair (t, u) of 1-D arrays of equal length >= 2, "
                f"got shapes {t.shape} and {val.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(val))):
            raise ValueError("u samples must be finite (t and u), got NaN or inf")
        if np.any(np.diff(t) <= 0):
            raise ValueError("u sample times t must be strictly increasing")
        t.setflags(write=False)
        val.setflags(write=False)
        return (t, val)
    raise TypeError(
        "u must be None, a callable u(t) [N] of time t [s], or a pair (t, u) of sample arrays, "
        f"got {u!r} of type {type(u).__name__}"
    )


@dataclass(frozen=True, eq=False)
class Oscillator:
    """Pre-sliding hysteresis oscillator (2.1): ``m x'' + F = u(t)``.

    Parameters
    ----------
    friction : FrictionModel
        The hysteretic restoring (friction) force ``f[x]``, e.g. :class:`Dahl`.
    mass : float, default 1.0
        Moving mass ``m`` [kg], ``0 < mass < inf``.
    u : None, callable or (t, u) samples, default None
        External force [N]. ``None`` is the unforced system (2.1) of the paper. A callable
        ``u(t)`` takes time in seconds; samples ``(t, u)`` are two 1-D arrays with strictly
        increasing times [s].
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
        object.__setattr__(self, "u", _check_input_force(self.u))

    @property
    def forced(self) -> bool:
        """True if an external force ``u`` acts on the mass."""
        return self.u is not None
