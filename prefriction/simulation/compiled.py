"""Just-in-time compilation of CasADi Functions with a compiled-code cache on disk.

:func:`compiled` generates C code for a CasADi Function (``Function.generate``), compiles it
with the system C compiler (``gcc -O2 -shared``) into a shared library named by the SHA-256 of
the generated code, and loads it with ``casadi.external``. The library is kept in the cache
directory (``$PREFRICTION_CACHE``, else ``~/.cache/prefriction``), so a second process with the
same Function loads it without compiling. Without a compiler, with ``PREFRICTION_NO_JIT=1``, or
if compiling fails, the interpreted Function is returned: same results, slower calls.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

__all__ = ["CompileInfo", "cache_dir", "compiled", "jit_available"]


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
    """Directory of the compiled-code cache: ``$PREFRICTION_CACHE`` or ``~/.cache/prefriction``."""
    env = os.environ.get("PREFRICTION_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "prefriction"


def _compiler() -> str | None:
    """Path of the C compiler to use (``$CC`` or ``gcc``), or None if there is none."""
    return _which(os.environ.get("CC", "gcc"))


@functools.lru_cache(maxsize=8)
def _which(name: str) -> str | None:
    """``shutil.which`` once per name (it searches the PATH: ~0.2 ms per call)."""
    return shutil.which(name)


def jit_available() -> bool:
    """True if compiled code can be used: a C compiler exists and ``PREFRICTION_NO_JIT`` is unset."""
    return os.environ.get("PREFRICTION_NO_JIT", "") in ("", "0") and _compiler() is not None


def compiled(fun: ca.Function, what: str = "") -> tuple[ca.Function, CompileInfo]:
    """Return a compiled equivalent of ``fun`` (loaded from the cache if present) and how it was made.

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
    if os.environ.get("PREFRICTION_NO_JIT", "") not in ("", "0"):
        return fun, CompileInfo("interpreted", 0.0, reason="PREFRICTION_NO_JIT is set")
    cc = _compiler()
    if cc is None:
        return fun, CompileInfo("interpreted", 0.0, reason="no C compiler found (gcc or $CC)")
    start = time.perf_counter()
    name = fun.name()
    with tempfile.TemporaryDirectory(prefix="prefriction-") as tmp:
        src = Path(tmp) / f"{name}.c"
        try:
            cg = ca.CodeGenerator(src.name, {"with_header": False})
            cg.add(fun)
            cg.generate(tmp + os.sep)
        except RuntimeError as exc:  # the Function cannot be code-generated
            return fun, CompileInfo("interpreted", 0.0, reason=f"code generation failed: {exc}")
        code = src.read_bytes()
        key = hashlib.sha256(code + cc.encode()).hexdigest()[:24]
        directory = cache_dir()
        lib = directory / f"{name}_{key}.so"
        if lib.exists():
            try:
                return ca.external(name, str(lib)), CompileInfo("cached", 0.0, str(lib))
            except RuntimeError:
                lib.unlink(missing_ok=True)  # corrupt or foreign library: rebuild it below
        print(f"prefriction: compiling {name} ({what or 'plant'}) once per structure; cached in {directory}",
              file=sys.stderr, flush=True)
        try:
            directory.mkdir(parents=True, exist_ok=True)
            part = Path(tmp) / lib.name
            subprocess.run(
                [cc, "-O2", "-shared", "-fPIC", str(src), "-o", str(part), "-lm"],
                check=True,
                capture_output=True,
                timeout=300,
            )
            # atomic publish: concurrent processes never load a half-written library
            staged = directory / f".{lib.name}.{os.getpid()}"
            shutil.copyfile(part, staged)
            os.replace(staged, lib)
            ext = ca.external(name, str(lib))
        except (OSError, subprocess.SubprocessError, RuntimeError) as exc:
            return fun, CompileInfo("interpreted", 0.0, reason=f"compiling failed: {exc}")
    return ext, CompileInfo("compiled", time.perf_counter() - start, str(lib))
