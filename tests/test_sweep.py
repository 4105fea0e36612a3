"""sweep(): many simulate runs, serially, on a process pool and on dask, in input order."""

from __future__ import annotations

import concurrent.futures as cf
import concurrent.futures.process
import multiprocessing
import threading
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import prefriction as pf
from prefriction.simulation.sweep import SweepResult, _group_key, sweep

GAMMAS = (1.0, 1.5, 2.0, 3.0)
N_REV = 10
RTOL = 1e-8  # simulate's default; sweep leaves it alone
SYSTEMS = [pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=g), mass=1.0) for g in GAMMAS]
V0 = [0.5, 1.0, 2.0, 0.25]  # per system, so that a mix-up of the order shows


def _rel(a: np.ndarray, b: np.ndarray, floor: float = 0.0) -> float:
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), floor)))


def _same(a: pf.SimulationResult, b: pf.SimulationResult) -> bool:
    ta, tb = a.reversals, b.reversals
    return all(np.array_equal(getattr(ta, f), getattr(tb, f)) for f in ("t", "x", "F", "E_p", "E_d"))


@pytest.fixture(scope="module")
def serial() -> SweepResult:
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        return sweep(SYSTEMS, V0, reversals=N_REV, progress=False)


def test_serial_sweep_matches_exact_reversals_in_input_order(serial: SweepResult) -> None:
    assert isinstance(serial, SweepResult) and len(serial) == len(SYSTEMS)
    assert serial.failed == [] and serial.errors == {} and serial.wall_time > 0
    for system, v0, res in zip(SYSTEMS, V0, serial):
        ref = pf.exact_reversals(system, v0, n=N_REV)
        tab = res.reversals
        assert len(tab) == N_REV
        xs = system.friction.Fc / system.friction.sigma
        assert _rel(tab.t, ref.t) <= 20 * RTOL, system
        assert _rel(tab.F, ref.F) <= 20 * RTOL, system
        assert _rel(tab.x, ref.x, xs) <= 20 * RTOL, system
    assert repr(serial).startswith("SweepResult(4 runs, 0 failed, ") and repr(serial).endswith(" s)")
    assert "4 runs" in serial.summary()


def test_process_pool_gives_the_serial_results(serial: SweepResult) -> None:
    ctx = multiprocessing.get_context("spawn")  # fresh workers: they load the compiled code from disk
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as pool:
        res = sweep(SYSTEMS, V0, reversals=N_REV, executor=pool, progress=False)
    assert res.failed == []
    assert all(_same(a, b) for a, b in zip(res, serial))


def test_dask_executor_gives_the_serial_results(serial: SweepResult) -> None:
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        res = sweep(SYSTEMS, V0, reversals=N_REV, executor=client.get_executor(), progress=False)
    assert res.failed == []
    assert all(_same(a, b) for a, b in zip(res, serial))


def test_failing_run_keeps_its_exception_in_place(serial: SweepResult) -> None:
    # v0 = 0 with F0 = 0 and no input: the mass rests, simulate raises ValueError for run 2 only
    v0 = [V0[0], V0[1], 0.0, V0[3]]
    with pytest.warns(RuntimeWarning, match=r"1 of 4 runs failed \(indices 2\).*the mass rests"):
        res = sweep(SYSTEMS, v0, reversals=N_REV, progress=False)
    assert res.failed == [2] and set(res.errors) == {2}
    assert isinstance(res[2], ValueError) and res.errors[2] is res[2]
    assert "the mass rests" in str(res[2])
    assert all(_same(res[i], serial[i]) for i in (0, 1, 3))
    assert repr(res).startswith("SweepResult(4 runs, 1 failed, ")
    assert "[2] ValueError" in res.summary()


def test_serial_sweep_is_the_same_with_a_thread_pool(serial: SweepResult) -> None:
    # runs of one structure share compiled buffers: sweep makes threads take turns
    from concurrent.futures import ThreadPoolExecutor

    systems = SYSTEMS * 3
    with ThreadPoolExecutor(max_workers=4) as pool:
        res = sweep(systems, V0 * 3, reversals=N_REV, executor=pool, progress=False)
    assert res.failed == []
    assert all(_same(a, serial[i % 4]) for i, a in enumerate(res))


def test_progress_line(capsys: pytest.CaptureFixture) -> None:
    sweep(SYSTEMS[:2], 1.0, reversals=N_REV, progress=False)  # builds the integrators: CasADi's first-build
    capsys.readouterr()  # warning on stderr ("Event support is experimental") is not the progress line's
    sweep(SYSTEMS[:2], 1.0, reversals=N_REV, progress=True)
    err = capsys.readouterr().err
    # stderr is not a terminal here: whole lines, no carriage returns (prefriction._progress)
    assert err.startswith("sweep: ") and "2/2 runs" in err and err.endswith("\n") and "\r" not in err
    sweep(SYSTEMS[:2], 1.0, reversals=N_REV)  # automatic: a short sweep prints nothing
    sweep(SYSTEMS[:2], 1.0, reversals=N_REV, progress=False)
    assert capsys.readouterr().err == ""


def test_group_key_follows_the_structure() -> None:
    a, b = SYSTEMS[0], SYSTEMS[3]
    assert _group_key(a, {}) == _group_key(b, {})
    assert _group_key(a, {"dense": True}) != _group_key(a, {"dense": False})
    assert _group_key(a, {"dense": np.linspace(0, 1, 5)}) == _group_key(a, {"dense": True})


def test_bad_input_is_refused_before_any_run() -> None:
    with pytest.raises(TypeError, match="revrsals"):
        sweep(SYSTEMS, 1.0, revrsals=N_REV)
    with pytest.raises(TypeError, match="'system'"):
        sweep(SYSTEMS, 1.0, system=SYSTEMS[0], reversals=N_REV)
    with pytest.raises(ValueError, match="empty"):
        sweep([], 1.0, reversals=N_REV)
    with pytest.raises(ValueError, match="empty"):
        sweep(iter(()), 1.0, reversals=N_REV)
    with pytest.raises(TypeError, match=r"systems\[2\].*Dahl"):
        sweep([SYSTEMS[0], SYSTEMS[1], SYSTEMS[2].friction], 1.0, reversals=N_REV)
    with pytest.raises(TypeError, match="single Oscillator"):
        sweep(SYSTEMS[0], 1.0, reversals=N_REV)
    with pytest.raises(ValueError, match=r"v0 has 3 values but there are 4 systems"):
        sweep(SYSTEMS, [1.0, 1.0, 1.0], reversals=N_REV)
    with pytest.raises(ValueError, match=r"v0\[1\] must be finite"):
        sweep(SYSTEMS, [1.0, float("nan"), 1.0, 1.0], reversals=N_REV)
    with pytest.raises(ValueError, match="v0 must be finite"):
        sweep(SYSTEMS, float("inf"), reversals=N_REV)
    with pytest.raises(TypeError, match="v0"):
        sweep(SYSTEMS, "1.0", reversals=N_REV)
    with pytest.raises(TypeError, match="executor"):
        sweep(SYSTEMS, 1.0, reversals=N_REV, executor=object())
    with pytest.raises(TypeError, match="progress"):
        sweep(SYSTEMS, 1.0, reversals=N_REV, progress="yes")


def test_more_than_a_million_systems_is_refused() -> None:
    with pytest.raises(ValueError, match="1,000,000"):
        sweep(iter([SYSTEMS[0]] * 1_000_001), 1.0, reversals=N_REV)


class _CountingExecutor(cf.Executor):
    """A thread pool that counts its tasks and the most futures in flight at once."""

    def __init__(self, workers: int, fail_task: int = -1) -> None:
        self.pool = cf.ThreadPoolExecutor(workers)
        self._max_workers = workers
        self.submitted = 0
        self.in_flight = 0
        self.most_in_flight = 0
        self.fail_task = fail_task
        self.lock = threading.Lock()

    def submit(self, fn, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003
        with self.lock:
            k = self.submitted
            self.submitted += 1
            self.in_flight += 1
            self.most_in_flight = max(self.most_in_flight, self.in_flight)
        if k == self.fail_task:  # the task fails as a whole (a worker that died)
            future = cf.Future()
            future.set_exception(cf.process.BrokenProcessPool("worker died"))
        else:
            future = self.pool.submit(fn, *args, **kwargs)
        future.add_done_callback(self._done)
        return future

    def _done(self, _future: cf.Future) -> None:
        with self.lock:
            self.in_flight -= 1

    def shutdown(self, wait: bool = True, **kwargs) -> None:  # noqa: ANN003
        self.pool.shutdown(wait)


def test_executor_gets_chunks_and_a_bounded_number_in_flight(serial: SweepResult) -> None:
    # 4 x 25 = 100 systems of one structure (the first runs here), chunks of 3: 99 / 3 = 33 tasks,
    # at most 3 chunks per worker in flight; results in input order, equal to the serial ones
    systems, v0 = SYSTEMS * 25, V0 * 25
    ex = _CountingExecutor(2)
    with ex:
        res = sweep(systems, v0, reversals=N_REV, executor=ex, progress=False, chunksize=3)
    assert res.failed == [] and len(res) == 100
    assert ex.submitted == 33
    assert ex.most_in_flight <= 3 * 2
    assert all(_same(a, serial[i % 4]) for i, a in enumerate(res))


def test_a_chunk_that_fails_as_a_whole_leaves_its_exception_in_each_place(serial: SweepResult) -> None:
    systems, v0 = SYSTEMS * 3, V0 * 3  # run 0 here (one structure); 1..11 in chunks of 2: task 1 = runs 3, 4
    with _CountingExecutor(2, fail_task=1) as ex, pytest.warns(RuntimeWarning, match=r"2 of 12 runs failed \(indices 3, 4\)"):
        res = sweep(systems, v0, reversals=N_REV, executor=ex, progress=False, chunksize=2)
    assert res.failed == [3, 4]
    assert all(isinstance(res[i], cf.process.BrokenProcessPool) for i in (3, 4))
    assert all(_same(res[i], serial[i % 4]) for i in range(12) if i not in (3, 4))


def test_dask_in_process_cluster_with_a_failing_run(serial: SweepResult) -> None:
    distributed = pytest.importorskip("dask.distributed")
    v0 = V0 * 3
    v0[9] = 0.0  # F0 = 0, no input: the mass rests, run 9 raises ValueError inside its chunk
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client, \
            pytest.warns(RuntimeWarning, match=r"1 of 12 runs failed \(indices 9\)"):
        res = sweep(SYSTEMS * 3, v0, reversals=N_REV, executor=client, progress=False, chunksize=3)
    assert res.failed == [9] and "the mass rests" in str(res[9])
    assert all(_same(res[i], serial[i % 4]) for i in range(12) if i != 9)


def test_chunk_sizes() -> None:
    from prefriction.simulation.chunks import MAX_CHUNK, chunk_size

    assert chunk_size(1, 2) == 1 and chunk_size(8, 2) == 1 and chunk_size(9, 2) == 2  # n / (4 workers)
    assert chunk_size(10_000, 2) == 500 == MAX_CHUNK and chunk_size(1000, 2) == 125
    with pytest.raises(ValueError, match=r"chunksize must be an integer >= 1, got 0"):
        sweep(SYSTEMS, 1.0, reversals=N_REV, chunksize=0)
    with pytest.raises(TypeError, match=r"chunksize must be an integer"):
        sweep(SYSTEMS, 1.0, reversals=N_REV, chunksize=2.5)
