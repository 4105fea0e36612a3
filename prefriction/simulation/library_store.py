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
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Optional

import casadi as ca

try:
    import fcntl
except ImportError:  # Windows: no advisory file locks; concurrent builds stay correct, only duplicated
    fcntl = None  # type: ignore[assignment]

__all__ = ["build_lock", "failure_note", "load", "private_dir", "publish", "record_failure", "unwritable", "verify"]

_PRIVATE: list[Path] = []


def _sidecar(lib: Path) -> Path:
    return lib.with_name(lib.name + ".sha256")


def _marker(lib: Path) -> Path:
    return lib.with_name(lib.name[: -len(".so")] + ".failed")


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


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
    if lib.is_dir():
        return f"{lib} is a directory, not a library"
    try:
        stored = _sidecar(lib).read_text().split()
    except OSError:
        return f"{lib} has no readable checksum beside it (written by an older version or damaged)"
    try:
        actual = _digest(lib)
    except OSError as exc:
        return f"{lib} cannot be read ({exc.strerror or exc})"
    if stored[1:2] != [key]:
        return f"{lib} belongs to another structure (its checksum file names another key)"
    if stored[:1] != [actual]:
        return f"{lib} does not match its checksum (truncated, damaged or replaced)"
    return ""


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


def _atomic_write(data: bytes, dest: Path) -> None:
    """Write ``data`` to ``dest`` through a temporary file in its directory and a rename."""
    fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", dir=dest.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)  # mkstemp makes 0600: let other users of a shared cache read it
        os.replace(tmp, dest)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def publish(built: Path, lib: Path, key: str) -> None:
    """Store the freshly built library ``built`` as ``lib`` with its checksum (``OSError`` if it cannot)."""
    data = built.read_bytes()
    _atomic_write(data, lib)
    _atomic_write(f"{hashlib.sha256(data).hexdigest()} {key}\n".encode(), _sidecar(lib))
    _marker(lib).unlink(missing_ok=True)


def unwritable(directory: Path, lib: Path) -> str:
    """Why ``lib`` cannot be stored in ``directory`` (``""`` if it can)."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".probe.", dir=directory)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        return f"the cache {directory} is not writable ({exc.strerror or exc})"
    if lib.is_dir():
        return f"{lib} is a directory, not a library (remove it to use the cache again)"
    return ""


def private_dir() -> Path:
    """A directory of this process for libraries the cache cannot hold (removed at exit)."""
    if not _PRIVATE:
        path = Path(tempfile.mkdtemp(prefix="prefriction-jit-"))
        atexit.register(shutil.rmtree, path, True)
        _PRIVATE.append(path)
    return _PRIVATE[0]


def record_failure(lib: Path, why: str) -> None:
    """Note beside ``lib`` that building it failed with ``why`` (best effort)."""
    try:
        _atomic_write(why.encode(), _marker(lib))
    except OSError:
        pass


def failure_note(lib: Path) -> str:
    """The failure recorded beside ``lib`` by an earlier process, with how to retry (``""`` if none)."""
    marker = _marker(lib)
    try:
        why = marker.read_text().strip()
    except OSError:
        return ""
    return f"{why} in an earlier process; delete {marker} to try again"


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
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
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
