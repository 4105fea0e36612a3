"""controllers: PD/PID positioning loops around the pre-sliding friction stage.

- Controllers are python-control LTI objects from the error ``e = r - x`` [m] to the force
  ``u`` [N]: :class:`PID` (with :func:`pd`, :func:`pid`) gives ``kp + ki/s + kd s/(tau s + 1)``
  as ``.ss()``, ``.tf()`` or ``.c2d(Ts)``; :func:`design_pd` and :func:`design_pid` place the
  poles on the pre-sliding linearisation ``1/(m s^2 + sigma)`` or the sliding one ``1/(m s^2)``;
  :func:`margins` reads gain and phase margins at the exact crossovers (``inf`` where
  there is none); :func:`closed_loop` is the linear loop
  (warns with its poles if unstable).
- :func:`simulate_loop` runs any SISO proper controller, continuous or sampled (ZOH), around
  the reversal-aware plant of :func:`prefriction.simulate`; a :class:`PID` with a force limit
  ``u_max`` adds back-calculation anti-windup (sampled loops). Returns a :class:`LoopResult`.
- Friction compensators for sampled loops (``simulate_loop(..., compensator=...)``,
  ``docs/compensation.md``): :class:`Feedforward` (an identified model along the reference,
  plus inertia), :class:`LuGreObserver` (Canudas de Wit et al. 1995), :class:`FrictionObserver`
  (Ruderman's reduced-order observer) and :class:`DisturbanceObserver` (Q-filter); measurement
  quantisation, noise, delay and model mismatch are options of :func:`simulate_loop`.
- :func:`plant_iosys` is the same stage as a ``control.NonlinearIOSystem`` for
  ``control.interconnect``; it does not locate reversals (see its notes and
  ``python -m prefriction.controllers.benchmark`` for the measured shortfall and run times).
- :mod:`controllers.plotting` draws step responses; :mod:`controllers.example_stage` holds the
  stage of ``examples/stage_*.py`` and of the benchmark and runs their step responses.
"""

from __future__ import annotations

from ._iosys import plant_iosys
from ._linear import UnstableLoopWarning, closed_loop, design_pd, design_pid, linear_plant
from ._margins import Margins, margins
from ._loop import LoopResult, simulate_loop
from ._pid import PID, pd, pid
from .compensators import DisturbanceObserver, Feedforward, FrictionObserver, LuGreObserver

__all__ = [
    "DisturbanceObserver",
    "Feedforward",
    "FrictionObserver",
    "LuGreObserver",
    "LoopResult",
    "Margins",
    "PID",
    "UnstableLoopWarning",
    "closed_loop",
    "design_pd",
    "design_pid",
    "linear_plant",
    "margins",
    "pd",
    "pid",
    "plant_iosys",
    "simulate_loop",
]
