"""Fit a :class:`StaticFriction` map to :class:`ForceVelocity` data (nonlinear least squares).

``scipy.optimize.least_squares`` (trust-region reflective, bounds: every level and ``vs``,
``delta`` positive, ``b >= 0``) on the residuals ``F_map(v) + F_off - F`` with the analytic
Jacobian of the map; Gauss-Newton standard errors and 95 % intervals as for every fit
(:func:`prefriction.identify.statistics.gauss_newton`). Without a Stribeck term the map is
linear in its parameters and the fit is the ordinary least-squares solution.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from prefriction._blas_threads import one_blas_thread
from prefriction.identify.data import ForceVelocity
from prefriction.identify.result import FitResult
from prefriction.identify.static_map import StaticFriction
from prefriction.identify.statistics import IdentifiabilityWarning, at_bounds, gauss_newton

__all__ = ["fit_static"]


def _names(arg: str, value: Any, allowed: list[str]) -> list[str] | None:
    if value is None:
        return None
    out = [value] if isinstance(value, str) else list(value)
    for n in out:
        if n not in allowed:
            raise ValueError(f"{arg} names an unknown parameter {n!r} of this StaticFriction (allowed: {allowed})")
    return out


def fit_static(model: StaticFriction, data: ForceVelocity, *, free: Any, fixed: Any, bounds: Any, offset: bool,
               max_iter: int, tol: float, limit: float) -> FitResult:
    """Least-squares fit of ``model``'s free parameters (and an offset) to ``data``.

    Raises
    ------
    ValueError
        For unknown names, no free parameter, or bounds outside the allowed range or not
        containing the start value.
    """
    allowed = list(model.names) + (["offset"] if offset else [])
    free_l, fixed_l = _names("free", free, allowed), _names("fixed", fixed, allowed) or []
    names = [n for n in allowed if n not in fixed_l] if free_l is None else [n for n in allowed if n in free_l]
    if not names:
        raise ValueError(f"no parameter left to fit: free = {free!r}, fixed = {fixed!r} (allowed names: {allowed})")
    start = {**model.values(), "offset": 0.0}
    lower = {n: (-np.inf if n == "offset" else 0.0) for n in allowed}
    upper = {n: np.inf for n in allowed}
    why = {n: "the declared range" for n in allowed}
    why_low, why_high = dict(why), dict(why)
    if bounds is not None and not isinstance(bounds, dict):
        raise TypeError(f"bounds must be a dict {{name: (low, high)}}, got {bounds!r} of type {type(bounds).__name__}")
    for n, lim in (bounds or {}).items():
        if n not in allowed:
            raise ValueError(f"bounds names an unknown parameter {n!r} (allowed: {allowed})")
        lo, hi = (float(x) for x in lim)
        if not (lower[n] <= lo < hi <= upper[n]) or not lo <= start[n] <= hi:
            raise ValueError(f"bounds[{n!r}] = {lim!r} must satisfy {lower[n]!r} <= low < high <= {upper[n]!r} and "
                             f"contain the start value {start[n]!r}")
        lower[n], upper[n], why_low[n], why_high[n] = lo, hi, "the user bound", "the user bound"
    scale = np.array([abs(start[n]) if start[n] != 0.0 else max(float(np.std(data.F)), 1e-300) for n in names])
    v, F = data.v, data.F

    def unpack(theta: np.ndarray) -> tuple[StaticFriction, float]:
        vals = dict(start)
        vals.update({n: float(t) * s for n, t, s in zip(names, theta, scale)})
        off = vals.pop("offset")
        return model.replace({n: vals[n] for n in model.names}), off

    cols = [list(model.names).index(n) if n != "offset" else -1 for n in names]

    def residuals(theta: np.ndarray) -> np.ndarray:
        m, off = unpack(theta)
        return m.force(v) + off - F

    def jac(theta: np.ndarray) -> np.ndarray:
        m, _ = unpack(theta)
        Jm = m.force_and_jacobian(v)[1]
        return np.column_stack([np.ones_like(v) if c < 0 else Jm[:, c] for c in cols]) * scale

    lo = np.array([lower[n] for n in names]) / scale
    hi = np.array([upper[n] for n in names]) / scale
    lo = np.where(np.array([n in ("Fc", "Fs", "vs", "delta", "Fc_neg", "Fs_neg") for n in names]) & (lo <= 0.0),
                  1e-9, lo)
    theta0 = np.array([start[n] for n in names]) / scale
    with one_blas_thread():
        sol = least_squares(residuals, theta0, jac=jac, bounds=(lo, hi), method="trf", xtol=tol, ftol=tol, gtol=tol,
                            max_nfev=max_iter, x_scale="jac")
    fitted_model, off = unpack(sol.x)
    est = sol.x * scale
    stats = gauss_newton(jac(sol.x), sol.fun, names, est, scale, limit=limit)
    for name, reason in stats.unidentifiable:
        warnings.warn(f"the data cannot identify {name}: {reason}; its interval is meaningless. Fix it "
                      f"(fixed=[{name!r}]) or measure at velocities that excite it", IdentifiabilityWarning,
                      stacklevel=4)
    low, high, flags = at_bounds(names, est, stats.low, stats.high, scale, lower, upper, why_low, why_high)
    fitted = F + sol.fun
    return FitResult(fitted_model, None, tuple(names), tuple("N" if n == "offset" else model.unit(n) for n in names),
                     est, stats.stderr, low, high, stats.correlation, -sol.fun, fitted, data, stats,
                     {}, f"least_squares: {sol.message}", success=bool(sol.success), flags=flags)
