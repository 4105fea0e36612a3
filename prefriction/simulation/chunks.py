"""Chunked execution of a sweep on an executor: bookkeeping linear in the number of systems.

:func:`run_chunks` cuts the runs of a :func:`prefriction.sweep` into chunks of consecutive
systems, submits one task per chunk and keeps at most a few chunks per worker in flight: a
finished chunk's results are written into place and its future dropped before the next chunk
is submitted. Waiting on the in-flight futures costs time proportional to their number, which
is bounded, so a sweep of 10,000 systems costs no more bookkeeping per system than one of 100
(one future per system cost ``wait(FIRST_COMPLETED)`` 3.3 ms per call at 10,000 pending ones:
quadratic in the systems, 2.2x slower than serial on two processes).

On an executor that pickles (processes, dask) a chunk's task is :func:`run_packed`: its
results come back packed in a few arrays (:mod:`prefriction.simulation.packed`) and are rebuilt
here; a thread pool's chunks run :func:`run_chunk` and return the results themselves.

A run that raises leaves its exception in its place; a chunk whose task fails as a whole (a
worker that died, a result that cannot be pickled) leaves that exception in each of its places.
"""

from __future__ import annotations

import concurrent.futures as cf
import itertools
import math
from typing import Any, Callable, Optional

from prefriction.models import Oscillator
from prefriction.simulation.packed import Packed, pack
from prefriction.simulation.simulate import simulate

__all__ = ["MAX_CHUNK", "Runs", "chunk_size", "chunk_sizes", "run_chunk", "run_chunks", "run_packed", "worker_count"]

MAX_CHUNK = 500
"""Most systems per chunk of the automatic chunk size (progress and memory per task stay small)."""
_CHUNKS_PER_WORKER = 4  # automatic chunk size: about this many full chunks per worker (a dask task costs ~5 ms of CPU)
_TAIL_PER_WORKER = 2  # automatic sizes shrink once fewer than this many full chunks per worker remain
_SMALLEST = 4  # ... down to a quarter of the full size
_IN_FLIGHT_PER_WORKER = 3  # chunks submitted ahead per worker: none waits for the parent
_WAIT = 0.5  # longest wait for a chunk before the progress line is refreshed [s]

def run_caught(system: Oscillator, v0: float, kwargs: dict) -> Any:
    """One :func:`prefriction.simulate` run (thread-safe: each thread has its own buffers),
    returning the exception instead of raising it (``Exception`` only)."""
    try:
        return simulate(system, v0, **kwargs)
    except Exception as exc:  # noqa: BLE001 - a failed run is a result of the sweep
        return exc


def run_chunk(systems: list, v0s: list, kwargs: dict) -> list:
    """The runs of one chunk, in order: each a result or the exception it raised (module level,
    so that executors can pickle it)."""
    return [run_caught(system, v0, kwargs) for system, v0 in zip(systems, v0s)]


class Runs:
    """The systems and initial velocities of one chunk as one argument: dask walks a task's list
    arguments element by element looking for futures (7 µs per system in the parent); an object
    of its own it pickles whole."""

    __slots__ = ("systems", "v0s")

    def __init__(self, systems: list, v0s: list) -> None:
        self.systems, self.v0s = systems, v0s

    def __reduce__(self) -> tuple:
        return Runs, (self.systems, self.v0s)


def run_packed(runs: Runs, kwargs: dict) -> Packed:
    """:func:`run_chunk` of ``runs``, its outcomes packed for the trip back
    (:func:`prefriction.simulation.packed.pack`): the task of executors that pickle."""
    return pack(run_chunk(runs.systems, runs.v0s, kwargs))


def worker_count(executor: cf.Executor) -> int:
    """Number of parallel workers of ``executor`` if it tells (process and thread pools: their
    ``max_workers``; dask's ``ClientExecutor``: the threads of its cluster), else 8."""
    n = getattr(executor, "_max_workers", None)
    if isinstance(n, int) and n > 0:
        return n
    client = getattr(executor, "_client", None)
    if client is not None:
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:  # noqa: BLE001 - only sizes the chunks
            pass
    return 8


def chunk_size(n: int, workers: int) -> int:
    """Automatic chunk size: about :data:`_CHUNKS_PER_WORKER` chunks per worker, at most
    :data:`MAX_CHUNK` systems each, at least 1."""
    return max(1, min(MAX_CHUNK, math.ceil(n / (workers * _CHUNKS_PER_WORKER))))


def chunk_sizes(n: int, workers: int, size: Optional[int] = None) -> list[int]:
    """Sizes of the consecutive chunks of ``n`` runs: ``size`` each (the last one the rest), or
    automatic (``size=None``): :func:`chunk_size` each, and once fewer than
    :data:`_TAIL_PER_WORKER` such chunks per worker remain, ``remaining / (2 workers)`` each, down
    to a quarter of the full size, so that the workers finish within a small chunk of each other.
    """
    if size is not None:
        return [size] * (n // size) + ([n % size] if n % size else [])
    full = chunk_size(n, workers)
    least = math.ceil(full / _SMALLEST)
    sizes = []
    left = n
    while left > 0:
        k = min(full, max(least, math.ceil(left / (_TAIL_PER_WORKER * workers))), left)
        sizes.append(k)
        left -= k
    return sizes


def run_chunks(executor: cf.Executor, items: list, systems: list, v0s: list, kwargs: dict, results: list,
               size: Optional[int], update: Callable[[int], None]) -> None:
    """Run the systems ``items`` (indices into ``systems``) on ``executor`` in chunks of ``size``
    (None: :func:`chunk_sizes`) and write each result (or exception) into ``results[i]``.

    At most :data:`_IN_FLIGHT_PER_WORKER` chunks per worker are in flight; ``update(k)`` is
    called with the number of runs finished so far after each chunk, and at least every 0.5 s.
    On an exception in the parent (e.g. ``KeyboardInterrupt``) the futures in flight are
    cancelled and it propagates.
    """
    workers = worker_count(executor)
    sizes = chunk_sizes(len(items), workers, size)
    chunks = [items[end - k:end] for k, end in zip(sizes, itertools.accumulate(sizes))]
    window = max(2, _IN_FLIGHT_PER_WORKER * workers)
    threads = isinstance(executor, cf.ThreadPoolExecutor)  # nothing to pickle: plain lists, results as they are
    pending: dict = {}
    done = 0
    next_chunk = 0
    try:
        while next_chunk < len(chunks) or pending:
            while next_chunk < len(chunks) and len(pending) < window:
                idx = chunks[next_chunk]
                chunk = ([systems[i] for i in idx], [v0s[i] for i in idx])
                future = executor.submit(run_chunk, *chunk, kwargs) if threads else \
                    executor.submit(run_packed, Runs(*chunk), kwargs)
                pending[future] = idx
                next_chunk += 1
            finished = _wait_some(pending)
            for future in finished:
                idx = pending.pop(future)
                for i, outcome in zip(idx, _outcome(future, len(idx))):
                    results[i] = outcome
                done += len(idx)
            update(done)
    except BaseException:
        for future in pending:
            future.cancel()
        raise


def _wait_some(pending: dict) -> list:
    """Futures of ``pending`` that are done: those ``concurrent.futures.wait`` returns within
    :data:`_WAIT` (possibly none); futures of another kind (no ``cf.Future``), the oldest one,
    waited for."""
    futures = list(pending)
    if all(isinstance(f, cf.Future) for f in futures):
        finished, _ = cf.wait(futures, timeout=_WAIT, return_when=cf.FIRST_COMPLETED)
        return list(finished)
    return futures[:1]  # its result() blocks until it is done


def _outcome(future: Any, n: int) -> list:
    """The ``n`` outcomes of a finished chunk: its list of results (unpacked), or its task's
    exception ``n`` times (a cancelled chunk gives ``CancelledError``)."""
    try:
        out = future.result()
    except BaseException as exc:  # noqa: BLE001 - a failed chunk is a result of the sweep
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            raise
        return [exc] * n
    if isinstance(out, Packed) and len(out) == n:
        out = out.unpack()
    if not isinstance(out, list) or len(out) != n:
        exc = RuntimeError(f"a chunk of {n} runs returned {type(out).__name__} instead of {n} results")
        return [exc] * n
    return out
