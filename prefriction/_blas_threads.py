"""One BLAS thread around the toolbox's dense linear algebra (shared machines).

OpenBLAS starts as many threads as the machine has cores for every large enough product or
factorisation. The fits call it on matrices of a few hundred columns, many times: on a shared
machine each process's threads then compete for the same cores (measured on 2 cores with other
fits running: a test process took 861 s with the default threads and 89 s with one). The fits
therefore run their dense solves with one BLAS thread (:func:`one_blas_thread`) and restore the
previous count afterwards.

The OpenBLAS libraries numpy and scipy have already loaded are found in ``/proc/self/maps``
(nothing new is loaded: ``RTLD_NOLOAD``) and driven through their own
``*openblas_set_num_threads*`` / ``*openblas_get_num_threads*`` entry points (the names of
OpenBLAS and of the ``scipy-openblas`` wheels, 32- and 64-bit integer builds). The count is a
setting of the whole process, so nested and concurrent callers share it: a lock and a depth
counter set it on the first entry and restore it on the last exit. Elsewhere (no
``/proc/self/maps``, another BLAS) the context does nothing; ``OPENBLAS_NUM_THREADS=1`` or
threadpoolctl then do the same from outside.
"""

from __future__ import annotations

import ctypes
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, Callable, TypeVar

__all__ = ["blas_thread_counts", "one_blas_thread", "with_one_blas_thread"]

_PAIRS = (("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
          ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
          ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
          ("openblas_set_num_threads", "openblas_get_num_threads"))
"""Setter and getter names, in the order tried in each library."""
_LOCK = threading.Lock()
_DEPTH = 0
_SAVED: list[tuple[Any, int]] = []
_KNOWN: dict[str, tuple[Any, Any] | None] = {}

F = TypeVar("F", bound=Callable[..., Any])


def _loaded_openblas() -> list[str]:
    """Paths of the OpenBLAS libraries mapped into this process (Linux), else none."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as fh:
            paths = {line.split(None, 5)[5].strip() for line in fh if "openblas" in line.lower()
                     and len(line.split(None, 5)) == 6}
    except OSError:
        return []
    return sorted(p for p in paths if p.startswith("/") and ".so" in os.path.basename(p))


def _controls() -> list[tuple[Any, Any]]:
    """``(set, get)`` ctypes functions of every loaded OpenBLAS (cached per library path)."""
    out = []
    for path in _loaded_openblas():
        if path not in _KNOWN:
            _KNOWN[path] = None
            try:
                lib = ctypes.CDLL(path, mode=getattr(os, "RTLD_NOLOAD", 0) | ctypes.RTLD_LOCAL)
            except OSError:
                continue
            for set_name, get_name in _PAIRS:
                setter, getter = getattr(lib, set_name, None), getattr(lib, get_name, None)
                if setter is not None and getter is not None:
                    setter.argtypes, setter.restype = [ctypes.c_int], None
                    getter.argtypes, getter.restype = [], ctypes.c_int
                    _KNOWN[path] = (setter, getter)
                    break
        if _KNOWN[path] is not None:
            out.append(_KNOWN[path])
    return out


def blas_thread_counts() -> list[int]:
    """The thread count of every loaded OpenBLAS library (empty where none is found)."""
    with _LOCK:
        return [int(get()) for _set, get in _controls()]


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with one OpenBLAS thread in every loaded OpenBLAS library, then restore the
    previous counts (module docstring). Safe to nest and to enter from several threads at once."""
    global _DEPTH
    with _LOCK:
        if _DEPTH == 0:
            _SAVED.clear()
            for setter, getter in _controls():
                before = int(getter())
                if before != 1:
                    setter(1)
                    _SAVED.append((setter, before))
        _DEPTH += 1
    try:
        yield
    finally:
        with _LOCK:
            _DEPTH -= 1
            if _DEPTH == 0:
                for setter, before in _SAVED:
                    setter(before)
                _SAVED.clear()


def with_one_blas_thread(fn: F) -> F:
    """Decorator: ``fn`` runs inside :func:`one_blas_thread`."""
    import functools

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with one_blas_thread():
            return fn(*args, **kwargs)
    return wrapper  # type: ignore[return-value]
