"""The child process of ``prefriction bench --sweep``: one sweep in a new Python process.

:func:`run_child` starts a new interpreter with ``PREFRICTION_CACHE`` set to a given
directory; it imports :mod:`prefriction` (timed), runs :func:`worker` and prints its JSON
report. The parent counts the compiles: new ``.so`` files in the cache directory and the
``prefriction: compiling`` lines on the child's stderr (``docs/bench.md#sweep``).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from prefriction.cli.bench.sweep.cases import exact_tables, reversal_error, sweep_cases
from prefriction.cli.bench.timing import progress

COMPILE_LINE = "prefriction: compiling"


def worker(spec: dict[str, Any], import_seconds: float) -> dict[str, Any]:
    """Run one sweep in this process and measure it (the body of a child process).

    Parameters
    ----------
    spec : dict
        ``{"case": key, "n": values per sweep, "reference": path or None}``; the reference file
        (JSON, forced sweep) holds the lists ``t``, ``x``, ``F`` per value [SI].
    import_seconds : float
        Time the child took to ``import prefriction`` [s], reported back unchanged.

    Returns
    -------
    dict
        ``sweep_s`` (end-to-end time of the :func:`prefriction.sweep` call, compiling or loading
        included), ``per_value_ms``, ``sim_wall_s`` (sum of the runs' integration times),
        ``setup_s``, ``jit`` (modes and their counts), ``failed``, ``errors`` per value and
        ``error`` (their maximum), ``import_s``.
    """
    from prefriction.simulation.sweep import sweep

    case = next(c for c in sweep_cases(int(spec["n"])) if c.key == spec["case"])
    systems = [case.system(v) for v in case.values]
    start = time.perf_counter()
    res = sweep(systems, case.v0, progress=False, **case.simulate_kwargs())
    seconds = time.perf_counter() - start
    if spec.get("reference"):
        data = json.loads(Path(spec["reference"]).read_text())
        refs = list(zip(data["t"], data["x"], data["F"]))
    else:
        refs = exact_tables(case)
    ok = [r for r in res if not isinstance(r, BaseException)]
    errors = [math.inf if isinstance(r, BaseException) else
              reversal_error(r.reversals.t, r.reversals.x, r.reversals.F, *ref) for r, ref in zip(res, refs)]
    modes: dict[str, int] = {}
    for r in ok:
        modes[r.stats.jit] = modes.get(r.stats.jit, 0) + 1
    return {
        "import_s": import_seconds, "sweep_s": seconds, "per_value_ms": 1e3 * seconds / len(systems),
        "sim_wall_s": sum(r.stats.wall_time for r in ok), "setup_s": sum(r.stats.setup_time for r in ok),
        "jit": modes, "failed": len(res.failed), "errors": [_json_float(e) for e in errors],
        "error": _json_float(max(errors)),
    }


def _json_float(value: float) -> Optional[float]:
    """``value`` for JSON (``None`` for inf or nan)."""
    return value if math.isfinite(value) else None


_CHILD = (
    "import sys, time, json\n"
    "t0 = time.perf_counter()\n"
    "import prefriction\n"
    "ti = time.perf_counter() - t0\n"
    "from prefriction.cli.bench.sweep.child import worker\n"
    "print(json.dumps(worker(json.loads(sys.argv[1]), ti)))\n"
)


@dataclass
class ChildRun:
    """What one child process measured, and the compiles it caused."""

    report: dict[str, Any]
    new_libraries: int
    compile_lines: int


def run_child(spec: dict[str, Any], cache: Path) -> ChildRun:
    """Run :func:`worker` in a new Python process with ``PREFRICTION_CACHE=cache``.

    Parameters
    ----------
    spec : dict
        The worker's spec (see :func:`worker`).
    cache : pathlib.Path
        Compiled-code cache directory of the child.

    Returns
    -------
    ChildRun
        The child's JSON report, the number of ``.so`` files it added to ``cache`` and the number
        of ``prefriction: compiling`` lines on its stderr.

    Raises
    ------
    RuntimeError
        If the child fails or prints no JSON report.
    """
    before = set(cache.glob("*.so"))
    env = dict(os.environ, PREFRICTION_CACHE=str(cache))
    proc = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(spec)], env=env, capture_output=True,
                          text=True, timeout=900)
    lines = [line for line in proc.stderr.splitlines() if line.startswith(COMPILE_LINE)]
    for line in lines:
        progress(f"  child: {line}")
    if proc.returncode != 0 or not proc.stdout.strip():
        raise RuntimeError(f"bench --sweep child failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    return ChildRun(report, len(set(cache.glob("*.so")) - before), len(lines))
