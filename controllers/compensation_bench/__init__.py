"""``prefriction bench --compensation``: PID alone against PID with each friction compensator.

:mod:`.cases` holds the stage, the plants, the compensators and the tasks; :mod:`.metrics` the
measures of a run (RMS and largest error, the spike after each reference reversal, settling,
effort); :mod:`.report` runs the cases, times the loops against python-control and formats the
table and the figures (``docs/compensation.md#bench``).
"""

from .report import main, run

__all__ = ["main", "run"]
