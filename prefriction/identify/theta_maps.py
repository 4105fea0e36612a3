"""The maps between the scaled free entries ``theta`` of a fit and the physical parameter values
(the mixin :class:`ThetaMaps` of :class:`prefriction.identify.parameters.ParameterSpace`).

The fit moves ``theta = p / scale``; a related pair with both ends free (``Fs >= Fc``) moves
the excess ``(p_high - p_low) / scale``, and an entry bounded by a ratio (``z_ba < Fc /
sigma0``) its fraction of the ratio (:mod:`prefriction.identify.entry_bounds`). These maps
go both ways, on numbers and on CasADi symbols, and transform the Jacobian for the statistics
of the physical parameters.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["ThetaMaps"]


class ThetaMaps:
    """``theta`` to physical values and back, their bounds, and the Jacobian's change of variables
    (module notes); mixin of :class:`prefriction.identify.parameters.ParameterSpace`, which sets
    ``free``, ``fixed``, ``start``, ``low``, ``high``, ``excess``, ``fraction`` and ``_scale``
    and gives ``scale`` and ``n_free``."""

    def theta_of(self, values: dict[str, float]) -> np.ndarray:
        """The scaled free entries at the physical ``values`` (by name, every free entry and the
        partners of its relations): the inverse of :meth:`values` inside the bounds (an excess
        over its partner, a fraction of its ratio bound)."""
        raw = dict(values)
        for hi_name, lo_name in self.excess.items():
            raw[hi_name] = values[hi_name] - values[lo_name]
        for name, (num, den) in self.fraction.items():
            raw[name] = values[name] * (values[den] / values[num]) * (self.start[num] / self.start[den])
        return np.array([raw[n] / self._scale[n] for n in self.free])

    def theta_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the scaled free entries (an excess: ``[0, inf)``)."""
        sc = self.scale
        lo = np.array([0.0 if n in self.excess else self.low[n] / sc[i] for i, n in enumerate(self.free)])
        hi = np.array([math.inf if n in self.excess else self.high[n] / sc[i] for i, n in enumerate(self.free)])
        return np.minimum(lo, hi), np.maximum(lo, hi)

    def symbols(self, theta: Any, fixed: Any, scale: Any = None) -> dict[str, Any]:
        """Physical values by name from the scaled free entries and the fixed values (CasADi
        symbols or numbers); ``scale`` defaults to :attr:`scale`."""
        scale = self.scale if scale is None else scale
        out = {}
        for i, n in enumerate(self.free):
            out[n] = theta[i] * scale[i]
        for i, n in enumerate(self.fixed):
            out[n] = fixed[i]
        for hi_name, lo_name in self.excess.items():
            out[hi_name] = out[lo_name] + out[hi_name]
        ref = {n: scale[i] for i, n in enumerate(self.free)} | {n: fixed[i] for i, n in enumerate(self.fixed)}
        for name, (num, den) in self.fraction.items():   # start[num] / start[den] from the inputs, not baked in
            out[name] = out[name] * (out[num] / out[den]) * (ref[den] / ref[num])
        return out

    def values(self, theta: np.ndarray) -> dict[str, float]:
        """Physical values by name of the scaled free entries ``theta`` (fixed ones at start),
        clipped to the allowed ranges (a value a rounding error past a bound is the bound)."""
        out = dict(self.start)
        sc = self.scale
        for i, n in enumerate(self.free):
            out[n] = min(max(float(theta[i]) * sc[i], self.low[n]), self.high[n]) if n not in self.excess \
                else max(float(theta[i]) * sc[i], 0.0)
        for hi_name, lo_name in self.excess.items():
            out[hi_name] = min(out[lo_name] + out[hi_name], self.high[hi_name])
        for name, (num, den) in self.fraction.items():
            out[name] = out[name] * (out[num] / out[den]) * (self.start[den] / self.start[num])
        return out

    def limits(self, values: dict[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """The allowed range of every entry at ``values``: a related ``high`` entry moved as an
        excess is bounded below by its partner's value."""
        low = dict(self.low)
        for hi_name, lo_name in self.excess.items():
            low[hi_name] = max(low[hi_name], values[lo_name])
        high = dict(self.high)
        for name, (num, den) in self.fraction.items():
            high[name] = values[num] / values[den]
        return low, high

    def physical_jacobian(self, J: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``J`` (columns: the scaled free entries first), taken at the scaled free entries
        ``theta``, with respect to ``p / s`` instead, ``s`` the start values (the offset's force
        scale), and ``s``: what the statistics of the physical parameters need when a related pair
        is moved as an excess, or an entry bounded by a ratio as its fraction (whose derivative
        depends on ``theta``)."""
        s = np.array([abs(self.start[n]) if n in self.excess else self._scale[n] for n in self.free])
        if not self.excess and not self.fraction:
            return J, s
        k = self.n_free
        M = np.eye(k)
        sc = self.scale
        for hi_name, lo_name in self.excess.items():
            i, j = self.free.index(hi_name), self.free.index(lo_name)
            M[i, i] = s[i] / sc[i]       # d theta_excess / d (p_high / s_high)
            M[i, j] = -s[j] / sc[i]      # d theta_excess / d (p_low / s_low)
            M[j, j] = s[j] / sc[j]
        if self.fraction:
            p = self.values(theta)
            for name, (num, den) in self.fraction.items():
                i = self.free.index(name)
                c = (self.start[num] / self.start[den]) * p[den] / p[num] / sc[i]  # theta_i = c' p_name den / num
                M[i, i] = c * s[i]
                if den in self.free:
                    M[i, self.free.index(den)] = c * p[name] / p[den] * s[self.free.index(den)]
                if num in self.free:
                    M[i, self.free.index(num)] = -c * p[name] / p[num] * s[self.free.index(num)]
        J = np.array(J, dtype=float, copy=True)
        J[:, :k] = J[:, :k] @ M
        return J, s
