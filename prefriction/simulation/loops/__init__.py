"""Positioning loops in compiled code: the sampled-data loop over many samples per call.

:func:`run_sampled` runs a discrete linear controller with zero-order hold (and an optional
force limit with back-calculation anti-windup) around the reversal-aware plant of
:func:`prefriction.simulate`, ``BLOCK`` samples per compiled call (``docs/controllers.md``).
:mod:`.feedback_loop` runs a sampled ``LinearFeedback`` of :func:`prefriction.simulate` on the
same native loop. The names below are loaded on first use: the simulator's plant builder
imports :mod:`.feedback_loop`, and :mod:`.runner` builds on the simulator.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["BLOCK", "LoopStats", "run_sampled"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        return getattr(importlib.import_module(".runner", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
