"""The interval step of prescribed motion, where the fit imports it from.

The implementation is :mod:`prefriction.along.step` (one step for the force-displacement fit,
:func:`prefriction.friction_along` and :class:`prefriction.FrictionStream`); this module keeps
the names the fit and its users import.
"""

from prefriction.along.step import apply_events, counted_interval_function, has_exact_step, interval_function, rk4

__all__ = ["apply_events", "counted_interval_function", "has_exact_step", "interval_function", "rk4"]
