"""Size of the applied force of a run, for the error-control scale of forced runs and loops."""

from __future__ import annotations

from typing import Optional

import numpy as np

from prefriction.simulation.feedback import LinearFeedback
from prefriction.models import Oscillator


def applied_force_scale(system: Oscillator, fb: Optional[LinearFeedback], x0: float, t_end: float) -> float:
    """Size [N] of the applied force over ``[0, t_end]``: the input's bound plus the feedback
    force ``|D| max |r - x0| + |C xc0|`` (reference evaluated at 257 times)."""
    scale = system.u.bound(t_end) if system.forced else 0.0
    if fb is not None:
        t = np.linspace(0.0, t_end, 257)
        with np.errstate(invalid="ignore"):
            r = np.asarray(fb.reference(t), dtype=float)
            scale += abs(fb.D[0, 0]) * float(np.nanmax(np.abs(r - x0), initial=0.0))
        scale += float(np.abs(fb.C[0] @ fb.xc0))
    return scale
