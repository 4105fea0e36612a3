"""Size of the applied force of a run, for the error-control scale of forced runs and loops, and
the range of motion amplitudes a run accepts (:func:`check_amplitude`)."""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from prefriction.signals import Chirp, Signal, Sine, Sum
from prefriction.simulation.feedback import LinearFeedback
from prefriction.models import Oscillator
from prefriction.units import Scales

MIN_AMPLITUDE = 1e-150
"""Least nonzero amplitude of the motion (normalised units) that :func:`prefriction.simulate` accepts: the
energies, ``A^2``, and the scaled states stay normal doubles."""
MAX_AMPLITUDE = 1e100
"""Largest amplitude of the motion (normalised units) that :func:`prefriction.simulate` accepts: energies
``A^2`` and first excursions ``~A^2 / 2`` stay far from the double-precision range."""


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


def check_amplitude(v0: float, F0: float, force_scale: float, sc: Scales) -> None:
    """``ValueError`` if the motion is nonzero but smaller than :data:`MIN_AMPLITUDE` (normalised
    initial velocity ``v0`` [m/s], force ``F0`` [N] and applied force scale): its scaled states, energies and steps
    would leave the double-precision range (a denormal ``v0 = 5e-324`` m/s gave reversal times
    12 % wrong, ``1e-300`` m/s a failed integrator); or larger than :data:`MAX_AMPLITUDE`."""
    if abs(v0 / sc.v) > MAX_AMPLITUDE:
        raise ValueError(f"v0 must satisfy |v0| <= {MAX_AMPLITUDE * sc.v:.3g} m/s ({MAX_AMPLITUDE:g} velocity units "
                         f"Fc/sqrt(m sigma): energies stay in the double-precision range), got {v0!r}")
    if force_scale > MAX_AMPLITUDE:
        raise ValueError(f"the applied force (input u and feedback) must stay below {MAX_AMPLITUDE * sc.F:.3g} N "
                         f"({MAX_AMPLITUDE:g} Fc), got a force scale of {force_scale * sc.F:.3g} N")
    amplitude = max(math.hypot(v0 / sc.v, F0 / sc.F), force_scale)
    if 0.0 < amplitude < MIN_AMPLITUDE:
        raise ValueError(
            f"v0 = {v0!r} m/s and F0 = {F0!r} N (with the applied force) give a motion of "
            f"{amplitude:.3g} normalised units, too small to simulate in double precision: the amplitude "
            f"hypot(v0 / (Fc/sqrt(m sigma)), F0 / Fc) must be 0 or >= {MIN_AMPLITUDE:g}, that is "
            f"|v0| >= {MIN_AMPLITUDE * sc.v:.3g} m/s or |F0| >= {MIN_AMPLITUDE * sc.F:.3g} N"
        )
