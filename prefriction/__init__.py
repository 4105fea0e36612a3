"""prefriction: pre-sliding friction hysteresis (Ruderman 2023): models, simulation, analysis.

Public API, re-exported from private modules:

- models (:mod:`prefriction.models`): :class:`FrictionModel` (the protocol), :class:`Dahl`,
  :class:`MaxwellSlip`, :class:`GMS`, :class:`LuGre`, :class:`ElastoPlastic`, :class:`Viscous`, :class:`Parallel` (``a + b``),
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

from typing import TYPE_CHECKING, Any as _Any

import casadi as _casadi

from prefriction._requirements import check_casadi as _check_casadi

_check_casadi(_casadi.__version__)

if TYPE_CHECKING:  # the names below, imported on first use (module __getattr__)
    from prefriction.errors import PrefrictionError, SolverError
    from prefriction.along import AlongResult, FrictionStream, friction_along
    from prefriction.models import (GMS, Dahl, DirectionalViscous, ElastoPlastic, FrictionModel, LuGre, MaxwellSlip,
                                    Oscillator, Parallel, Parameter, Viscous)
    from prefriction.reversals import ReversalTable
    from prefriction.units import Scales
    from prefriction.simulation.simulate import SimulationResult, simulate
    from prefriction.simulation.sweep import SweepResult, sweep
    from prefriction.simulation.feedback import LinearFeedback
    from prefriction.analysis import dahl, energy
    from prefriction import (controllers, data, describing, export, identify, optimal, sensitivity, signals,
                             symbolic)
    from prefriction.sensitivity import sensitivities
    from prefriction.analysis.exact import exact_reversals

__version__ = "0.8.8"
del annotations, TYPE_CHECKING  # bound by the imports above; not part of the API

# where each public name lives: _WHERE, the module it is an attribute of; _MODULES, the public
# names that are modules themselves. Importing the package imports CasADi only (0.3 s, for the version check); scipy, python-control and the
# rest load on first use of a name that needs them (0.8 s for everything).
_WHERE = {
    **dict.fromkeys(["PrefrictionError", "SolverError"], "prefriction.errors"),
    **dict.fromkeys(["AlongResult", "FrictionStream", "friction_along"], "prefriction.along"),
    **dict.fromkeys(["GMS", "Dahl", "DirectionalViscous", "ElastoPlastic", "FrictionModel", "LuGre", "MaxwellSlip",
                     "Oscillator", "Parallel", "Parameter", "Viscous"], "prefriction.models"),
    "ReversalTable": "prefriction.reversals",
    "Scales": "prefriction.units",
    **dict.fromkeys(["SimulationResult", "simulate"], "prefriction.simulation.simulate"),
    **dict.fromkeys(["SweepResult", "sweep"], "prefriction.simulation.sweep"),
    "LinearFeedback": "prefriction.simulation.feedback",
    "sensitivities": "prefriction.sensitivity",
    "exact_reversals": "prefriction.analysis.exact",
}
_MODULES = {"dahl": "prefriction.analysis.dahl", "energy": "prefriction.analysis.energy",
            **{name: f"prefriction.{name}" for name in ("controllers", "data", "describing", "export", "identify",
                                                         "optimal", "sensitivity", "signals", "symbolic")}}
__all__ = sorted([*_WHERE, *_MODULES])


def __getattr__(name: str) -> _Any:
    """Import a public name on first use (and keep it: later lookups are plain attributes)."""
    import importlib

    if name in _MODULES:
        value = importlib.import_module(_MODULES[name])
    elif name in _WHERE:
        value = getattr(importlib.import_module(_WHERE[name]), name)
    else:
        raise AttributeError(f"module 'prefriction' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
