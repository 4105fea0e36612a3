"""Identification: friction parameters from measurements (``docs/identify.md``).

- :func:`fit`: fit a :class:`prefriction.FrictionModel` to :class:`ForceDisplacement` data
  (force along a prescribed displacement) or :class:`Motion` data (positions of a mass under a
  known force, a free decay included), with Gauss-Newton standard errors and 95 % intervals.
- :class:`FitResult`: the fitted model, estimates, intervals, correlation, residuals,
  ``report()`` and ``plot()``.
- :class:`IdentifiabilityWarning`: names a parameter the data cannot identify.
"""

from __future__ import annotations

from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.identify.fit import fit
from prefriction.identify.result import FitResult
from prefriction.identify.statistics import IdentifiabilityWarning

__all__ = ["FitResult", "ForceDisplacement", "IdentifiabilityWarning", "Motion", "fit"]
