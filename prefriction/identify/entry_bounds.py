"""Bounds and relations of the entries of a :class:`prefriction.identify.parameters.ParameterSpace`.

Three kinds, each made part of the fit so that it always returns a model that constructs:

- a user's bound ``(low, high)`` inside the declared range (:meth:`ParameterConstraints._set_bound`);
- a relation ``value[high] >= value[low]`` (``Fs >= Fc``): with one end fixed it bounds the
  other; with both free the fit moves ``high - low >= 0`` (:meth:`ParameterConstraints._relate`);
- a ratio bound ``value[name] < value[num] / value[den]`` (ElastoPlastic's ``z_ba < Fc /
  sigma0``): with ``name`` free it is moved as a fraction of the ratio; with ``num`` or ``den``
  free and the others fixed it bounds that one (:meth:`ParameterConstraints._bound_by_ratio`).

Each end also records why it is where it is (``why_low``, ``why_high``: the declared range, a
structure boundary, a fixed partner, the user bound), for the result's flags.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["OPEN", "ParameterConstraints"]

OPEN = 1e-9
"""Relative margin kept from an open end of a parameter's range (``0 < sigma``)."""


class ParameterConstraints:
    """The bound-setting steps of :class:`prefriction.identify.parameters.ParameterSpace` (module
    notes), run by its constructor on its ``free``, ``start``, ``low``, ``high``, ``why_low``,
    ``why_high``, ``units``, ``excess``, ``fraction`` and ``_scale`` (by name)."""

    free: list[str]
    start: dict[str, float]
    low: dict[str, float]
    high: dict[str, float]
    why_low: dict[str, str]
    why_high: dict[str, str]
    units: dict[str, str]
    excess: dict[str, str]
    fraction: dict[str, tuple[str, str]]
    _scale: dict[str, float]

    def _relate(self, lo_name: str, hi_name: str) -> None:
        """Make ``value[hi_name] >= value[lo_name]`` part of the problem (see the class text)."""
        free = set(self.free)
        why = f"{hi_name} >= {lo_name}"
        if lo_name in free and hi_name not in free:
            if self.start[hi_name] < self.high[lo_name]:
                self.high[lo_name], self.why_high[lo_name] = self.start[hi_name], f"the fixed {hi_name} ({why})"
            if self.start[lo_name] > self.high[lo_name]:
                raise ValueError(f"the start value {lo_name} = {self.start[lo_name]!r} exceeds the fixed "
                                 f"{hi_name} = {self.start[hi_name]!r}: the model needs {why}")
        elif hi_name in free and lo_name not in free:
            if self.start[lo_name] > self.low[hi_name]:
                self.low[hi_name], self.why_low[hi_name] = self.start[lo_name], f"the fixed {lo_name} ({why})"
        elif hi_name in free and lo_name in free:
            self.excess[hi_name] = lo_name
            gap = self.start[hi_name] - self.start[lo_name]
            self._scale[hi_name] = gap if gap > OPEN * abs(self.start[hi_name]) else 0.1 * abs(self.start[hi_name])
            self.why_low[hi_name] = f"{lo_name} ({why})"

    def _bound_by_ratio(self, name: str, num: str, den: str) -> None:
        """Make ``value[name] < value[num] / value[den]`` part of the problem (positive values)."""
        free, why = set(self.free), f"{name} < {num} / {den}"
        if name in free:
            ratio = self.start[num] / self.start[den]
            if self.start[name] >= ratio:
                raise ValueError(f"the start value {name} = {self.start[name]!r} must be below {num} / {den} = "
                                 f"{ratio!r}: the model needs {why}")
            if name not in self.excess and self.high[name] >= ratio:
                self.fraction[name] = (num, den)
                self.high[name], self.why_high[name] = ratio * (1.0 - OPEN), f"{num} / {den} ({why})"
        elif num in free and den not in free and self.start[name] * self.start[den] > self.low[num]:
            self.low[num] = self.start[name] * self.start[den] * (1.0 + OPEN)
            self.why_low[num] = f"the fixed {name} and {den} ({why})"
        elif den in free and num not in free and self.start[num] / self.start[name] < self.high[den]:
            self.high[den] = self.start[num] / self.start[name] * (1.0 - OPEN)
            self.why_high[den] = f"the fixed {name} and {num} ({why})"

    def _set_bound(self, name: str, lim: Any, names: list[str]) -> None:
        if name not in names:
            raise ValueError(f"bounds names an unknown parameter {name!r} (allowed: {names})")
        try:
            lo, hi = (float(v) for v in lim)
        except (TypeError, ValueError):
            raise ValueError(f"bounds[{name!r}] must be a pair (low, high) of numbers, got {lim!r}") from None
        e_lo, e_hi = self.low[name], self.high[name]
        if not (e_lo <= lo < hi <= e_hi) or math.isnan(lo) or math.isnan(hi):
            raise ValueError(f"bounds[{name!r}] = {lim!r} must satisfy {e_lo!r} <= low < high <= {e_hi!r} "
                             f"[{self.units[name]}] (the declared range)")
        if not lo <= self.start[name] <= hi:
            raise ValueError(f"bounds[{name!r}] = {lim!r} must contain the start value {self.start[name]!r}")
        if lo > e_lo:
            self.low[name], self.why_low[name] = lo, "the user bound"
        if hi < e_hi:
            self.high[name], self.why_high[name] = hi, "the user bound"
