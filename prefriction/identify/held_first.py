"""Parameters a Motion fit holds in its first stage: those the record pins only together with another.

A GMS slip transient (an element that breaks away at ``alpha_i Fs`` and relaxes towards
``alpha_i S(v)`` at the rate ``C / (alpha_i S)``) is seen in the positions through the area it
adds to the friction force, and a larger break-away force with a faster relaxation adds about the
same area as a smaller one with a slower relaxation. A record that slides mostly faster than the
Stribeck velocity ``vs`` therefore pins one combination of the excess ``Fs - Fc`` and the
attraction rate ``C``: a curved valley of the sum of squares. Measured on the 1,000-sample GMS(2)
records of :mod:`prefriction.identify._success_events` (``Fs = 1.3``, ``C = 50``): the valley
runs through ``(Fs, C) = (1.15, 100)``, ``(1.3, 50)`` and ``(1.8, 25)`` with its floor within
2 residual variances, while a point off it, ``(1.11, 41)``, lies 67 residual variances above; a
fit with both free from a factor-2 start stopped there (the trust region creeps along the bend),
with the stiffnesses 3 standard errors from the truth.

Held at any value of ``C``, the valley's cross-section in ``Fs`` is a clean minimum (``Fs`` has
all of ``[Fc, inf)`` to reach it), so the first stage fits with ``C`` held at its start and lands
on the valley floor; the second frees ``C`` from there (:func:`prefriction.identify.continuation.fit_motion`).
On the floor, the parameters the record does pin (stiffnesses, ``Fc``, mass, offset) take the
values of the truth's neighbourhood wherever along the valley ``C`` and ``Fs`` end, and the
statistics report ``C`` and ``Fs`` as not identifiable when the valley is that flat.
"""

from __future__ import annotations

from prefriction.identify.parameters import ParameterSpace
from prefriction.models.base import FrictionModel
from prefriction.models.gms import GMS

__all__ = ["held_first", "valley"]


def held_first(model: FrictionModel, space: ParameterSpace) -> tuple[str, ...]:
    """The free parameters of ``space`` a first stage holds at their start values (module notes):
    ``("C",)`` for a :class:`prefriction.GMS` with ``C`` and ``Fs`` both free, else ``()``."""
    if isinstance(model, GMS) and "C" in space.free and "Fs" in space.free:
        return ("C",)
    return ()


def valley(model: FrictionModel, space: ParameterSpace) -> tuple[str, ...]:
    """The free parameters of ``space`` along the curved valley (module notes) whose intervals the
    linearisation may understate: ``("C", "Fs")`` for a :class:`prefriction.GMS` with both free."""
    return ("C", "Fs") if held_first(model, space) == ("C",) else ()
