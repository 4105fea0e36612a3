"""prefriction: pre-sliding friction hysteresis (Ruderman 2023): models, simulation, analysis.

Public API, re-exported from private modules:

- models (:mod:`prefriction.models`): :class:`FrictionModel` (the protocol), :class:`Dahl`,
  :class:`MaxwellSlip`, :class:`GMS`, :class:`LuGre`, :class:`Oscillator`, :class:`Parameter`
- input signals: :mod:`prefriction.signals` (``Constant``, ``Step``, ``Ramp``, ``Sine``,
  ``Chirp``, ``Samples`` and sums; compiled once per kind)
- analytics: :mod:`prefriction.dahl` (exact and approximate reversal maps, energies; Dahl only)
- exact reference: :func:`exact_reversals` (Dahl only)
- simulation: :func:`simulate` (closed linear loops: :class:`LinearFeedback`), :func:`sweep`
- energy analysis: :mod:`prefriction.energy`
- model checks for new models: :mod:`prefriction.testing`
- identification: :mod:`prefriction.identify` (``fit``, ``ForceDisplacement``, ``Motion``,
  ``FitResult``, ``IdentifiabilityWarning``)
- derivatives through the simulator and the exact map: :func:`sensitivities`
  (:mod:`prefriction.sensitivity`)
- describing functions and limit cycles (hunting): :mod:`prefriction.describing`
"""

from __future__ import annotations

import casadi as _casadi

from prefriction._requirements import check_casadi as _check_casadi

_check_casadi(_casadi.__version__)

from prefriction.errors import PrefrictionError, SolverError
from prefriction.models import GMS, Dahl, FrictionModel, LuGre, MaxwellSlip, Oscillator, Parameter
from prefriction.reversals import ReversalTable
from prefriction.units import Scales
from prefriction.simulation.simulate import SimulationResult, simulate
from prefriction.simulation.sweep import SweepResult, sweep
from prefriction.simulation.feedback import LinearFeedback
from prefriction.analysis import dahl, energy
from prefriction import sensitivity, signals
from prefriction.sensitivity import sensitivities
from prefriction.analysis.exact import exact_reversals

__all__ = [
    "Dahl",
    "FrictionModel",
    "GMS",
    "LinearFeedback",
    "LuGre",
    "MaxwellSlip",
    "Oscillator",
    "Parameter",
    "PrefrictionError",
    "ReversalTable",
    "Scales",
    "SimulationResult",
    "SolverError",
    "SweepResult",
    "controllers",
    "dahl",
    "energy",
    "exact_reversals",
    "describing",
    "identify",
    "sensitivities",
    "sensitivity",
    "signals",
    "simulate",
    "sweep",
]
__version__ = "0.2.0"
del annotations  # bound by the __future__ import; not part of the API


_LAZY = ("controllers", "describing", "identify")  # python-control (1.6 s) and scipy.stats (0.6 s) on first use


def __getattr__(name: str):
    """Import :mod:`prefriction.describing` and :mod:`prefriction.identify` on first use."""
    if name in _LAZY:
        import importlib

        return importlib.import_module(f"prefriction.{name}")
    raise AttributeError(f"module 'prefriction' has no attribute {name!r}")
