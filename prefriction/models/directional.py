"""Direction-dependent viscous friction ``F = b v`` (``v > 0``), ``b_neg v`` (``v < 0``): see
:class:`DirectionalViscous`.

Drives are often asymmetric (the EMPS benchmark's reference model has a viscous coefficient and a
Coulomb level per direction: Janot, Gautier and Brunot 2019, ``Script_IDIM_LS_Asym_Fric.m``).
Added to a hysteretic model (``pf.Dahl(...) + pf.DirectionalViscous(b, b_neg)``) it gives the
viscous part; with a force offset ``F_off`` the Coulomb levels ``Fc + F_off`` and ``Fc - F_off``
of the two directions are the asymmetric Coulomb part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Hashable, Sequence

import numpy as np

from prefriction.models.base import Parameter
from prefriction.models.viscous import Viscous

if TYPE_CHECKING:
    from prefriction.units import Scales

__all__ = ["DirectionalViscous"]


@dataclass(frozen=True)
class DirectionalViscous(Viscous):
    """Viscous friction with a coefficient per direction of motion [N].

    ``F = b v`` while moving in the positive direction (``s = +1``), ``F = b_neg v`` in the
    negative one (``s = -1``): ``F = v (b (1 + s) + b_neg (1 - s)) / 2``, continuous at the
    reversals (``v = 0`` there).

    Parameters
    ----------
    b : float
        Viscous coefficient [N s/m] of the positive direction, ``0 <= b < inf``.
    b_neg : float
        Viscous coefficient [N s/m] of the negative direction, ``0 <= b_neg < inf``.

    Raises
    ------
    ValueError
        If a coefficient is negative or not finite.
    TypeError
        If a coefficient is not a real number.

    Notes
    -----
    Protocol as :class:`prefriction.Viscous` (no state, nominal units), run-time numbers
    ``q = [b V / Fc, b_neg V / Fc]``; the direction is the one the simulators carry.

    Examples
    --------
    >>> import numpy as np, prefriction as pf
    >>> t = np.linspace(0.0, 2.0, 201)
    >>> res = pf.friction_along(pf.DirectionalViscous(b=200.0, b_neg=150.0), t, 0.01 * np.sin(np.pi * t))
    >>> round(float(res.F.max()), 2), round(float(res.F.min()), 2)  # 200 x and 150 x 0.01 pi m/s
    (6.28, -4.71)
    """

    b_neg: float = 0.0

    parameters = (Parameter("b", "N s/m", 0.0, math.inf), Parameter("b_neg", "N s/m", 0.0, math.inf))

    def structure_key(self) -> Hashable:
        return ("DirectionalViscous",)

    def runtime_params_for(self, scales: "Scales") -> Any:
        """``q = [b V / Fc, b_neg V / Fc]`` with the velocity unit ``V = scales.v`` (``Fc = 1`` N)."""
        q = [self.b * scales.v / self.Fc, self.b_neg * scales.v / self.Fc]
        return np.array(q) if all(isinstance(a, (int, float, np.floating)) for a in q) else q

    def runtime_params(self) -> np.ndarray:
        """``q`` for a unit mass (``V = 1`` m/s with the nominal units)."""
        return np.array([self.b, self.b_neg])

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        return 0.5 * v * (q[0] * (1.0 + s) + q[1] * (1.0 - s))
