"""C code for real-time targets: friction models, compensated controllers and the plant, in C99.

- :func:`c_source`: a friction model sampled along measured positions (``<name>_reset``,
  ``<name>_force``), the streaming form of the friction along a measured motion;
- :func:`sample_function`: the CasADi Function that code is generated from (evaluate it in Python);
- :class:`CSource`: what an export wrote;
- :func:`run_c` (compile and run with gcc, time per step) and :func:`evaluate` (the same in Python).

Every export writes a header and a source that depend on ``<math.h>`` only (``gcc -std=c99``,
link with ``-lm``); the numbers of the model are constants of the code. See ``docs/export.md``.
"""

from .model import c_source, sample_function
from .run import CRun, evaluate, gcc, run_c
from .source import CSource

__all__ = ["CRun", "CSource", "c_source", "evaluate", "gcc", "run_c", "sample_function"]
