"""Positioning loops in compiled code: the sampled-data loop over many samples per call.

:func:`run_sampled` runs a discrete linear controller with zero-order hold (and an optional
force limit with back-calculation anti-windup) around the reversal-aware plant of
:func:`prefriction.simulate`, ``BLOCK`` samples per compiled call (``docs/controllers.md``).
"""

from .runner import BLOCK, LoopStats, run_sampled

__all__ = ["BLOCK", "LoopStats", "run_sampled"]
