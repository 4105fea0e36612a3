"""The former module of ``prefriction bench --sweep``, now the package :mod:`prefriction.cli.bench.sweep`.

Kept so that ``import prefriction.cli.bench_sweep`` and ``python -m prefriction.cli.bench_sweep``
go on working; every name comes from :mod:`prefriction.cli.bench.sweep`.
"""

import sys

from prefriction.cli.bench.sweep import *  # noqa: F401,F403
from prefriction.cli.bench.sweep import __all__, main  # noqa: F401

if __name__ == "__main__":
    sys.exit(main())
