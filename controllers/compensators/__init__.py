"""Friction compensators for the sampled positioning loop (``docs/compensation.md``).

Each compensator adds a force to the controller's at every sample of
:func:`controllers.simulate_loop` (``compensator=``), inside the compiled loop: its per-sample
update is a CasADi Function ``(state, meas, ref, params) -> (state_next, force)``
(:meth:`Compensator.update_function`, :meth:`Compensator.numbers`), compiled once per structure.

- :class:`Feedforward`: the friction of an identified model driven along the reference motion,
  plus the inertia term ``m a_ref``;
- :class:`LuGreObserver`: the observer of Canudas de Wit, Olsson, Astrom and Lischinsky (1995),
  section V;
- :class:`FrictionObserver`: a reduced-order Luenberger observer of velocity and friction from
  the position alone (Ruderman 2023, 2025);
- :class:`DisturbanceObserver`: the nominal inverse plant with a Q-filter (model-free peer).
"""

from ._base import Compensator, scaled_model
from .disturbance_observer import DisturbanceObserver
from .feedforward import Feedforward
from .friction_observer import FrictionObserver
from .lugre_observer import LuGreObserver

__all__ = ["Compensator", "DisturbanceObserver", "Feedforward", "FrictionObserver", "LuGreObserver", "scaled_model"]
