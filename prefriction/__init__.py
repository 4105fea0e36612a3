"""prefriction: pre-sliding friction hysteresis (Ruderman 2023, Dahl model).

Public API, re-exported from private modules:

- models: :class:`Dahl`, :class:`Oscillator`, :class:`FrictionModel`
- analytics: :mod:`prefriction.dahl` (exact and approximate reversal maps, energies)
- exact reference: :func:`exact_reversals`
- simulation: :func:`simulate` (closed linear loops: :class:`LinearFeedback`)
- energy analysis: :mod:`prefriction.energy`
"""

from __future__ import annotations

from .errors import PrefrictionError, SolverError
from .models import Dahl, FrictionModel, Oscillator
from .reversals import ReversalTable
from .units import Scales
from .simulate import SimulationResult, simulate
from ._feedback import LinearFeedback
from . import energy
from . import dahl
from .exact import exact_reversals

__all__ = [
    "Dahl",
    "FrictionModel",
    "LinearFeedback",
    "Oscillator",
    "PrefrictionError",
    "ReversalTable",
    "Scales",
    "SimulationResult",
    "SolverError",
    "dahl",
    "energy",
    "exact_reversals",
    "simulate",
]
__version__ = "0.1.0"
