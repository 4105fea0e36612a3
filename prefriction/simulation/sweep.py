"""Parameter sweeps: many :func:`prefriction.simulate` runs, serially or on any executor.

:func:`sweep` runs one simulation per oscillator (any mix of friction models, parameters and
inputs) with shared keyword arguments, in the calling process or on a
:class:`concurrent.futures.Executor` (process pool, thread pool, dask.distributed). The results
come back in input order in a :class:`SweepResult`; a run that raises leaves its exception in its
place and the others go on.

Compiling is the expensive part of a first run (about 1 s), so before anything is submitted to an
executor the first system of each *structure group* (systems that share generated code) runs in
the calling process: the compiled code lands in the disk cache (``$PREFRICTION_CACHE``), where
worker processes on the same machine load it instead of compiling it again.
"""

from __future__ import annotations

import concurrent.futures as cf
import inspect
import itertools
import math
import pickle
import time
import warnings
from numbers import Real
from pathlib import Path
from typing import Any, Hashable, Iterable, Optional, Sequence, Sized, Union

import numpy as np

from prefriction._progress import ProgressLine
from prefriction._validation import check_bool, check_choice, check_count, check_finite, check_positive
from prefriction.models import Oscillator
from prefriction.simulation.chunks import run_caught, run_chunks
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.simulate import METHODS, simulate

__all__ = ["MAX_SYSTEMS", "SweepResult", "sweep"]

MAX_SYSTEMS = 1_000_000
"""Largest number of systems :func:`sweep` accepts in one call."""

_PROGRESS_AFTER = 1.0  # automatic progress: show only once the sweep has run this long [s]
_PROGRESS_EVERY = 0.5  # least interval between two progress lines [s]
_MAX_LISTED = 10  # failed indices listed in the warning and in summary()

class SweepResult(list):
    """Results of :func:`sweep`: a list with one entry per system, in input order.

    Each entry is the :class:`prefriction.SimulationResult` of that system, or the exception its
    run raised. ``repr`` is compact (no arrays); :meth:`summary` lists the failures.

    Attributes
    ----------
    failed : list of int
        Indices of the runs that raised, increasing.
    errors : dict
        Index -> exception of each failed run.
    wall_time : float
        Wall time of the whole sweep [s], compiling included.
    status : int
        As scipy's ``OdeResult``: ``0`` every run returned a result, ``-1`` some run raised.
    success : bool
        True if no run raised (``status >= 0``).
    message : str
        The outcome in words: all runs succeeded, or how many failed and the first error.
    """

    def __init__(self, results: Iterable[Any] = (), wall_time: float = 0.0) -> None:
        super().__init__(results)
        self.failed: list[int] = [i for i, r in enumerate(self) if isinstance(r, BaseException)]
        self.errors: dict[int, BaseException] = {i: self[i] for i in self.failed}
        self.wall_time = float(wall_time)

    def __repr__(self) -> str:
        return f"SweepResult({len(self)} runs, {len(self.failed)} failed, {self.wall_time:.2f} s)"

    __str__ = __repr__

    @property
    def status(self) -> int:
        """``0`` if every run returned a result, ``-1`` if some run raised (as ``OdeResult.status``)."""
        return -1 if self.failed else 0

    @property
    def success(self) -> bool:
        """True if no run raised (as ``OdeResult.success``)."""
        return self.status >= 0

    @property
    def message(self) -> str:
        """The outcome in words (as ``OdeResult.message``)."""
        return _failure_message(self) if self.failed else f"all {len(self)} runs succeeded"

    @property
    def n_reversals(self) -> np.ndarray:
        """Number of reversals of each run (0 for a failed run), an int array of length ``len(self)``."""
        return np.array([0 if isinstance(r, BaseException) else len(r.reversals) for r in self], dtype=int)

    def reversal_array(self, field: str) -> np.ndarray:
        """One column of every run's reversal table as one array, a row per run.

        Parameters
        ----------
        field : {"t", "x", "F", "E_p", "E_d"}
            Reversal times [s], positions [m], forces [N], potential energies or dissipations [J]
            (:class:`prefriction.ReversalTable`).

        Returns
        -------
        numpy.ndarray
            Shape ``(len(self), max(n_reversals))``; rows of shorter runs padded with NaN, a
            failed run's row all NaN.

        Raises
        ------
        ValueError
            If ``field`` is not one of the reversal table's columns.
        """
        if field not in _REVERSAL_FIELDS:
            raise ValueError(f"field must be one of {_REVERSAL_FIELDS}, got {field!r}")
        rows = [None if isinstance(r, BaseException) else getattr(r.reversals, field) for r in self]
        return _padded_rows(rows)

    def sample_array(self, field: str) -> np.ndarray:
        """One sampled field of every run (``dense=`` or ``t_eval``-style output) as one array.

        Parameters
        ----------
        field : {"t", "x", "v", "F", "E_k", "E_f", "u"}
            A sample field of :class:`prefriction.SimulationResult`.

        Returns
        -------
        numpy.ndarray
            Shape ``(len(self), max samples)``, padded with NaN (a failed run: all NaN).

        Raises
        ------
        ValueError
            If ``field`` is not a sample field, or no run has samples (sweep with ``dense=...``).
        """
        if field not in _SAMPLE_FIELDS:
            raise ValueError(f"field must be one of {_SAMPLE_FIELDS}, got {field!r}")
        rows = [None if isinstance(r, BaseException) else getattr(r, field) for r in self]
        if all(row is None for row in rows):
            raise ValueError(f"no run has the samples {field!r}: sweep with dense=True or an array of times")
        return _padded_rows(rows)

    def plot(self, path: "str | Path" = "sweep.png") -> "Path":
        """Each run's reversal amplitudes and every run's last one, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "sweep.png"
            Image file to write (the format from the suffix).

        Returns
        -------
        Path
            The file written.
        """
        from prefriction._result_plots import plot_sweep

        return plot_sweep(self, path)

    def summary(self) -> str:
        """One line of counts and wall time, then one line per failed run (at most 10).

        Returns
        -------
        str
            E.g. ``"20 runs, 1 failed, 1.23 s\\n  [7] ValueError: ..."``.
        """
        n_ok = len(self) - len(self.failed)
        lines = [f"{len(self)} runs, {n_ok} succeeded, {len(self.failed)} failed, {self.wall_time:.2f} s"]
        for i in self.failed[:_MAX_LISTED]:
            lines.append(f"  [{i}] {_describe(self.errors[i])}")
        if len(self.failed) > _MAX_LISTED:
            lines.append(f"  ... and {len(self.failed) - _MAX_LISTED} more")
        return "\n".join(lines)


_REVERSAL_FIELDS = ("t", "x", "F", "E_p", "E_d")
_SAMPLE_FIELDS = ("t", "x", "v", "F", "E_k", "E_f", "u")


def _padded_rows(rows: list) -> np.ndarray:
    """Rows of different lengths (``None``: a row of NaN) as one float array padded with NaN."""
    width = max((len(r) for r in rows if r is not None), default=0)
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        if row is not None:
            out[i, :len(row)] = row
    return out


def sweep(
    systems: Union[Sequence[Oscillator], Iterable[Oscillator]],
    v0: Union[float, Sequence[float]],
    *,
    executor: Optional[cf.Executor] = None,
    progress: Optional[bool] = None,
    chunksize: Optional[int] = None,
    **simulate_kwargs: Any,
) -> SweepResult:
    """Simulate many oscillators with the same settings, serially or on an executor.

    Parameters
    ----------
    systems : sequence or iterable of Oscillator
        The systems, one run each: any mix of friction models, parameters and input forces.
        At least 1 and at most :data:`MAX_SYSTEMS` (1 000 000).
    v0 : float or sequence of float
        Initial velocity [m/s]: one number for every run, or one finite number per system.
    executor : concurrent.futures.Executor, optional
        Where to run: ``None`` (default) runs serially in the calling process. Any
        :class:`concurrent.futures.Executor` works: ``ProcessPoolExecutor``,
        ``ThreadPoolExecutor`` (correct but no faster than serial: runs in one process take
        turns, since they share compiled integrators), or dask.distributed's
        ``client.get_executor()`` (a ``Client`` itself is accepted and converted). The systems
        go to the executor in chunks (one task per chunk, a few chunks per worker in flight;
        see ``chunksize``), so the bookkeeping is linear in the number of systems; on an
        executor that pickles, a chunk's results come back packed in a few arrays and are
        rebuilt here (:mod:`prefriction.simulation.packed`). The first
        system of each structure group runs in the calling process first, so that the compiled
        code is in the disk cache before the workers start (workers on other machines need the
        cache directory ``$PREFRICTION_CACHE`` on a shared file system, or compile once each).
        With a ``ProcessPoolExecutor`` the systems are pickled: a callable input ``u`` must be a
        module-level function (dask pickles lambdas too); one that cannot be pickled is refused
        before any run. Runs in threads (``ThreadPoolExecutor``) do not interfere: each thread
        calls the shared compiled code through its own buffers.
    progress : bool, optional
        ``None`` (default): print a progress line such as ``sweep: 12/40 runs, 3.1 s`` to
        stderr, updated in place every 0.5 s, once the sweep has run for 1 s (short sweeps print
        nothing). ``True``: always print it; ``False``: never.
    chunksize : int, optional
        Systems per task on an executor (ignored without one). ``None`` (default): chunks of
        about ``n / (4 workers)`` systems, at most 500, smaller over the last two per worker so
        that the workers finish together (:func:`prefriction.simulation.chunks.chunk_sizes`).
        A larger chunk costs less per system to ship; a smaller one balances the load and
        updates the progress more often.
    **simulate_kwargs
        Keyword arguments of :func:`prefriction.simulate` for every run, passed unchanged
        (``reversals``, ``t_end``, ``rtol``, ``x0``, ``F0``, ``dense``, ``feedback``, ...).

    Returns
    -------
    SweepResult
        A list of :class:`prefriction.SimulationResult`, in the order of ``systems``; the entry of
        a run that raised is its exception (indices in ``.failed``, exceptions in ``.errors``).
        ``.wall_time`` is the wall time of the sweep [s].

    Raises
    ------
    TypeError
        Before any run: for a keyword that :func:`prefriction.simulate` does not take, an entry
        of ``systems`` that is not an :class:`prefriction.Oscillator` (the message names
        ``systems[i]``), a non-real ``v0``, an ``executor`` without ``submit``, or a keyword of
        the wrong type (``reversals``, ``t_end``, ``rtol``, ``atol``, ``x0``, ``F0``,
        ``method``, ``jit``, ``feedback``).
    ValueError
        Before any run: for no systems, more than :data:`MAX_SYSTEMS`, a ``v0`` sequence whose
        length differs from the number of systems or that holds a non-finite value, a
        ``chunksize`` below 1, or one of
        those keywords out of its range (``reversals >= 1``; ``t_end``, ``rtol``, ``atol`` > 0;
        ``x0``, ``F0`` finite; ``method`` in :data:`prefriction.simulation.simulate.METHODS`).

    Warns
    -----
    RuntimeWarning
        Once, if some runs failed: how many, their indices and the first error message. The
        runs themselves are not retried; inspect ``result.errors``.

    Notes
    -----
    Runs are deterministic: the same system and settings give bitwise the same result serially
    or on any executor. Keywords that are invalid whatever the system (a negative ``reversals``,
    ``method="euler"``, ...) raise before any run; what depends on the system (``|F0| > Fc``, a
    forced system without ``t_end``, ``rtol`` beyond the simulator's range, ...) is checked by
    :func:`prefriction.simulate` in each run: those runs fail and their exceptions sit in their
    places.

    A structure group is what decides the generated code: the friction model's class and
    ``structure_key()``, the input's ``key`` (or type), whether samples are requested
    (``dense``) and the feedback's type. Grouping affects only the order of the runs and how
    often code is compiled, never the results.

    Examples
    --------
    A gamma sweep of the Dahl oscillator, serially:

    >>> import prefriction as pf
    >>> from prefriction.simulation.sweep import sweep
    >>> systems = [pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0, gamma=g), mass=1.0)
    ...            for g in (1.0, 1.5, 2.0, 3.0)]
    >>> res = sweep(systems, 1.0, reversals=50)
    >>> res  # doctest: +ELLIPSIS
    SweepResult(4 runs, 0 failed, ... s)
    >>> [r.reversals.F[-1] for r in res]  # doctest: +SKIP

    The same on a dask cluster (two local worker processes here):

    >>> from dask.distributed import Client, LocalCluster  # doctest: +SKIP
    >>> client = Client(LocalCluster(n_workers=2))  # doctest: +SKIP
    >>> res = sweep(systems, 1.0, reversals=50, executor=client.get_executor())  # doctest: +SKIP

    or on a process pool (in a script, under ``if __name__ == "__main__":``):

    >>> from concurrent.futures import ProcessPoolExecutor  # doctest: +SKIP
    >>> with ProcessPoolExecutor(max_workers=4) as pool:  # doctest: +SKIP
    ...     res = sweep(systems, [0.5, 1.0, 2.0, 4.0], reversals=50, executor=pool)
    """
    start = time.perf_counter()
    kwargs = _check_kwargs(simulate_kwargs)
    executor = _check_executor(executor)
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise TypeError(f"progress must be None, True or False, got {_short_repr(progress)} of type "
                        f"{type(progress).__name__}")
    if chunksize is not None:
        chunksize = check_count("chunksize", chunksize, 1)
    systems = _check_systems(systems)
    v0s = _check_v0(v0, len(systems))

    n = len(systems)
    results: list[Any] = [None] * n
    bar = _Progress(n, progress, start)
    if executor is None:
        for i in range(n):
            results[i] = run_caught(systems[i], v0s[i], kwargs)
            bar.update(i + 1)
    else:
        if isinstance(executor, cf.ProcessPoolExecutor):
            _check_picklable(systems, kwargs)
        _run_on(executor, systems, v0s, kwargs, results, bar, chunksize)
    bar.close(n)

    out = SweepResult(results, time.perf_counter() - start)
    if out.failed:
        warnings.warn(_failure_message(out), RuntimeWarning, stacklevel=2)
    return out


def _check_picklable(systems: list, kwargs: dict) -> None:
    """``TypeError`` before any run if a system or keyword cannot be sent to a process pool."""
    seen: set = set()
    for i, system in enumerate(systems):
        for part, what in ((system.u, "input u"), (system.friction, "friction model")):
            if id(part) in seen:
                continue
            seen.add(id(part))
            try:
                pickle.dumps(part)
            except Exception as exc:  # noqa: BLE001 - any pickling failure, reported with its reason
                raise TypeError(
                    f"systems[{i}].{'u' if part is system.u else 'friction'} ({what}) cannot be sent to a "
                    f"ProcessPoolExecutor: {exc}. Use a prefriction.signals input (Sine, Step, Ramp, Chirp, Samples) "
                    f"or a module-level function instead of a lambda or local function, or a ThreadPoolExecutor"
                ) from None
    try:
        pickle.dumps(kwargs)
    except Exception as exc:  # noqa: BLE001
        raise TypeError(f"the keyword arguments cannot be sent to a ProcessPoolExecutor: {exc}") from None


def _group_key(system: Oscillator, kwargs: dict) -> Hashable:
    """Structure group of a run: runs with equal keys share compiled code.

    Built from the friction model's class name and ``structure_key()`` (None if it has none),
    the input's ``key`` (else its type name), whether dense samples are requested and the type
    of the feedback; parts that are not hashable enter through their ``repr``.
    """
    friction = system.friction
    structure_key = getattr(friction, "structure_key", None)
    try:
        structure = structure_key() if callable(structure_key) else None
    except Exception:  # noqa: BLE001 - the key only orders the runs
        structure = None
    u_key = getattr(system.u, "key", type(system.u).__name__)
    dense = kwargs.get("dense", False)
    parts = (
        type(friction).__name__,
        structure,
        u_key,
        not (dense is None or dense is False),
        type(kwargs.get("feedback")),
    )
    return tuple(_hashable(p) for p in parts)


def _hashable(value: Any) -> Hashable:
    """``value`` if it is hashable, else its ``repr``."""
    try:
        hash(value)
    except TypeError:
        return repr(value)
    return value


def _run_on(executor: cf.Executor, systems: list, v0s: list, kwargs: dict, results: list, bar: "_Progress",
            chunksize: Optional[int]) -> None:
    """Fill ``results`` from ``executor``: the first run of each group here, the others in chunks."""
    first: dict = {}
    for i, system in enumerate(systems):
        first.setdefault(_group_key(system, kwargs), i)
    warm = sorted(first.values())
    for k, i in enumerate(warm):  # compile once, in this process, into the disk cache the workers load from
        results[i] = run_caught(systems[i], v0s[i], kwargs)
        bar.update(k + 1)
    warm_set = set(warm)
    rest = [i for i in range(len(systems)) if i not in warm_set]
    if rest:
        run_chunks(executor, rest, systems, v0s, kwargs, results, chunksize, lambda k: bar.update(len(warm) + k))


class _Progress:
    """A progress line on stderr (``mode``: None automatic, True, False)."""

    def __init__(self, n: int, mode: Optional[bool], start: float) -> None:
        self.n, self.mode, self.start = n, mode, start
        self.last: Optional[float] = None
        self.line = ProgressLine()  # in place on a terminal, one line per update in a log

    def update(self, done: int) -> None:
        if self.mode is False:
            return
        now = time.perf_counter()
        if self.mode is None and now - self.start < _PROGRESS_AFTER:
            return
        if self.last is not None and now - self.last < _PROGRESS_EVERY:
            return
        self.last = now
        self._write(done, now)

    def close(self, done: int) -> None:
        if self.mode is True or (self.mode is None and self.last is not None):
            self._write(done, time.perf_counter())
            self.line.close()

    def _write(self, done: int, now: float) -> None:
        self.line.show(f"sweep: {done}/{self.n} runs, {now - self.start:.1f} s")


# --- validation ------------------------------------------------------------------------------


def _check_kwargs(kwargs: dict) -> dict:
    """The keyword arguments for :func:`prefriction.simulate`; ``TypeError`` naming unknown ones."""
    allowed = [
        name for name, par in inspect.signature(simulate).parameters.items()
        if par.kind is inspect.Parameter.KEYWORD_ONLY
    ]
    unknown = [name for name in kwargs if name not in allowed]
    if unknown:
        names = ", ".join(repr(u) for u in unknown)
        raise TypeError(
            f"sweep() got unexpected keyword argument(s) {names}: not keyword arguments of "
            f"prefriction.simulate, which takes {', '.join(allowed)} (systems and v0 are given "
            f"to sweep directly; sweep's own are executor and progress)"
        )
    _check_shared(kwargs)
    return dict(kwargs)


def _check_shared(kwargs: dict) -> None:
    """Check the keywords whose validity does not depend on the system (types and basic ranges, as
    :func:`prefriction.simulate` documents them), so that a bad one fails once, before any run."""
    optional = {"reversals": lambda n, v: check_count(n, v, 1), "t_end": check_positive, "atol": check_positive}
    for name, check in optional.items():
        if kwargs.get(name) is not None:
            check(name, kwargs[name])
    for name in ("x0", "F0"):
        if name in kwargs:
            check_finite(name, kwargs[name])
    if "rtol" in kwargs:
        check_positive("rtol", kwargs["rtol"])
    if "method" in kwargs:
        check_choice("method", kwargs["method"], METHODS)
    if "jit" in kwargs:
        check_bool("jit", kwargs["jit"])
    if kwargs.get("feedback") is not None and not isinstance(kwargs["feedback"], LinearFeedback):
        raise TypeError(f"feedback must be a prefriction LinearFeedback or None, got {_short_repr(kwargs['feedback'])}")


def _check_executor(executor: Any) -> Optional[cf.Executor]:
    """``executor`` as a ``concurrent.futures.Executor`` (a dask ``Client`` is converted) or None."""
    if executor is None or isinstance(executor, cf.Executor):
        return executor
    get_executor = getattr(executor, "get_executor", None)
    if callable(get_executor):  # dask.distributed.Client: chunks are never the same task twice
        return get_executor(pure=False)
    if callable(getattr(executor, "submit", None)):
        return executor
    raise TypeError(
        f"executor must be None or a concurrent.futures.Executor (e.g. ProcessPoolExecutor, or "
        f"client.get_executor() of dask.distributed), got {executor!r} of type {type(executor).__name__}"
    )


def _check_systems(systems: Any) -> list:
    """``systems`` as a list of :class:`Oscillator`, 1 to :data:`MAX_SYSTEMS` of them."""
    if isinstance(systems, Oscillator):
        raise TypeError("systems must be a sequence of prefriction.Oscillator, got a single Oscillator; wrap it in a list")
    if isinstance(systems, (str, bytes)) or not isinstance(systems, Iterable):
        raise TypeError(
            f"systems must be a sequence of prefriction.Oscillator, got {systems!r} of type {type(systems).__name__}"
        )
    items = list(itertools.islice(systems, MAX_SYSTEMS + 1))
    if not items:
        raise ValueError("systems is empty: give at least one prefriction.Oscillator")
    if len(items) > MAX_SYSTEMS:
        raise ValueError(
            f"systems holds more than {MAX_SYSTEMS:,} systems, the limit of one sweep; split it into several sweeps"
        )
    for i, system in enumerate(items):
        if not isinstance(system, Oscillator):
            raise TypeError(
                f"systems[{i}] must be a prefriction.Oscillator, got {_short_repr(system)} of type "
                f"{type(system).__name__}"
            )
    return items


def _check_v0(v0: Any, n: int) -> list[float]:
    """One finite initial velocity per system, from a number or a sequence of ``n`` numbers."""
    if isinstance(v0, np.ndarray) and v0.ndim == 0:
        v0 = v0[()]
    if _is_real(v0):
        v = float(v0)
        if not math.isfinite(v):
            raise ValueError(f"v0 must be finite, got {v!r}")
        return [v] * n
    if isinstance(v0, (str, bytes, bool)) or not isinstance(v0, Iterable):
        raise TypeError(
            f"v0 must be a real number or a sequence of one per system, got {_short_repr(v0)} of type "
            f"{type(v0).__name__}"
        )
    values = list(v0) if isinstance(v0, Sized) else list(itertools.islice(v0, n + 1))
    if len(values) != n:
        got = f"{len(values)}" if isinstance(v0, Sized) or len(values) <= n else f"more than {n}"
        raise ValueError(
            f"v0 has {got} values but there are {n} systems: give one v0 per system, or one number for all"
        )
    out = []
    for i, value in enumerate(values):
        if not _is_real(value):
            raise TypeError(f"v0[{i}] must be a real number, got {_short_repr(value)} of type {type(value).__name__}")
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"v0[{i}] must be finite, got {v!r}")
        out.append(v)
    return out


def _is_real(value: Any) -> bool:
    """True for a real number (not a bool)."""
    return not isinstance(value, bool) and isinstance(value, (Real, np.floating, np.integer))


def _short_repr(value: Any, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe(exc: BaseException) -> str:
    """``"Type: message"`` of an exception, the message cut to 300 characters."""
    msg = str(exc)
    if len(msg) > 300:
        msg = msg[:297] + "..."
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


def _failure_message(res: SweepResult) -> str:
    k, n = len(res.failed), len(res)
    idx = ", ".join(str(i) for i in res.failed[:_MAX_LISTED])
    if k > _MAX_LISTED:
        idx += ", ..."
    first = res.failed[0]
    return (
        f"{k} of {n} runs failed (indices {idx}); their exceptions are in place "
        f"(result.errors); first error, run {first}: {_describe(res.errors[first])}"
    )
