"""Identification: friction parameters from measurements (``docs/identify.md``).

- :func:`fit`: fit a :class:`prefriction.FrictionModel` to :class:`ForceDisplacement` data
  (force along a prescribed displacement) or :class:`Motion` data (positions of a mass under a
  known force, a free decay included), with standard errors and 95 % intervals that allow for
  correlated residuals (HAC) and, for force-displacement data, noisy quantised positions.
- :class:`FitResult`: the fitted model, estimates, intervals, correlation, residuals,
  ``report()`` and ``plot()``.
- :class:`IdentifiabilityWarning`: names a parameter the data cannot identify;
  :class:`BoundWarning`: an estimate on a bound; :class:`ConvergenceWarning`: a fit that
  stopped without converging.
- :class:`ResidualWarning`: residuals with structure the model does not explain (runs, spikes
  at reversals), naming the estimates to distrust (``FitResult.diagnostics``).
- :class:`NoisyPositionsWarning`: force-displacement positions that turn at the noise, with no
  ``x_noise``/``quantum`` declared.
- :class:`Validation`: prediction errors on held-out data (``FitResult.validate``).
- :class:`ForceVelocity` and :class:`StaticFriction`: steady-sliding force against velocity and
  the classic static map (Coulomb + viscous + Stribeck, direction-dependent levels) it fits.
- Closed-loop records (``docs/identify.md#closed-loop-records``): :func:`fit_inverse` (the
  inverse model: the force balance along the filtered motion, :func:`inverse_start` its start
  values for other routes), :func:`fit_closed_loop` (output error of the model simulated inside
  the known :class:`DigitalLoop`), :func:`recommend` (which route a record needs).
"""

from __future__ import annotations

from prefriction.identify.closed_loop_fit import fit_closed_loop, simulate_closed_loop
from prefriction.identify.data import ForceDisplacement, ForceVelocity, Motion
from prefriction.identify.digital_loop import DigitalLoop
from prefriction.identify.fit import fit
from prefriction.identify.inverse import fit_inverse, inverse_start
from prefriction.identify.routes import Recommendation, recommend
from prefriction.identify.result import FitResult
from prefriction.identify.static_map import StaticFriction
from prefriction.identify.statistics import (BoundWarning, ConvergenceWarning, IdentifiabilityWarning,
                                             NoisyPositionsWarning, ResidualWarning)
from prefriction.identify.validation import Validation

__all__ = ["BoundWarning", "ConvergenceWarning", "DigitalLoop", "FitResult", "ForceDisplacement", "ForceVelocity",
           "IdentifiabilityWarning", "Motion", "NoisyPositionsWarning", "Recommendation", "ResidualWarning",
           "StaticFriction", "Validation", "fit", "fit_closed_loop", "fit_inverse", "inverse_start", "recommend",
           "simulate_closed_loop"]
