"""The friction force along a prescribed or measured motion (``docs/along.md``).

- :func:`friction_along` (``run.py``): the force at every sample of a record, :class:`AlongResult`
  (``result.py``);
- :class:`FrictionStream` (``stream.py``): the same, sample by sample;
- ``motion.py``: the samples as intervals of constant velocity, directions and reversals;
- ``step.py``: the interval step of a model (CasADi), shared with the fit;
- ``engine.py``: the compiled interval step of a model structure, run over blocks of samples;
- ``bench.py``: ``prefriction bench --along`` (time per 100,000 samples and error against scipy).
"""

from prefriction.along.result import AlongResult
from prefriction.along.run import friction_along
from prefriction.along.stream import FrictionStream

__all__ = ["AlongResult", "FrictionStream", "friction_along"]
