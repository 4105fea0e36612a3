"""C code for real-time targets: friction models, compensated controllers and the plant, in C99.

- :func:`c_source`: a friction model sampled along measured positions (``<name>_reset``,
  ``<name>_force``), the streaming form of the friction along a measured motion;
- :func:`sample_function`: the CasADi Function that code is generated from (evaluate it in Python);
- :class:`CSource`: what an export wrote;
- :func:`run_c` (compile and run with gcc, time per step) and :func:`evaluate` (the same in Python);
- :func:`plant_source`: the stage over one sample period with a held force, every reversal
  located (hardware in the loop), from :func:`plant_function`; :func:`run_plant_c` and
  :func:`evaluate_plant` run it;
- :func:`controller_source`: a (compensated) positioning controller at a fixed sample time, from
  :func:`controller_function`; :func:`run_loop_c` closes the loop of it and the plant in C.

Every export writes a header and a source that depend on ``<math.h>`` only (``gcc -std=c99``,
link with ``-lm``); the numbers of the model are constants of the code. See ``docs/export.md``.
"""

from .controller import controller_function, controller_initial_state, controller_source
from .loop_run import LoopRun, run_loop_c
from .model import c_source, sample_function
from .plant import plant_function, plant_initial_state, plant_source
from .plant_run import PlantRun, evaluate_plant, run_plant_c
from .run import CRun, evaluate, gcc, run_c
from .source import CSource

__all__ = ["CRun", "CSource", "LoopRun", "PlantRun", "c_source", "controller_function", "controller_initial_state",
           "controller_source", "evaluate", "evaluate_plant", "gcc", "plant_function", "plant_initial_state",
           "plant_source", "run_c", "run_loop_c", "run_plant_c", "sample_function"]
