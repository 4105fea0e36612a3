"""The scaling section of ``prefriction bench --sweep``: large sweeps serially, on a process
pool and on dask (``docs/bench.md#sweep-scaling``).

The same unforced Dahl systems (gamma uniform in [1, 3], ``sigma`` log-uniform in
[1e3, 1e5] N/m, ``Fc = 1`` N, ``m = 1`` kg, ``v0 = 1`` m/s, 50 reversals, ``rtol = 1e-8``,
random generator seed 0) are swept serially, on ``ProcessPoolExecutor(2)`` and on a dask
``LocalCluster`` of 2 worker processes with 1 thread each, at each size (1,000 and 10,000;
``--quick``: 200 and 1,000). The pool and the cluster are started and warmed (each worker has
imported prefriction and run the structure) before the clock starts, as a user's long-lived pool
would be; each time is the end-to-end :func:`prefriction.sweep` call, the least of
:data:`ROUNDS` interleaved rounds (serial, pool, dask; ``--quick``: one). For dask a line per size
splits the two cores' time during the sweep (2 x wall) into the runs (the serial sweep's CPU
time), the workers' other CPU time (unpickling, packing, dask's threads), the parent's CPU time
(the scheduler of the ``LocalCluster``, the client, the sweep's own bookkeeping) and the rest
(cores idle, or taken by other processes).
"""

from __future__ import annotations

import logging
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import ExitStack
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from prefriction.cli.bench.timing import progress
from prefriction.models import Dahl, Oscillator

SIZES, QUICK_SIZES = (1_000, 10_000), (200, 1_000)
ROUNDS = 2  # interleaved rounds of serial, pool and dask per size (least of each): load bursts of other processes
WORKERS = 2
N_REV = 50
POOL_TARGET, DASK_TARGET = 1.6, 1.4  # least speed-up over serial: pool at every size, dask at the largest
SINGLE_TARGET, C_TARGET = 1.2, 2.5  # serial sweep per system against one simulate, and against plain C
SEED = 0
N_SAMPLE = 50  # systems timed one by one (simulate and plain C), every (n / 50)-th of the set


@dataclass
class ScaleRow:
    """One size of the scaling section: end-to-end times [s] and failures (NaN: not measured)."""

    n: int
    load: float
    serial_s: float
    pool_s: float
    dask_s: float
    failed: int
    sample_sweep_s: float = math.nan
    single_s: float = math.nan
    c_s: float = math.nan
    serial_cpu_s: float = math.nan
    dask_parent_cpu_s: float = math.nan
    dask_worker_cpu_s: float = math.nan

    @property
    def pool_speedup(self) -> float:
        """Serial time over the pool's."""
        return self.serial_s / self.pool_s

    @property
    def per_system_s(self) -> float:
        """Serial sweep time per system [s]."""
        return self.serial_s / self.n

    @property
    def dask_speedup(self) -> float:
        """Serial time over dask's (NaN without dask)."""
        return self.serial_s / self.dask_s

    def dask_breakdown(self) -> str:
        """The cores' time during the dask sweep, ``WORKERS x wall``, in shares: the runs (serial
        CPU), the workers' other CPU, the parent's CPU and the rest (idle or other processes)."""
        cores = WORKERS * self.dask_s
        runs, parent = self.serial_cpu_s, self.dask_parent_cpu_s
        extra = self.dask_worker_cpu_s - runs
        rest = cores - runs - extra - parent
        shares = [f"runs {100 * runs / cores:.0f}%"] + [
            f"{name} {100 * part / cores:.0f}% ({1e3 * part / self.n:.3f} ms/system)"
            for name, part in (("workers' other CPU", extra), ("parent CPU (scheduler, client, sweep)", parent),
                               ("idle or other processes", rest))]
        return f"dask at {self.n:,}, {WORKERS} x {self.dask_s:.2f} s of cores: " + ", ".join(shares)


def scale_systems(n: int) -> list[Oscillator]:
    """The ``n`` systems of the scaling section (seeded, the same in every run).

    Parameters
    ----------
    n : int
        Number of systems.

    Returns
    -------
    list of Oscillator
        Unforced Dahl oscillators, gamma in [1, 3], ``sigma`` in [1e3, 1e5] N/m, ``Fc = 1`` N,
        ``m = 1`` kg.
    """
    rng = np.random.default_rng(SEED)
    gammas = rng.uniform(1.0, 3.0, n)
    sigmas = 10.0 ** rng.uniform(3.0, 5.0, n)
    return [Oscillator(Dahl(sigma=float(s), Fc=1.0, gamma=float(g)), mass=1.0) for g, s in zip(gammas, sigmas)]


def _timed(systems: list, executor: Any) -> tuple[float, int]:
    """End-to-end time of one sweep [s] and its number of failed runs."""
    from prefriction.simulation.sweep import sweep

    start = time.perf_counter()
    res = sweep(systems, 1.0, reversals=N_REV, executor=executor, progress=False)
    return time.perf_counter() - start, len(res.failed)


def _timed_dask(systems: list, client: Any) -> tuple[float, int, float, float]:
    """:func:`_timed` on dask, with the CPU time [s] of this process (scheduler, client, sweep) and
    of the worker processes during the sweep."""
    before = sum(client.run(time.process_time).values())
    cpu = time.process_time()
    seconds, failed = _timed(systems, client)
    cpu = time.process_time() - cpu
    return seconds, failed, cpu, sum(client.run(time.process_time).values()) - before


def _dask_client(stack: ExitStack) -> Optional[Any]:
    """A dask ``Client`` on a ``LocalCluster(2 workers x 1 thread)``, or None without dask."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        return None
    # silence_logs: a worker whose heartbeat meets the closing scheduler logs a traceback at ERROR
    cluster = stack.enter_context(LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True,
                                               dashboard_address=None, silence_logs=logging.CRITICAL))
    return stack.enter_context(Client(cluster))


def single_runs(systems: list, rounds: int = 5) -> tuple[float, float, float]:
    """Per-system times [s] on every ``len(systems) // N_SAMPLE``-th system, in interleaved rounds
    (the least of each over ``rounds``): a serial :func:`prefriction.sweep` of the sample, one
    :func:`prefriction.simulate` per system (end to end, warm) and one plain-C reference run per
    system (NaN without a C compiler). Returns ``(sweep, simulate, C)`` per system."""
    from prefriction.cli.bench.plain_c import c_available, c_reversals
    from prefriction.simulation.simulate import simulate
    from prefriction.simulation.sweep import sweep

    sample = systems[:: max(1, len(systems) // N_SAMPLE)][:N_SAMPLE]
    has_c = c_available()
    best = [math.inf, math.inf, math.inf]
    for _ in range(rounds):
        start = time.perf_counter()
        sweep(sample, 1.0, reversals=N_REV, progress=False)
        best[0] = min(best[0], time.perf_counter() - start)
        start = time.perf_counter()
        for system in sample:
            simulate(system, 1.0, reversals=N_REV)
        best[1] = min(best[1], time.perf_counter() - start)
        if has_c:
            start = time.perf_counter()
            for system in sample:
                c_reversals(system, 1.0, N_REV)
            best[2] = min(best[2], time.perf_counter() - start)
    return best[0] / len(sample), best[1] / len(sample), best[2] / len(sample) if has_c else math.nan


def _keep(best: dict, key: str, timing: tuple) -> None:
    """Keep in ``best[key]`` the faster of it and ``timing`` (wall time first)."""
    if key not in best or timing[0] < best[key][0]:
        best[key] = timing


def measure_scaling(sizes: tuple[int, ...], rounds: int = ROUNDS) -> list[ScaleRow]:
    """Sweep ``scale_systems(n)`` serially, on the pool and on dask for each ``n`` of ``sizes``,
    in ``rounds`` interleaved rounds (serial, pool, dask); each time is the least of its rounds.

    Parameters
    ----------
    sizes : tuple of int
        Numbers of systems.
    rounds : int, optional
        Rounds per size (default :data:`ROUNDS`).

    Returns
    -------
    list of ScaleRow
        One row per size (``dask_s`` NaN if dask.distributed is not installed); ``load`` is the
        highest 1-minute load average at the start of a round, ``failed`` counts every round.
    """
    rows = []
    with ExitStack() as stack:
        pool = stack.enter_context(ProcessPoolExecutor(WORKERS))
        client = _dask_client(stack)
        warm = scale_systems(8 * WORKERS)
        _timed(warm[:1], None)
        _timed(warm, pool)  # both workers have run the structure
        if client is not None:
            _timed(warm, client)
        for n in sizes:
            systems = scale_systems(n)
            best: dict[str, tuple] = {}  # the fastest round of each: (wall, CPU times ...)
            loads, failed = [], 0
            for k in range(rounds):
                loads.append(os.getloadavg()[0])
                tag = f"{n:,} systems [{k + 1}/{rounds}]"
                progress(f"scaling: {tag} serially")
                cpu = time.process_time()
                seconds, f = _timed(systems, None)
                failed += f
                _keep(best, "serial", (seconds, time.process_time() - cpu))
                progress(f"scaling: {tag} on ProcessPoolExecutor({WORKERS}) (serial {seconds:.1f} s)")
                seconds, f = _timed(systems, pool)
                failed += f
                _keep(best, "pool", (seconds,))
                if client is not None:
                    progress(f"scaling: {tag} on dask LocalCluster({WORKERS} x 1) (pool {seconds:.1f} s)")
                    seconds, f, parent_cpu, worker_cpu = _timed_dask(systems, client)
                    failed += f
                    _keep(best, "dask", (seconds, parent_cpu, worker_cpu))
            progress(f"scaling: {N_SAMPLE} of the {n:,} systems: sweep, one by one and plain C, interleaved")
            (serial, serial_cpu), (pool_s,) = best["serial"], best["pool"]
            dask_s, parent_cpu, worker_cpu = best.get("dask", (math.nan,) * 3)
            rows.append(ScaleRow(n, max(loads), serial, pool_s, dask_s, failed, *single_runs(systems),
                                 serial_cpu, parent_cpu, worker_cpu))
    return rows


def format_scaling(rows: list[ScaleRow]) -> str:
    """The table of the scaling section."""
    lines = [f"Scaling: unforced Dahl, gamma in [1, 3], sigma in [1e3, 1e5] N/m, {N_REV} reversals, rtol 1e-8; "
             f"end-to-end sweep time, least of the interleaved rounds, pool and cluster started and warm; load: "
             f"the machine's highest 1-minute load average at the start of a round (another process on a core "
             f"halves a {WORKERS}-worker speed-up)",
             f"{'systems':>8} {'load':>5} {'serial s':>9} {'ms/system':>9} {'pool(2) s':>10} {'speed-up':>8} "
             f"{'dask(2x1) s':>11} {'speed-up':>8} {'failed':>6}"]
    for r in rows:
        lines.append(f"{r.n:>8,} {r.load:>5.1f} {r.serial_s:>9.2f} {r.serial_s / r.n * 1e3:>9.3f} {r.pool_s:>10.2f} "
                     f"{r.pool_speedup:>7.2f}x {r.dask_s:>11.2f} {r.dask_speedup:>7.2f}x {r.failed:>6}")
    lines.extend(r.dask_breakdown() for r in rows if not math.isnan(r.dask_parent_cpu_s))
    lines.append(f"Per system, on {N_SAMPLE} of the systems in 5 interleaved rounds (least of each): a serial sweep of "
                 f"them, simulate one by one, the plain-C reference one by one (docs/bench.md#plain-c)")
    lines.append(f"{'systems':>8} {'sweep ms':>9} {'simulate ms':>11} {'ratio':>6} {'plain C ms':>10} {'ratio':>6}")
    for r in rows:
        lines.append(f"{r.n:>8,} {r.sample_sweep_s * 1e3:>9.3f} {r.single_s * 1e3:>11.3f} "
                     f"{r.sample_sweep_s / r.single_s:>6.2f} {r.c_s * 1e3:>10.3f} {r.sample_sweep_s / r.c_s:>6.2f}")
    return "\n".join(lines)


def scaling_targets(rows: list[ScaleRow], quick: bool) -> list[str]:
    """The target lines T3 (pool and dask speed-ups) and T4 (serial sweep per system against one
    simulate and the plain-C reference), in the order T3, T4; not checked with ``--quick``."""
    pool_ok = all(r.pool_speedup >= POOL_TARGET for r in rows)
    largest = rows[-1]
    dask_ok = math.isnan(largest.dask_s) or largest.dask_speedup >= DASK_TARGET
    ok = (pool_ok and dask_ok and all(r.failed == 0 for r in rows)) or quick
    pools = ", ".join(f"{r.n:,}: {r.pool_speedup:.2f}x" for r in rows)
    dask = "dask.distributed not installed" if math.isnan(largest.dask_s) else \
        f"dask at {largest.n:,}: {largest.dask_speedup:.2f}x"
    note = "speed not checked in --quick; " if quick else ""
    big = rows[-1]
    per = big.sample_sweep_s
    ok4 = per <= SINGLE_TARGET * big.single_s and (math.isnan(big.c_s) or per <= C_TARGET * big.c_s)
    line4 = (f"T4 (serial sweep, per system <= {SINGLE_TARGET:g}x one simulate and <= {C_TARGET:g}x the "
             f"plain-C reference): {'PASS' if ok4 or quick else 'FAIL'}  ({note}{per * 1e3:.3f} ms per "
             f"system; simulate {big.single_s * 1e3:.3f} ms: {per / big.single_s:.2f}x; plain C "
             f"{big.c_s * 1e3:.3f} ms: {per / big.c_s:.2f}x)")
    return [f"T3 (ProcessPoolExecutor({WORKERS}) >= {POOL_TARGET:g}x faster than serial at every size, dask "
            f"LocalCluster({WORKERS} x 1) >= {DASK_TARGET:g}x at the largest, no failed run): "
            f"{'PASS' if ok else 'FAIL'}  ({note}pool {pools}; {dask})", line4]
