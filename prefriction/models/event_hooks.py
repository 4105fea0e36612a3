"""In-branch events and reversals of a friction model, mixed into :class:`prefriction.FrictionModel`.

A model with in-branch events (an element that starts to slip, a mode that switches) gives
their indicators (:meth:`EventHooks.events`) and the state just after each
(:meth:`EventHooks.on_event`); every model gives the state just after a velocity reversal
(:meth:`EventHooks.reverse`). The defaults here: no events, and a reversal that keeps the
state and clears the flags. Everything is in the normalised units of :mod:`prefriction.units`,
on floats, numpy arrays and CasADi ``SX`` symbols alike.
"""

from __future__ import annotations

from typing import Any, Sequence

__all__ = ["EventHooks"]


class EventHooks:
    """The event and reversal hooks of a friction model with their defaults (module notes); a
    model overrides those it has. Used through :class:`prefriction.FrictionModel`."""

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        """In-branch event indicators: positive before the event, the event where one turns negative.

        An indicator that must not fire (e.g. its element already slips) returns a positive
        constant. The list has :attr:`n_events` entries.
        """
        return []

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """State ``(z, m)`` just after in-branch event ``k``."""
        raise NotImplementedError(f"{type(self).__name__} has no in-branch events")

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        """State ``(z, m)`` just after a velocity reversal into direction ``s_new``.

        ``snap`` is the relative tolerance of the run: an event whose indicator is within
        ``snap`` of zero at the reversal may be taken as coinciding with it. Default: the
        state carries over and the flags clear (the modes end with the motion).
        """
        return list(z), [0.0 * f for f in m]
