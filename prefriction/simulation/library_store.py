"""The on-disk store of compiled libraries: atomic writes, a checksum beside each, verified loads.

A library ``NAME_KEY.so`` (``KEY`` hashes the generated C code, the compiler and the CasADi
version) is published by writing a temporary file in the same directory and renaming it, so a
reader never sees half a file. Beside it, ``NAME_KEY.so.sha256`` holds the SHA-256 of the
library's bytes and the key. :func:`load` checks both, and that the loaded Function has the
inputs and outputs of the one it stands for, before the library is used: a truncated, damaged
or foreign library (another structure's under this name), a directory in its place or a file
that cannot be read is reported as a problem (a string) instead of being loaded, which could
kill the process (SIGBUS, SIGILL). ``NAME_KEY.failed`` records a compilation that timed out,
so later processes do not wait for the compiler again. ``NAME_KEY.so.lock`` is the lock that one
process holds (``fcntl.flock``) while it builds and publishes the library: a second process that
needs the same library waits for it (:func:`build_lock`) and then loads the published library
instead of compiling it again. The kernel releases the lock when its holder exits, so a killed
process leaves no stale lock; without ``fcntl`` (Windows) there is no lock and two processes may
both compile (each publishes the same bytes atomically).

Every file is read and written through :mod:`prefriction._safe_files`: the cache directory is
created 0700 and used only if it and its parents are this user's own and not writable by
others (:func:`trusted_dir`; else this process compiles into a private temporary directory);
libraries, checksums, notes and locks are opened without following links and must be this
user's files; a note is printed as data (printable ASCII, one line), never raw.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import hashlib
import os
import shutil
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Optional

import casadi as ca

from prefriction import _safe_files as safe

try:
    import fcntl
except ImportError:  # Windows: no advisory file locks; concurrent builds stay correct, only duplicated
    fcntl = None  # type: ignore[assignment]

__all__ = ["build_lock", "failure_note", "load", "private_dir", "publish", "record_failure", "trusted_dir",
           "unwritable", "verify"]

_PRIVATE: list[Path] = []
_PRIVATE_LOCK = threading.Lock()
_REFUSED: dict[str, str] = {}  # cache directories refused in this process -> why
MAX_LIBRARY = 1 << 30
"""Largest library [bytes] the cache reads (a generated plant is a few MiB)."""
MAX_NOTE = 4096
"""Largest checksum or failure note [bytes] the cache reads."""


def _sidecar(lib: Path) -> Path:
    return lib.with_name(lib.name + ".sha256")


def _marker(lib: Path) -> Path:
    return lib.with_name(lib.name[: -len(".so")] + ".failed")


def _same_signature(a: ca.Function, b: ca.Function) -> bool:
    """True if ``a`` and ``b`` have the same inputs and outputs (counts and sparsity patterns)."""
    if (a.n_in(), a.n_out()) != (b.n_in(), b.n_out()):
        return False
    return (all(a.sparsity_in(i) == b.sparsity_in(i) for i in range(a.n_in()))
            and all(a.sparsity_out(i) == b.sparsity_out(i) for i in range(a.n_out())))


def verify(lib: Path, key: str) -> str:
    """What is wrong with the stored library ``lib`` of ``key`` (``""`` if it can be loaded,
    ``"missing"`` if there is none yet)."""
    if not os.path.lexists(lib):
        return "missing"
    if lib.is_dir() and not lib.is_symlink():
        return f"{lib} is a directory, not a library"
    try:
        actual = hashlib.sha256(safe.read_owned(lib, MAX_LIBRARY)).hexdigest()
    except safe.UnsafeFile as exc:
        return f"{exc}: not loaded"
    except OSError as exc:
        return f"{lib} cannot be read ({exc.strerror or exc})"
    try:
        stored = safe.read_owned(_sidecar(lib), MAX_NOTE).decode("ascii", "replace").split()
    except safe.UnsafeFile as exc:
        return f"{exc}: {lib} not loaded"
    except OSError:
        return f"{lib} has no readable checksum beside it (written by an older version or damaged)"
    if stored[1:2] != [key]:
        return f"{lib} belongs to another structure (its checksum file names another key)"
    if stored[:1] != [actual]:
        return f"{lib} does not match its checksum (truncated, damaged or replaced)"
    return ""


def load_verified(lib: Path, key: str, symbols: tuple[str, ...]) -> tuple[Optional[ctypes.CDLL], str]:
    """The stored library ``lib`` of ``key`` loaded with ctypes once :func:`verify` passes, if it
    exports every name in ``symbols``; else None and what is wrong (``""`` if there is none yet).

    Every compiled library of the toolbox is loaded here (bind ``symbols`` with
    :func:`functools.partial` to get the loader :func:`library` takes)."""
    problem = verify(lib, key)
    if problem:
        return None, "" if problem == "missing" else problem
    try:
        handle = ctypes.CDLL(str(lib))
    except OSError as exc:
        return None, f"{lib} could not be loaded ({exc})"
    missing = [name for name in symbols if not hasattr(handle, name)]
    if missing:
        return None, f"{lib} has no {', '.join(missing)}"
    return handle, ""


def load(fun: ca.Function, lib: Path, key: str) -> tuple[Optional[ca.Function], str]:
    """The verified library ``lib`` of ``fun`` loaded, or ``None`` and what is wrong with it.

    The problem is ``""`` when there is no library yet (nothing to report).
    """
    problem = verify(lib, key)
    if problem:
        return None, "" if problem == "missing" else problem
    try:
        ext = ca.external(fun.name(), str(lib))
    except RuntimeError as exc:
        return None, f"{lib} could not be loaded ({str(exc).strip().splitlines()[-1]})"
    if not _same_signature(fun, ext):
        return None, f"{lib} has the inputs and outputs of another Function"
    return ext, ""


def publish(built: Path, lib: Path, key: str) -> None:
    """Store the freshly built library ``built`` as ``lib`` with its checksum (``OSError`` if it cannot)."""
    data = built.read_bytes()
    safe.write_atomic(lib, data)
    safe.write_atomic(_sidecar(lib), f"{hashlib.sha256(data).hexdigest()} {key}\n".encode())
    _marker(lib).unlink(missing_ok=True)


def unwritable(directory: Path, lib: Path) -> str:
    """Why ``lib`` cannot be stored in ``directory`` (``""`` if it can)."""
    try:
        safe.make_private_dir(directory)
        fd, probe = tempfile.mkstemp(prefix=".probe.", dir=directory)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        return f"the cache {directory} is not writable ({exc.strerror or exc})"
    if lib.is_dir() and not lib.is_symlink():
        return f"{lib} is a directory, not a library (remove it to use the cache again)"
    return ""


def trusted_dir(directory: Path) -> tuple[Path, str]:
    """The directory to load libraries from and store them in, and why ``directory`` was refused.

    ``directory`` (created with its missing parents, mode 0700) is used if it and its parents
    are this user's own and not writable by others (:func:`prefriction._safe_files.dir_problem`);
    otherwise this process's :func:`private_dir` is, and the second item says why (non-empty
    only the first time a directory is refused in this process: one message each).
    """
    try:
        safe.make_private_dir(directory)
    except OSError:
        return directory, ""  # nothing there to load; unwritable() says why it cannot be stored
    key = str(directory)
    if key in _REFUSED:
        return private_dir(), ""
    problem = safe.dir_problem(directory)
    if not problem:
        return directory, ""
    _REFUSED[key] = problem
    return private_dir(), problem


def private_dir() -> Path:
    """A directory of this process (mode 0700) for libraries the cache cannot hold (removed at exit)."""
    with _PRIVATE_LOCK:
        if not _PRIVATE:
            path = Path(tempfile.mkdtemp(prefix="prefriction-jit-"))
            atexit.register(shutil.rmtree, path, True)
            _PRIVATE.append(path)
        return _PRIVATE[0]


def record_failure(lib: Path, why: str, timeout: Optional[float] = None) -> None:
    """Note beside ``lib`` that building it failed with ``why`` (best effort); ``timeout`` [s] is
    the compiler's time limit if it was stopped (a later process with a longer one tries again)."""
    try:
        safe.write_atomic(_marker(lib), f"timeout={'' if timeout is None else repr(float(timeout))}\n{why}".encode())
    except OSError:
        pass


def failure_note(lib: Path, timeout: float) -> str:
    """The failure recorded beside ``lib`` by an earlier process, with how to retry (``""`` if none).

    A note is data: it is read only if it is this user's own file (no link followed) and returned
    as one line of printable ASCII. A note of a compiler stopped after a shorter time limit than
    ``timeout`` [s] is ignored (this process tries again, with its longer limit).
    """
    marker = _marker(lib)
    try:
        text = safe.read_owned(marker, MAX_NOTE).decode("utf-8", "replace")
    except OSError:
        return ""
    first, _, why = text.partition("\n")
    if not first.startswith("timeout="):
        return ""  # not a note this version wrote
    try:
        limit = float(first[len("timeout="):]) if first != "timeout=" else None
    except ValueError:
        return ""
    if limit is not None and not timeout <= limit:
        return ""
    return f"{safe.printable(why)} in an earlier process; delete {marker} to try again"


@contextlib.contextmanager
def build_lock(lib: Path, patience: float, waiting: Callable[[Path], None]) -> Iterator[bool]:
    """Hold the lock beside ``lib`` while building it; yields True if the lock is held.

    If another process holds it, ``waiting(lock_path)`` is called once and the lock is polled
    until it is free or ``patience`` seconds [s] have passed; then (and where there is no
    ``fcntl`` or the lock file cannot be opened) it yields False and the caller builds without
    the lock, as it would with no other process: the publish is atomic either way.
    """
    if fcntl is None:
        yield False
        return
    path = lib.with_name(lib.name + ".lock")
    try:
        fd = safe.open_lock(path)
    except OSError:  # a link or another user's file (not followed), or no lock possible here
        yield False
        return
    try:
        yield _acquire(fd, path, patience, waiting)
    finally:
        os.close(fd)  # closing the descriptor releases the lock


def _acquire(fd: int, path: Path, patience: float, waiting: Callable[[Path], None]) -> bool:
    """Take the exclusive lock on ``fd``, waiting at most ``patience`` [s]; True if taken."""
    deadline = time.monotonic() + patience
    told = False
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            pass
        except OSError:  # a file system without locks
            return False
        if not told:
            waiting(path)
            told = True
        if time.monotonic() >= deadline:
            return False
        time.sleep(0.02)
