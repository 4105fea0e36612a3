"""CasADi Functions as plain C99 text, and the checks and file writing every export shares.

What an export writes is its user's own and holds only what it means: the name is a plain C
identifier that shadows no system header (:func:`check_name`), text from the model (a class
name, a controller's description) enters the C only as a sanitised comment
(:func:`comment_text`), and the files are written atomically, never through a link
(:func:`write_export`); the SHA-256 of what was written identifies the export
(:attr:`prefriction.export.CSource.digest`).
"""

from __future__ import annotations

import hashlib
import keyword
import os
import re
from pathlib import Path
from typing import Any

import casadi as ca

from prefriction import _safe_files as safe
from prefriction._validation import check_positive

__all__ = ["MIN_TS", "c_text", "check_name", "check_sample_time", "comment_text", "work_sizes",
           "write_export"]

MIN_TS = 1e-12
"""Shortest sample time [s] an export takes (a 1 THz sampler): below it velocities
``(x - x_prev) / Ts`` and normalised steps leave the double-precision range (``Ts = 5e-324``
gave NaN forces)."""

_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "_Bool _Complex _Imaginary main".split()
)
_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")
_SYSTEM_HEADERS = frozenset(
    # C11 and POSIX headers: an export <name>.h of one of these names would be included in
    # their place by any code compiled with -I pointing at the export's directory
    "assert complex ctype errno fenv float inttypes iso646 limits locale math setjmp signal stdalign stdarg "
    "stdatomic stdbool stddef stdint stdio stdlib stdnoreturn string tgmath threads time uchar wchar wctype "
    "aio arpa cpio dirent dlfcn fcntl fmtmsg fnmatch ftw glob grp iconv langinfo libgen monetary mqueue ndbm "
    "netdb nl_types poll pthread pwd regex sched search semaphore spawn strings stropts syslog tar termios "
    "trace ulimit unistd utime utmpx wordexp malloc alloca memory features endian byteswap".split()
)
_OPTIONS = {
    "with_header": False,     # the export writes its own header (no casadi types in it)
    "with_export": False,     # no dllexport decoration
    "with_mem": False,        # no memory-object API
    "main": False,
    "mex": False,
    "cpp": False,
    "verbose": False,
    "casadi_real": "double",
    "casadi_int": "long",
    "include_math": True,     # <math.h>: the only dependency (link with -lm)
    "avoid_stack": False,
}


def check_sample_time(Ts: Any) -> float:
    """``Ts`` [s] as a finite float ``>= MIN_TS`` (ValueError/TypeError naming it)."""
    Ts = check_positive("Ts", Ts)
    if Ts < MIN_TS:
        raise ValueError(f"Ts must be a sample time >= {MIN_TS:g} s (shorter ones overflow the velocity "
                         f"(x - x_prev) / Ts in double precision), got {Ts!r}")
    return Ts


def check_name(name: Any) -> str:
    """``name`` as a C identifier for the exported symbols and files (ValueError/TypeError naming it).

    1 to 63 ASCII letters, digits and underscores starting with a letter (identifiers starting
    with ``_`` are the C library's), not a C or Python keyword, not starting with ``casadi`` and
    not the name of a C or POSIX header in any case (``math``, ``stdio``, ``time``, ...).
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a str (a C identifier), got {type(name).__name__} {name!r}")
    if (not _IDENT.fullmatch(name) or name in _C_KEYWORDS or keyword.iskeyword(name)
            or name.lower().startswith("casadi")):
        raise ValueError(
            f"name must be a C identifier of 1 to 63 letters, digits and underscores, starting with a letter, "
            f"not a C keyword and not starting with 'casadi', got {name!r}"
        )
    if name.lower() in _SYSTEM_HEADERS:
        raise ValueError(f"name must not be the name of a C or POSIX header ({name.lower()}.h would shadow the "
                         f"system's), got {name!r}")
    return name


def comment_text(text: str) -> str:
    """``text`` fit for a C block comment: one line of printable ASCII without ``*/``, ``/*`` or ``\\``."""
    line = safe.printable(str(text), 400).replace("\\", "/")
    while "*/" in line or "/*" in line:
        line = line.replace("*/", "* /").replace("/*", "/ *")
    return line


def write_export(path: Path, name: str, header: str, body: str) -> tuple[Path, Path, str]:
    """Write ``<name>.h`` and ``<name>.c`` into the directory ``path``; their paths and digest.

    Each file is written atomically (a new temporary file renamed over it, mode 0644); a symbolic
    link at either path is refused (``ValueError``), never followed or replaced, and a directory
    that cannot be written is a ``ValueError`` naming it. The digest is the
    SHA-256 of both texts, which :meth:`prefriction.export.CSource.texts` checks before use.
    """
    h_path, c_path = path / f"{name}.h", path / f"{name}.c"
    for target in (h_path, c_path):
        if os.path.islink(target):
            raise ValueError(f"{target} is a symbolic link: an export never writes through a link (remove it or "
                             f"export into another directory)")
        if os.path.isdir(target):
            raise ValueError(f"{target} is a directory: an export writes a file of that name there")
    data = header.encode(), body.encode()
    try:
        safe.write_atomic(h_path, data[0], 0o644)
        safe.write_atomic(c_path, data[1], 0o644)
    except OSError as exc:
        raise ValueError(f"directory {str(path)!r}: the export {name!r} cannot be written there "
                         f"({exc.strerror or exc})") from exc
    return h_path, c_path, digest(*data)


def digest(header: bytes, body: bytes) -> str:
    """The SHA-256 (hex) that identifies an export's header and source texts."""
    return hashlib.sha256(hashlib.sha256(header).digest() + hashlib.sha256(body).digest()).hexdigest()


def c_text(functions: dict[str, ca.Function], prefix: str) -> str:
    """The C99 source of ``functions`` (symbol name -> Function), CasADi's code generator without
    a casadi header; ``prefix`` prefixes the internal symbols.

    Each entry point is ``int name(const double **arg, double **res, long *iw, double *w, int mem)``;
    numbers that are constants of a Function are literals of the text.
    """
    cg = ca.CodeGenerator(prefix, _OPTIONS)
    for name, fun in functions.items():
        cg.add(_renamed(fun, name))
    return cg.dump()


def _renamed(fun: ca.Function, name: str) -> ca.Function:
    """``fun`` under the name ``name`` (the generated entry point)."""
    if fun.name() == name:
        return fun
    args = fun.sx_in() if fun.is_a("SXFunction") else fun.mx_in()
    return ca.Function(name, args, fun.call(args), fun.name_in(), fun.name_out())


def work_sizes(fun: ca.Function) -> tuple[int, int, int, int]:
    """``(sz_arg, sz_res, sz_iw, sz_w)`` of ``fun``: the buffers its generated code needs."""
    return int(fun.sz_arg()), int(fun.sz_res()), int(fun.sz_iw()), int(fun.sz_w())
