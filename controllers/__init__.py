"""controllers: PD/PID positioning loops around the pre-sliding friction stage.

Controllers are python-control LTI objects (or a :class:`PID` description that produces one);
the loop is simulated by :func:`simulate_loop` with the reversal-aware plant of
:func:`prefriction.simulate`. :func:`plant_iosys` gives the same plant as a
``control.NonlinearIOSystem`` for python-control's own tools (less accurate, see its notes).
"""

from __future__ import annotations

from ._iosys import plant_iosys
from ._linear import (
    Margins,
    UnstableLoopWarning,
    closed_loop,
    design_pd,
    design_pid,
    linear_plant,
    margins,
)
from ._loop import LoopResult, simulate_loop
from ._pid import PID, pd, pid

__all__ = [
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
