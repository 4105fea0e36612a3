"""CasADi Functions as plain C99 text, and the checks and file writing every export shares."""

from __future__ import annotations

import keyword
import re
from pathlib import Path
from typing import Any

import casadi as ca

__all__ = ["c_text", "check_name", "directory_of", "work_sizes"]

_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "_Bool _Complex _Imaginary main".split()
)
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,62}$")
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


def check_name(name: Any) -> str:
    """``name`` as a C identifier for the exported symbols (ValueError/TypeError naming it)."""
    if not isinstance(name, str):
        raise TypeError(f"name must be a str (a C identifier), got {type(name).__name__} {name!r}")
    if not _IDENT.match(name) or name in _C_KEYWORDS or keyword.iskeyword(name) or name.startswith("casadi"):
        raise ValueError(
            f"name must be a C identifier of 1 to 63 letters, digits and underscores, starting with a letter or "
            f"underscore, not a C keyword and not starting with 'casadi', got {name!r}"
        )
    return name


def directory_of(directory: Any) -> Path:
    """``directory`` as a Path, created if missing (TypeError naming it if it is no path)."""
    if not isinstance(directory, (str, Path)):
        raise TypeError(f"directory must be a str or pathlib.Path, got {type(directory).__name__} {directory!r}")
    path = Path(directory)
    if path.exists() and not path.is_dir():
        raise ValueError(f"directory must be a directory, got the file {str(path)!r}")
    path.mkdir(parents=True, exist_ok=True)
    return path


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
