"""Argument checks of the energy analysis (:mod:`prefriction.energy`): sample arrays, quadrature
method, Dahl friction model; messages name the argument, its value and the allowed range."""

from __future__ import annotations

from typing import Any

import numpy as np

from prefriction.models import FrictionModel, check_oscillator

QUADRATURES = ("trapezoid", "simpson")
"""Quadrature rules of the power integrals: cumulative trapezoid or Simpson (scipy)."""
ROUNDING = 64 * np.finfo(float).eps
"""Relative slack of the checks ``|F| <= Fc`` and ``E_p <= bound`` for rounding errors."""


def sample_array(name: str, values: Any) -> np.ndarray:
    """Return ``values`` as a finite 1-D float array of length >= 2, or raise naming ``name``."""
    if isinstance(values, (str, bytes)) or values is None:
        raise TypeError(f"{name} must be a 1-D array of real numbers, got {values!r}")
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a 1-D array of real numbers, got {values!r}") from exc
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got an array of shape {arr.shape}")
    if arr.size < 2:
        raise ValueError(f"{name} must hold at least 2 samples, got {arr.size}")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} must be finite, got {name}[{i}] = {float(arr[i])!r} (allowed: finite reals)")
    return arr


def check_samples(**arrays: Any) -> list[np.ndarray]:
    """Validate sample arrays: the first is time (strictly increasing), all of equal length."""
    names = list(arrays)
    out = [sample_array(name, arrays[name]) for name in names]
    n = out[0].size
    for name, arr in zip(names[1:], out[1:]):
        if arr.size != n:
            raise ValueError(
                f"{name} has length {arr.size} but {names[0]} has length {n} "
                "(all sample arrays must have the same length)"
            )
    if names[0] == "t":
        dt = np.diff(out[0])
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ValueError(
                f"t must be strictly increasing, got t[{i + 1}] = {float(out[0][i + 1])!r} <= t[{i}] = {float(out[0][i])!r}"
            )
    return out


def check_method(method: Any) -> str:
    """Return the quadrature ``method`` if it is one of :data:`QUADRATURES`; ``ValueError`` otherwise."""
    if method not in QUADRATURES:
        raise ValueError(f"method must be one of {QUADRATURES}, got {method!r}")
    return method


def check_dahl_system(system: Any) -> tuple[FrictionModel, float]:
    """Return the (rate-independent) friction model and the mass of ``system``; ``TypeError`` otherwise."""
    return check_model(check_oscillator(system, "the energy analysis")), system.mass


def check_model(friction: Any) -> FrictionModel:
    """Return ``friction`` if it is a rate-independent :class:`prefriction.FrictionModel` with a
    branch energy (the energy analysis (2.3)-(2.12) needs it); ``TypeError`` otherwise."""
    if not isinstance(friction, FrictionModel):
        raise TypeError(f"friction must be a prefriction.FrictionModel such as Dahl, got {friction!r} "
                        f"of type {type(friction).__name__}")
    if not friction.rate_independent:
        raise TypeError(f"the energy analysis needs a rate-independent friction model, got {type(friction).__name__}")
    if type(friction).branch_energy_of_force is FrictionModel.branch_energy_of_force:
        raise TypeError(f"the energy analysis needs the branch energy as a function of the force; "
                        f"{type(friction).__name__} does not define branch_energy_of_force")
    return friction
