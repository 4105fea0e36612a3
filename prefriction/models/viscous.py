"""Viscous friction ``F = b v`` through the friction-model protocol (no state): ``F~ = b~ v~``.

Meant as a term of a sum of models (:class:`prefriction.Parallel`, ``pf.Dahl(...) +
pf.Viscous(b)``); alone it is a linear damper. See :class:`Viscous`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

from prefriction.models.base import FrictionModel, Parameter

__all__ = ["Viscous"]


@dataclass(frozen=True)
class Viscous(FrictionModel):
    """Viscous friction ``F = b v`` [N]: a force proportional to the sliding velocity.

    Parameters
    ----------
    b : float
        Viscous coefficient [N s/m], ``0 <= b < inf``.

    Raises
    ------
    ValueError
        If ``b`` is negative or not finite.
    TypeError
        If ``b`` is not a real number.

    Notes
    -----
    Protocol (``docs/models.md``): no state, no flag, no event; rate-dependent. A damper has
    no stiffness and no force level of its own, so its normalised units are nominal:
    ``sigma = 1`` N/m and ``Fc = 1`` N; in a sum (:class:`prefriction.Parallel`) the units
    are those of the other models. Run-time number ``q = [b V / Fc]`` with the velocity unit
    ``V`` (it holds the mass: the base's default for a parameter in N s/m), ``max_hysteretic_force``
    (so ``F0 = 0``, the default initial state) and ``k_min`` are 0.

    Examples
    --------
    >>> import prefriction as pf
    >>> model = pf.Dahl(sigma=1e5, Fc=1.0) + pf.Viscous(b=20.0)
    >>> model
    Dahl(sigma=100000.0, Fc=1.0, gamma=1.0) + Viscous(b=20.0)
    >>> model.parameter_names
    ('sigma', 'Fc', 'gamma', 'b')
    """

    b: float

    parameters = (Parameter("b", "N s/m", 0.0, math.inf),)
    n_states = 0

    @property
    def sigma(self) -> float:  # type: ignore[override]
        """Nominal reference stiffness: 1 N/m (a damper has none)."""
        return 1.0

    @property
    def Fc(self) -> float:  # type: ignore[override]
        """Nominal reference force: 1 N (a damper has none)."""
        return 1.0

    @property
    def max_hysteretic_force(self) -> float:  # type: ignore[override]
        """0 N: a damper at rest carries no force."""
        return 0.0

    @property
    def k_min(self) -> float:
        """0 N/m: a damper has no stiffness."""
        return 0.0

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        return []

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        return q[0] * v

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """No state to advance."""
        return [], []
