"""Just-in-time compilation of CasADi Functions with a compiled-code cache on disk.

:func:`compiled` generates C code for a CasADi Function (``Function.generate``), compiles it
with the system C compiler (``gcc -O1 -shared``) into a shared library named by the SHA-256 of
the generated code and the flags, and loads it with ``casadi.external``. The library is kept in the cache
directory (``$PREFRICTION_CACHE``, else ``~/.cache/prefriction``), so a second process with the
same Function loads it without compiling; :mod:`prefriction.simulation.library_store` writes
libraries atomically and verifies a checksum before loading one. Processes that need the same
library at once (e.g. pytest-xdist workers) compile it once: one holds a lock beside the library
while it compiles and publishes it, the others wait and load it. Without a compiler, with
``PREFRICTION_NO_JIT=1``, or if compiling fails, the interpreted Function is returned: the
same computation, slower calls (results agree to rounding: the compiler may order floating-point
operations differently). With no C compiler at all, one warning per process says what that costs.

Only the user's own files are loaded: the cache directory must be this user's and writable by
no one else (else this process compiles into a private temporary directory and says so once);
see :mod:`prefriction.simulation.library_store` and :mod:`prefriction._safe_files`.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional

import casadi as ca

from prefriction import _safe_files as safe
from prefriction.simulation import library_store as store

__all__ = ["CompileInfo", "cache_dir", "compile_timeout", "compiled", "compiled_seconds", "generated_source", "jit_available", "library",
           "no_jit"]

_SPENT = [0.0]  # wall time spent generating and compiling code in this process [s]

CFLAGS = ("-O1", "-shared", "-fPIC")
"""Compiler flags. ``-O1`` compiles in about 35 % less CPU time than ``-O2`` (1.7 s against
2.6 s for a LuGre, a GMS and a Dahl plant) and the runs take the same time within 5 % (forced
LuGre with dense output, unforced GMS with 3 elements and Dahl, interleaved rounds)."""


def compiled_seconds() -> float:
    """Wall time [s] this process has spent generating and compiling code (all calls of :func:`compiled`)."""
    return _SPENT[0]


@dataclass(frozen=True)
class CompileInfo:
    """How a Function was obtained: ``mode`` is ``"compiled"``, ``"cached"`` or ``"interpreted"``.

    ``seconds`` is the wall time spent generating and compiling code (0 when loaded from the
    cache or interpreted); ``path`` the shared library (``None`` when interpreted); ``reason``
    why the interpreted Function was used, if it was.
    """

    mode: str
    seconds: float
    path: str | None = None
    reason: str = ""


def cache_dir() -> Path:
    """Directory of the compiled-code cache: ``$PREFRICTION_CACHE`` (``~`` expanded, made
    absolute) or ``~/.cache/prefriction``."""
    env = os.environ.get("PREFRICTION_CACHE", "")
    return Path(os.path.abspath(os.path.expanduser(env))) if env else Path.home() / ".cache" / "prefriction"


_FALSE = ("", "0", "false", "no", "off")
_TRUE = ("1", "true", "yes", "on")
_WARNED: list[bool] = []
NO_TIMEOUT = 1e6
"""A ``PREFRICTION_COMPILE_TIMEOUT`` at or above this [s] (about 11.6 days), ``inf`` included, means no limit."""


def no_jit() -> bool:
    """True if ``$PREFRICTION_NO_JIT`` turns compiled code off (``1``, ``true``, ``yes``, ``on``;
    ``0``, ``false``, ``no``, ``off`` or unset leave it on; any case). ``ValueError`` for other values."""
    value = os.environ.get("PREFRICTION_NO_JIT", "")
    word = value.strip().lower()
    if word in _FALSE:
        return False
    if word in _TRUE:
        return True
    raise ValueError(f"the environment variable PREFRICTION_NO_JIT must be one of 1, true, yes, on (compiled code "
                     f"off) or 0, false, no, off, empty (on), got {value!r}")


def _compiler() -> str | None:
    """Path of the C compiler to use (``$CC`` or ``gcc``), or None if there is none."""
    return _which(os.environ.get("CC", "gcc"))


@functools.lru_cache(maxsize=8)
def _which(name: str) -> str | None:
    """``shutil.which`` once per name (it searches the PATH: ~0.2 ms per call)."""
    return shutil.which(name)


def jit_available() -> bool:
    """True if compiled code can be used: a C compiler exists and ``PREFRICTION_NO_JIT`` is off.

    The first time in a process that no compiler is found, a ``RuntimeWarning`` says what that
    costs and how to install one.
    """
    if no_jit():
        return False
    if _compiler() is not None:
        return True
    if not _WARNED:
        _WARNED.append(True)
        warnings.warn(
            f"prefriction found no C compiler ({os.environ.get('CC', 'gcc')!r}, from $CC or gcc, is not on the PATH): "
            "simulations run interpreted, about 100 times slower. Install one (Debian/Ubuntu: apt install gcc; "
            "Fedora: dnf install gcc; macOS: xcode-select --install; conda: conda install c-compiler) or set "
            "PREFRICTION_NO_JIT=1 to choose interpreted code without this warning.", RuntimeWarning, stacklevel=2)
    return False


def compile_timeout() -> float:
    """Longest wait for the C compiler [s]: ``$PREFRICTION_COMPILE_TIMEOUT``, else 120.

    ``inf`` or any value at or above :data:`NO_TIMEOUT` means no limit (returned as ``inf``);
    ``ValueError`` naming the variable for a value that is no number > 0.
    """
    text = os.environ.get("PREFRICTION_COMPILE_TIMEOUT", "").strip()
    if not text:
        return 120.0
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0:
        raise ValueError(f"the environment variable PREFRICTION_COMPILE_TIMEOUT must be a number of seconds > 0 "
                         f"(inf or >= {NO_TIMEOUT:g} for no limit), got {text!r}")
    return float("inf") if value >= NO_TIMEOUT else value


def _say(line: str) -> None:
    print(f"prefriction: {line}", file=sys.stderr, flush=True)


def compiled(fun: ca.Function, what: str = "") -> tuple[ca.Function, CompileInfo]:
    """Return a compiled equivalent of ``fun`` (loaded from the cache if present) and how it was made.

    A cached library is used only if it matches the checksum stored beside it and has the inputs
    and outputs of ``fun`` (:mod:`prefriction.simulation.library_store`); otherwise it is rebuilt,
    with one line on stderr saying what was wrong. If the cache cannot hold the library (not
    writable, a directory in its place), the library is built in a directory of this process and
    the line says so. A compiler that runs longer than :func:`compile_timeout` is stopped, the
    interpreted Function is used, and later processes use it at once (the line names the file
    to delete to try again). While another process compiles the same library, this one waits
    (one line on stderr; at most :func:`compile_timeout` + 10 s, then it compiles it itself) and
    loads the library that process published (``CompileInfo.mode == "cached"``).

    Parameters
    ----------
    fun : casadi.Function
        A Function that supports code generation (e.g. an ``erk`` or ``rosenbrock`` integrator).
    what : str, optional
        What the Function is, for the one line printed to stderr when it is compiled.

    Returns
    -------
    (casadi.Function, CompileInfo)
        The external Function with the same inputs and outputs as ``fun``, or ``fun`` itself
        when no compiler is available or compiling fails (``CompileInfo.reason`` says why).
    """
    if no_jit():
        return fun, CompileInfo("interpreted", 0.0, reason="PREFRICTION_NO_JIT is set")
    name = fun.name()
    try:
        source = generated_source(name, [fun])
    except RuntimeError as exc:  # the Function cannot be code-generated
        return fun, CompileInfo("interpreted", 0.0, reason=f"code generation failed: {exc}")
    ext, info = library(name, source, what or "plant", lambda lib, key: store.load(fun, lib, key))
    return (fun if ext is None else ext), info


def generated_source(name: str, funs: list[ca.Function]) -> str:
    """C source of the CasADi Functions ``funs`` by CasADi's code generator (no header), written as
    ``<name>.c`` in a private temporary directory and read back.

    Raises
    ------
    RuntimeError
        CasADi's, for a Function that cannot be code-generated.
    """
    with tempfile.TemporaryDirectory(prefix="prefriction-") as tmp:
        cg = ca.CodeGenerator(f"{name}.c", {"with_header": False})
        for fun in funs:
            cg.add(fun)
        cg.generate(tmp + os.sep)
        return (Path(tmp) / f"{name}.c").read_text()


def library(name: str, source: str, what: str, load: Callable[[Path, str], tuple[Optional[Any], str]],
            fallback: str = "the interpreted Function",
            cflags: tuple[str, ...] = CFLAGS) -> tuple[Optional[Any], CompileInfo]:
    """The shared library of the C ``source`` from the cache, or compiled into it, loaded by ``load``.

    ``load(path, key)`` returns the loaded object or ``None`` and what is wrong with the file
    (``""`` if there is none yet). One process compiles a library at a time: another that needs
    it waits on the lock beside it (:func:`~prefriction.simulation.library_store.build_lock`)
    and loads what the first published. Returns ``(None, info)`` when no compiler is available
    or compiling fails (``info.reason`` says why): the caller then uses ``fallback``, which the
    line printed to stderr names. ``cflags`` are the compiler flags (they enter the key).
    """
    if no_jit():
        return None, CompileInfo("interpreted", 0.0, reason="PREFRICTION_NO_JIT is set")
    cc = _compiler()
    if cc is None:
        jit_available()  # the one warning of the process
        return None, CompileInfo("interpreted", 0.0, reason="no C compiler found (gcc or $CC)")
    start = time.perf_counter()
    key = hashlib.sha256(source.encode() + " ".join((cc, *cflags)).encode()
                         + ca.__version__.encode()).hexdigest()[:24]
    cache = cache_dir()
    directory, refused = store.trusted_dir(cache)
    if refused:
        _say(f"the compile cache {cache} is refused ({refused}): a library there could have been written by "
             f"someone else. Compiled code is kept for this process only, in {directory}; make the cache yours and "
             f"private (chown, chmod 700) or set PREFRICTION_CACHE to a directory of yours")
    lib = directory / f"{name}_{key}.so"
    found, problem = _from_cache(name, lib, key, load, fallback)
    if found is not None:
        return found
    blocked = store.unwritable(directory, lib) or (f"the cache {cache} is not trusted" if directory != cache else "")
    if blocked:
        return _build(name, source, what, (cc, *cflags), lib, key, problem, blocked, start, load, fallback)
    patience = compile_timeout() + 10.0  # the holder's compiler is stopped after compile_timeout()
    with store.build_lock(lib, patience, lambda path: _say(
            f"{name}: waiting for another process that is compiling it (lock {path})")):
        found, problem = _from_cache(name, lib, key, load, fallback)  # published while this process waited
        if found is not None:
            return found
        return _build(name, source, what, (cc, *cflags), lib, key, problem, "", start, load, fallback)


def _from_cache(name: str, lib: Path, key: str, load: Callable[[Path, str], tuple[Optional[Any], str]],
                fallback: str) -> tuple[Optional[tuple[Optional[Any], CompileInfo]], str]:
    """The verified library ``lib`` loaded, or no library after an earlier failed build of it;
    else ``None`` and what is wrong with the library there (``""`` if there is none)."""
    ext, problem = load(lib, key)
    if ext is not None:
        return (ext, CompileInfo("cached", 0.0, str(lib))), ""
    earlier = store.failure_note(lib, compile_timeout())
    if earlier:
        _say(f"{name}: {earlier}; using {fallback} (the same computation, slower)")
        return (None, CompileInfo("interpreted", 0.0, reason=earlier)), ""
    return None, problem


def _build(name: str, source: str, what: str, command: tuple[str, ...], lib: Path, key: str, problem: str, blocked: str,
           start: float, load: Callable[[Path, str], tuple[Optional[Any], str]],
           fallback: str) -> tuple[Optional[Any], CompileInfo]:
    """Compile ``source`` into ``lib`` (or a directory of this process if ``blocked`` says why the
    cache cannot hold it), publish it and load it; ``problem`` is what was wrong with the library
    found there, ``command`` the compiler and its flags, ``start`` when :func:`library` began [s]."""
    cc = command[0]
    dest = store.private_dir() / lib.name if blocked else lib
    where = (f"{blocked}: compiled code kept for this process only, in {dest.parent}" if blocked
             else f"cached in {lib.parent}")
    _say(f"compiling {name} ({what}) once per structure; "
         + (f"replacing a bad library: {problem}; " if problem else "") + where)
    with tempfile.TemporaryDirectory(prefix="prefriction-") as tmp:
        src = Path(tmp) / f"{name}.c"
        src.write_text(source)
        part = src.with_name(lib.name)
        try:
            _run_compiler([*command, str(src), "-o", str(part), "-lm"])
        except subprocess.TimeoutExpired:
            why = f"compiling {name} with {cc} took longer than {compile_timeout():g} s (PREFRICTION_COMPILE_TIMEOUT)"
            return _interpreted(lib, why, fallback, timeout=compile_timeout())
        except subprocess.CalledProcessError as exc:
            detail = exc.stderr.decode(errors="replace").strip().splitlines()[-1:] or [f"exit status {exc.returncode}"]
            return _interpreted(lib, f"compiling {name} with {cc} failed: {detail[0]}", fallback)
        except OSError as exc:
            return _interpreted(lib, f"running the compiler {cc} failed: {exc}", fallback, record=False)
        try:
            store.publish(part, dest, key)
        except OSError as exc:  # the cache changed under us: keep the library for this process
            dest = store.private_dir() / lib.name
            store.publish(part, dest, key)
            _say(f"{lib} could not be written ({exc.strerror or exc}); compiled code kept in {dest.parent}")
    ext, problem = load(dest, key)
    if ext is None:
        return _interpreted(lib, f"the freshly compiled library could not be used: {problem}", fallback, record=False)
    seconds = time.perf_counter() - start
    _SPENT[0] += seconds
    return ext, CompileInfo("compiled", seconds, str(dest))


def _run_compiler(cmd: list[str]) -> None:
    """Run the compiler; on timeout stop it and everything it started (``TimeoutExpired``)."""
    with subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True) as proc:
        try:
            limit = compile_timeout()
            out, err = proc.communicate(timeout=None if limit == float("inf") else limit)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
            raise
    if proc.returncode:
        raise subprocess.CalledProcessError(proc.returncode, cmd, out, err)


def _interpreted(lib: Path, why: str, fallback: str, record: bool = True,
                 timeout: Optional[float] = None) -> tuple[None, CompileInfo]:
    """No library: one line on stderr (the caller falls back to interpreted code); note a
    compiler failure beside ``lib`` (``timeout`` [s]: the limit it was stopped at)."""
    if record:
        store.record_failure(lib, why, timeout)
    _say(f"{safe.printable(why, 500)}; using {fallback} (the same computation, slower)")
    return None, CompileInfo("interpreted", 0.0, reason=why)
