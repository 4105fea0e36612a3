"""A start of a Motion fit with a free Dahl exponent from the force balance of the record.

Dahl's exponent ``gamma`` sets the shape of every reversal branch, ``dF/dx = sigma (1 - s F /
Fc)^gamma`` (3.2). With ``gamma`` far off, the stiffness and the Coulomb force compensate along a
long valley of the shooting problem: on the 2.5 kg, 2 kHz, 10 nm closed-loop stage of
``identify/_success.py`` (``gamma = 2``) a fit from a start with ``gamma = 3.07``, ``sigma``
0.57 and ``Fc`` 1.97 times the truth did not converge in 1,000 s of CPU, and with ``gamma`` held
at 1 or at 3.07 the other parameters run far off (``Fc`` 23 times the truth at ``gamma = 1``).

The inverse model (:func:`prefriction.identify.inverse.fit_inverse`: the friction along the
measured positions, ``u - m a - F_off``, fitted without shooting) estimates ``gamma`` within 2 %
on those 2,500-sample records in 0.3 s, its stiffness within 20 % (the filtered acceleration).
Its estimates of the free parameters (mass and offset included) are the start here, and the fit
holds ``gamma`` at that estimate in a first stage (the branch shape fixed, the rest settles), then
frees it. As for the element start (:mod:`prefriction.identify.element_start`), the fit starts
there only where its 50-sample shooting segments follow the record more closely than the given
start's, and :attr:`prefriction.identify.FitResult.start` says so.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

from prefriction.identify.data import Motion
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.structures import gamma_entry
from prefriction.models.base import FrictionModel

__all__ = ["HELD_EVALS", "BalanceStart", "balance_start"]

HELD_EVALS = 100
"""Most Jacobian evaluations of each layout of the first stage, with ``gamma`` held (module notes):
that stage settles the other parameters, it need not converge. Measured on the 2.5 kg closed-loop
stage (seeds 0, 1, 4 at 1,000 samples, factor-2 starts): 25 to 30 s of CPU per fit against 79 to
93 s with the fit's own budget of 500, the same estimates; seed 0 at 2,500 samples: 404 s against
755 s."""


@dataclass(frozen=True)
class BalanceStart:
    """What :func:`balance_start` found: the start model, mass [kg] (``None``: known), offset [N],
    one line saying what replaced what, and the name of the Dahl exponent to hold first."""

    model: FrictionModel
    mass: float | None
    offset: float
    line: str
    gamma: str


def balance_start(model: FrictionModel, data: Motion, space: ParameterSpace, free: Any, fixed: Any,
                  bounds: dict | None, offset: bool) -> BalanceStart | None:
    """The inverse model's estimates (module notes) as the start of a Motion fit.

    Parameters
    ----------
    model : FrictionModel
        The user's start model, with a Dahl term.
    data : Motion
        A forced record.
    space : ParameterSpace
        The fit's space at the given start (its ``start`` holds the start mass and offset).
    free, fixed, bounds :
        As :func:`prefriction.identify.fit`.
    offset : bool
        Whether the offset is fitted.

    Returns
    -------
    BalanceStart or None
        ``None`` without a free Dahl ``gamma``, for a Dahl with ``gamma < 1`` (in-branch events),
        a free decay, or where the inverse fit fails or lands off the allowed ranges or on the other
        side of ``gamma = 1``.
    """
    from prefriction.errors import SolverError
    from prefriction.identify.inverse import fit_inverse

    gamma = gamma_entry(model)
    if gamma is None or gamma not in space.free or model.n_events or data.free_decay:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = fit_inverse(model, data, offset=offset, free=free, fixed=fixed, bounds=bounds,
                              mass0=space.start.get("mass"), offset0=space.start.get("offset", 0.0))
    except (SolverError, ValueError, ArithmeticError):
        return None
    found = {n: res.estimate(n) for n in res.names if n in space.free}
    if set(found) != set(space.free) or not all(math.isfinite(v) for v in found.values()):
        return None
    inside = all(space.low.get(n, -math.inf) <= v <= space.high.get(n, math.inf) for n, v in found.items())
    if not inside or found[gamma] < 1.0:
        return None
    try:
        new = space.build(dict(space.start, **found))
    except ValueError:
        return None
    said = ", ".join(f"{n} {space.start[n]:.4g} -> {v:.4g}" + (" kg" if n == "mass" else " N" if n == "offset" else "")
                     for n, v in found.items())
    line = (f"start from the force balance (the inverse model u - m a - F_off along the filtered positions, "
            f"identify.fit_inverse): {said}; {gamma} held at {found[gamma]:.4g} in a first stage (at most {HELD_EVALS} "
            f"evaluations per layout), then freed")
    return BalanceStart(new, found.get("mass"), found.get("offset", space.start.get("offset", 0.0)), line, gamma)
