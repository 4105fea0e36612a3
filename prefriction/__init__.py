"""prefriction: pre-sliding friction hysteresis (Ruderman 2023): models, simulation, analysis.

Public API, re-exported from private modules:

- models (:mod:`prefriction.models`): :class:`FrictionModel` (the protocol), :class:`Dahl`,
  :class:`MaxwellSlip`, :class:`GMS`, :class:`LuGre`, :class:`Viscous`, :class:`Parallel` (``a + b``),
  :class:`Oscillator`, :class:`Parameter`
- input signals: :mod:`prefriction.signals` (``Constant``, ``Step``, ``Ramp``, ``Sine``,
  ``Chirp``, ``Samples``, ``ZeroOrderHold`` and sums; compiled once per kind)
- analytics: :mod:`prefriction.dahl` (exact and approximate reversal maps, energies; Dahl only)
- exact reference: :func:`exact_reversals` (Dahl only)
- the force along a prescribed or measured motion: :func:`friction_along` (:class:`AlongResult`),
  sample by sample :class:`FrictionStream` (:mod:`prefriction.along`)
- simulation: :func:`simulate` (closed linear loops: :class:`LinearFeedback`), :func:`sweep`
- energy analysis: :mod:`prefriction.energy`
- model checks for new models: :mod:`prefriction.testing`
- measured records: :mod:`prefriction.data` (``tribometer()``, a reciprocating tribometer record)
- identification: :mod:`prefriction.identify` (``fit``, ``ForceDisplacement``, ``Motion``,
  ``FitResult``, ``IdentifiabilityWarning``)
- derivatives through the simulator and the exact map: :func:`sensitivities`
  (:mod:`prefriction.sensitivity`)
- describing functions and limit cycles (hunting): :mod:`prefriction.describing`
- the models and the simulator's plant as CasADi Functions: :mod:`prefriction.symbolic`
- optimal point-to-point motion through pre-sliding friction (IPOPT): :mod:`prefriction.optimal`
"""

from __future__ import annotations

import casadi as _casadi

from prefriction._requirements import check_casadi as _check_casadi

_check_casadi(_casadi.__version__)

from prefriction.errors import PrefrictionError, SolverError
from prefriction.along import AlongResult, FrictionStream, friction_along
from prefriction.models import GMS, Dahl, FrictionModel, LuGre, MaxwellSlip, Oscillator, Parallel, Parameter, Viscous
from prefriction.reversals import ReversalTable
from prefriction.units import Scales
from prefriction.simulation.simulate import SimulationResult, simulate
from prefriction.simulation.sweep import SweepResult, sweep
from prefriction.simulation.feedback import LinearFeedback
from prefriction.analysis import dahl, energy
from prefriction import optimal, sensitivity, signals, symbolic
from prefriction.sensitivity import sensitivities
from prefriction.analysis.exact import exact_reversals

__all__ = [
    "AlongResult",
    "Dahl",
    "FrictionModel",
    "FrictionStream",
    "GMS",
    "LinearFeedback",
    "LuGre",
    "MaxwellSlip",
    "Oscillator",
    "Parallel",
    "Parameter",
    "PrefrictionError",
    "ReversalTable",
    "Scales",
    "SimulationResult",
    "SolverError",
    "SweepResult",
    "Viscous",
    "controllers",
    "dahl",
    "energy",
    "exact_reversals",
    "export",
    "friction_along",
    "describing",
    "identify",
    "optimal",
    "data",
    "sensitivities",
    "sensitivity",
    "signals",
    "simulate",
    "sweep",
    "symbolic",
]
__version__ = "0.3.0"
del annotations  # bound by the __future__ import; not part of the API


_LAZY = ("controllers", "data", "describing", "export", "identify")  # python-control (1.6 s) and scipy.stats (0.6 s) on first use


def __getattr__(name: str):
    """Import :mod:`prefriction.describing` and :mod:`prefriction.identify` on first use."""
    if name in _LAZY:
        import importlib

        return importlib.import_module(f"prefriction.{name}")
    raise AttributeError(f"module 'prefriction' has no attribute {name!r}")
