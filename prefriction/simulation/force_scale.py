"""Size of the applied force of a run, for the error-control scale of forced runs and loops."""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from prefriction.signals import Chirp, Signal, Sine, Sum
from prefriction.simulation.feedback import LinearFeedback
from prefriction.models import Oscillator
from prefriction.units import Scales


def applied_force_scale(system: Oscillator, fb: Optional[LinearFeedback], x0: float, t_end: float) -> float:
    """Size [N] of the applied force over ``[0, t_end]`` as the motion sees it: the input's
    :func:`motion_bound` plus the feedback force ``|D| max |r - x0| + |C xc0|`` (reference
    evaluated at 257 times), at most its limit ``fb.u_max``."""
    scale = motion_bound(system.u, t_end, Scales.of(system).t) if system.forced else 0.0
    if fb is not None:
        t = np.linspace(0.0, t_end, 257)
        with np.errstate(invalid="ignore"):
            r = np.asarray(fb.reference(t), dtype=float)
            f = abs(fb.D[0, 0]) * float(np.nanmax(np.abs(r - x0), initial=0.0))
        f += float(np.abs(fb.C[0] @ fb.xc0))
        scale += f if fb.u_max is None else min(f, fb.u_max)
    return scale


def motion_bound(u: Signal, t_end: float, t_unit: float) -> float:
    """The input's bound over ``[0, t_end]`` [N] with each sinusoid of normalised angular frequency
    ``w~ = 2 pi f t_unit > 1`` (``t_unit = sqrt(m / sigma)`` [s]) divided by ``w~``.

    Far above the oscillator's frequency a sine of amplitude ``a`` moves the mass with velocity
    amplitude ``a / w~`` and force amplitude ``a / w~^2`` (normalised), so the motion's amplitude
    ``hypot(v~, F~)`` is ``a / w~``, not ``a``: the error control stays relative to the response
    (under ``0.5 sin(30 w0 t)`` N the reversal forces, 1/150 to 1/30 of the forcing, come out
    within 1.3 rtol of the reference; relative to the forcing they were 18-49 rtol off). A chirp counts at its lower end frequency; other kinds at their
    :meth:`~prefriction.signals.Signal.bound`.
    """
    if isinstance(u, Sum):
        return sum(motion_bound(term, t_end, t_unit) for term in u.terms)
    if isinstance(u, Sine):
        return abs(u.offset) + abs(u.amplitude) / max(1.0, 2.0 * math.pi * u.frequency * t_unit)
    if isinstance(u, Chirp):
        return abs(u.amplitude) / max(1.0, 2.0 * math.pi * min(u.f0, u.f1) * t_unit)
    return u.bound(t_end)
