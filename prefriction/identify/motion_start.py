"""Start values of a :class:`Motion` fit from a static least-squares fit of the measured force.

In sliding the friction of a dynamic model is close to its static map, so the record's force
balance ``u = m a + Fc sign(v) + b v + F_off`` (Coulomb, viscous and offset; ``a``, ``v`` from
a Savitzky-Golay fit of the positions) is linear in ``m``, ``Fc``, ``b`` and ``F_off``: ordinary
least squares over the samples that move faster than a tenth of the largest speed gives them
without any start value. A record that slides in one direction only cannot tell the offset
from ``Fc``: its offset starts at 0. The dynamic fit starts from them, so it never starts where the model
has no meaning (a negative force level, a NaN).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

from prefriction.identify.data import Motion
from prefriction.models.base import FrictionModel

__all__ = ["StaticStart", "derivatives", "start_model", "start_values", "static_start"]

_WINDOW = 21
"""Samples of the Savitzky-Golay window (cubic) of the velocity and acceleration estimates."""


@dataclass(frozen=True)
class StaticStart:
    """Static least-squares estimates from a record: mass [kg] (``None`` if given), Coulomb
    force [N], viscous coefficient [N s/m] and force offset [N]."""

    mass: float | None
    Fc: float
    b: float
    offset: float


def derivatives(t: np.ndarray, x: np.ndarray, window: int = _WINDOW) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smoothed position [m], velocity [m/s] and acceleration [m/s^2] at the samples (cubic
    Savitzky-Golay over ``window`` samples, the mean sample interval)."""
    w = min(window, x.size - (1 - x.size % 2))
    h = float(np.mean(np.diff(t)))
    return (savgol_filter(x, w, 3), savgol_filter(x, w, 3, deriv=1, delta=h),
            savgol_filter(x, w, 3, deriv=2, delta=h))


def static_start(data: Motion) -> StaticStart | None:
    """Least-squares Coulomb + viscous + offset (+ mass if ``data.mass`` is None) of a forced record.

    Returns
    -------
    StaticStart or None
        ``None`` for a free decay (``u = 0``: the force balance has no scale), when too few
        samples slide, or when the estimates are not physical (a mass or ``Fc`` not positive, a
        negative viscous coefficient: the record does not excite the balance enough).
    """
    if data.free_decay:
        return None
    _x, v, a = derivatives(data.t, data.x)
    moving = np.abs(v) > 0.1 * float(np.max(np.abs(v)))
    if np.count_nonzero(moving) < 8:
        return None
    sv = np.sign(v[moving])
    both = min(np.count_nonzero(sv > 0), np.count_nonzero(sv < 0)) >= 0.1 * sv.size
    cols = [np.sign(v), v, np.ones_like(v) if both else np.zeros_like(v)]
    rhs = data.u.copy()
    if data.mass is None:
        cols.insert(0, a)
    else:
        rhs = rhs - data.mass * a
    M = np.column_stack(cols)[moving]
    coef, *_ = np.linalg.lstsq(M, rhs[moving], rcond=None)  # no offset column in one direction: 0
    if data.mass is None:
        mass, coef = float(coef[0]), coef[1:]
    else:
        mass = None
    if (mass is not None and not mass > 0.0) or not coef[0] > 0.0 or not coef[1] >= 0.0:
        return None  # a record that does not excite the balance (e.g. one short move): no physical fit
    return StaticStart(mass, float(coef[0]), float(coef[1]), float(coef[2]))


def start_values(model: FrictionModel, data: Motion, mass0: float | None, free: Any, fixed: Any,
                 bounds: Any) -> tuple[FrictionModel, float | None, float, float]:
    """Start model, start mass [kg], start offset [N] and offset scale [N] of a Motion fit.

    The static estimates (:func:`static_start`) replace the start model's ``Fc`` (``Fs`` in
    proportion), its viscous coefficient (``sigma2`` of LuGre, ``b`` of a
    :class:`prefriction.Viscous` term) and ``mass0`` where they are positive and the name is
    fitted, not fixed and not bounded by the user.
    """
    fit = static_start(data)
    keep = set(_list(fixed)) | set(bounds or {})
    if free is not None:
        keep |= {p.name for p in type(model).parameters} - set(_list(free))
    model = start_model(model, fit, keep)
    if fit is not None and mass0 is not None and fit.mass is not None and fit.mass > 0.0 and "mass" not in keep:
        mass0 = fit.mass
    offset0 = fit.offset if fit is not None else 0.0
    return model, mass0, offset0, float(model.Fc)


def _list(names: Any) -> list[str]:
    if names is None:
        return []
    return [names] if isinstance(names, str) else list(names)


def start_model(model: FrictionModel, fit: StaticStart | None, keep: set[str]) -> FrictionModel:
    """``model`` with its force level (``Fc``, and ``Fs`` in proportion) and viscous coefficient
    (``sigma2``, or ``b`` of a :class:`prefriction.Viscous` term of a sum) replaced by the static
    estimates where positive, except the names in ``keep``."""
    from prefriction.models.parallel import Parallel

    if fit is None:
        return model
    if isinstance(model, Parallel):
        levels = [m for m in model.models if "Fc" in {p.name for p in type(m).parameters}]
        share = StaticStart(fit.mass, fit.Fc / max(len(levels), 1), fit.b, fit.offset)
        terms = [start_model(m, share, keep if "b" in {p.name for p in type(m).parameters} else set(keep) | {"b"})
                 for m in model.models]
        return Parallel(tuple(terms))
    names = {p.name for p in type(model).parameters}
    new: dict[str, float] = {}
    if "Fc" in names and "Fc" not in keep and fit.Fc > 0.0:
        new["Fc"] = fit.Fc
        if "Fs" in names and "Fs" not in keep:
            new["Fs"] = getattr(model, "Fs") * fit.Fc / model.Fc
    for visc in ("sigma2", "b"):
        if visc in names and visc not in keep and fit.b > 0.0:
            new[visc] = fit.b
    try:
        return dataclasses.replace(model, **new) if new else model
    except ValueError:  # e.g. Fs below the new Fc when Fs is kept: start from the user's model
        return model
