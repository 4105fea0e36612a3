"""Describing functions of friction models and limit-cycle prediction (python-control).

- :func:`dahl_describing_function`, :class:`DahlDescribingFunction`: Dahl (3.2) with
  gamma = 1 in closed form;
- :func:`friction_describing_function`, :func:`plant_describing_function`: any protocol model,
  from one settled cycle (friction alone under a displacement; mass and friction under a force);
- :class:`FrictionDescribingFunction`, :class:`PlantDescribingFunction`: the same as
  python-control ``DescribingFunctionNonlinearity`` objects (with ``at(omega)`` for
  rate-dependent blocks);
- :func:`velocity_loop`, :class:`VelocityDescribingFunction`: friction as a nonlinearity of the
  velocity, ``G(s) = s / (m s^2 + C(s))``;
- :func:`friction_loop`, :func:`predict_limit_cycles` / :func:`predict_limit_cycle` (every
  harmonic balance, stability over all modes),
  :func:`measure_limit_cycle`, :func:`trace_unstable_cycle`, :func:`simulate_from_cycle`: predicted against simulated limit
  cycles.

See ``docs/describing.md``.
"""

from prefriction.describing.cycle import friction_describing_function, plant_describing_function
from prefriction.describing.dahl import DahlDescribingFunction, dahl_cycle, dahl_describing_function
from prefriction.describing.limit_cycle import (
    LimitCycle,
    MeasuredCycle,
    friction_loop,
    measure_limit_cycle,
    predict_limit_cycle,
    predict_limit_cycles,
)
from prefriction.describing.nonlinearity import FrictionDescribingFunction, PlantDescribingFunction
from prefriction.describing.trace import TracedCycle, simulate_from_cycle, trace_unstable_cycle
from prefriction.describing.velocity import VelocityDescribingFunction, velocity_loop

__all__ = [
    "DahlDescribingFunction",
    "FrictionDescribingFunction",
    "LimitCycle",
    "MeasuredCycle",
    "PlantDescribingFunction",
    "TracedCycle",
    "VelocityDescribingFunction",
    "dahl_cycle",
    "dahl_describing_function",
    "friction_describing_function",
    "friction_loop",
    "measure_limit_cycle",
    "plant_describing_function",
    "predict_limit_cycle",
    "predict_limit_cycles",
    "simulate_from_cycle",
    "trace_unstable_cycle",
    "velocity_loop",
]
