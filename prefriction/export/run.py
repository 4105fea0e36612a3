"""Run an exported friction model: compiled with gcc over positions, or its Function in Python.

:func:`run_c` compiles ``<name>.c`` with a small driver (``gcc -std=c99 -Wall -Werror -O2``),
runs it over the positions and returns the forces and the time per step; :func:`evaluate` gives
the same forces from the CasADi Function the code was generated from (``Function.mapaccum``).
"""

from __future__ import annotations

import hashlib
import shutil
import subprocess
import tempfile
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from prefriction._validation import check_bool, check_count, check_real_array

from .model import virgin_state
from .source import CSource

__all__ = ["CRun", "c_driver", "compile_and_run", "evaluate", "gcc", "run_c"]

MAX_SAMPLES = 50_000_000
"""Largest number of positions :func:`run_c` takes (memory: 16 bytes each)."""
MAX_EVALUATE = 1_000_000
"""Largest number of positions :func:`evaluate` takes (CasADi's virtual machine: about 20 us each)."""
CFLAGS = ("-std=c99", "-Wall", "-Werror")
"""The compiler flags of :func:`run_c` (the code is also clean under ``-pedantic``), with ``-O2``
(``optimize=True``, timings) or ``-O0`` (a quick compile: the same numbers, IEEE arithmetic
without contraction under ``-std=c99``)."""

_HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
@INCLUDES@

int main(int argc, char **argv) {
  long n, i;
  int r, rounds;
  double *in, *out, best = 1e300, t;
  struct timespec a, b;
  FILE *f;
@STATE@
  if (argc != 5) return 2;
  n = @N@;
  rounds = atoi(argv[4]);
  in = malloc((@N_IN@) * sizeof(double));
  out = malloc((@N_OUT@) * sizeof(double));
  if (!in || !out) return 3;
  f = fopen(argv[1], "rb");
  if (!f || fread(in, sizeof(double), @N_IN@, f) != (size_t) (@N_IN@)) return 4;
  fclose(f);
  for (r = 0; r < rounds; ++r) {
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &a);
@BODY@
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &b);
    t = (b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec);
    if (t < best) best = t;
  }
  f = fopen(argv[2], "wb");
  if (!f || fwrite(out, sizeof(double), @N_OUT@, f) != (size_t) (@N_OUT@)) return 5;
  fclose(f);
  printf("%.6g\n", best / n);
  free(in);
  free(out);
  return 0;
}
"""


def c_driver(headers: list[str], state: str, n: str, n_in: str, n_out: str, body: str) -> str:
    """C source of a timing driver for :func:`compile_and_run`.

    The driver reads ``n_in`` doubles into ``in`` from the file ``argv[1]``, runs ``body`` (one
    pass over the ``n`` steps, writing ``out``) ``argv[4]`` times, writes the ``n_out`` doubles
    of ``out`` to the file ``argv[2]`` and prints the least CPU time per step [ns] over the passes.
    ``n``, ``n_in`` and ``n_out`` are C expressions (``n`` in terms of ``atol(argv[3])``, the
    number of input doubles; the others in terms of ``n``); ``state`` declares the variables of
    ``body``, and ``headers`` names the headers to include.
    """
    text = _HARNESS
    for key, value in (("@INCLUDES@", "\n".join(f'#include "{h}"' for h in headers)), ("@STATE@", state),
                       ("@N_IN@", n_in), ("@N_OUT@", n_out), ("@N@", n), ("@BODY@", body)):
        text = text.replace(key, value)
    return text


_DRIVER = c_driver(["NAME.h"], "  NAME_state s;", "atol(argv[3])", "n", "n", """\
    NAME_reset(&s, in[0]);
    for (i = 0; i < n; ++i) out[i] = NAME_force(&s, in[i]);""")


@dataclass(frozen=True)
class CRun:
    """Forces of an exported model run in C over positions, and its time per step.

    Attributes
    ----------
    F : numpy.ndarray
        Friction force [N] at each position (``<name>_force`` after ``<name>_reset(x[0])``).
    ns_per_step : float
        Least CPU time of the process per ``<name>_force`` call over the rounds [ns] (``-O2``, this machine; CPU time, so that waiting for a shared core does not count).
    rounds : int
        Timed passes over the positions.
    """

    F: np.ndarray
    ns_per_step: float
    rounds: int

    def __repr__(self) -> str:
        return f"CRun({self.F.size} samples, {self.ns_per_step:.4g} ns per step, best of {self.rounds})"

    def summary(self) -> str:
        """One line: samples, time per step, force range."""
        return (f"{self.F.size} samples in C: {self.ns_per_step:.4g} ns per step (best of {self.rounds} rounds), "
                f"F from {self.F.min():.6g} to {self.F.max():.6g} N")


def gcc() -> str | None:
    """Path of the ``gcc`` executable, or ``None`` if there is none on the ``PATH``."""
    return shutil.which("gcc")


def _source(source: Any) -> CSource:
    if not isinstance(source, CSource) or source.kind != "model":
        raise TypeError(f"source must be the CSource of prefriction.export.c_source (kind 'model'), got {source!r}")
    return source


def _positions(x: Any, limit: int = MAX_SAMPLES) -> np.ndarray:
    x = check_real_array("x", x, "m")
    if x.ndim != 1 or not 1 <= x.size <= limit:
        raise ValueError(f"x must be a 1-d array of 1 to {limit} positions [m], got shape {x.shape}")
    return np.ascontiguousarray(x, dtype=float)


def run_c(source: CSource, x: Any, *, rounds: int = 1, optimize: bool = True) -> CRun:
    """Compile the exported model with a driver and run it over the positions ``x``.

    Parameters
    ----------
    source : CSource
        What :func:`prefriction.export.c_source` wrote.
    x : array_like
        Positions [m], one per sample; the state is reset at ``x[0]`` (virgin).
    rounds : int, default 1
        Passes over ``x`` (1 to 1000); the time per step is the least over them.
    optimize : bool, default True
        Compile with ``-O2`` (``False``: ``-O0``, which compiles faster and gives the same forces).

    Returns
    -------
    CRun
        The forces [N] and the time per step [ns].

    Raises
    ------
    FileNotFoundError
        If there is no ``gcc`` on the ``PATH``.
    RuntimeError
        If the code does not compile (the message holds gcc's output) or the program fails.
    """
    source = _source(source)
    x = _positions(x)
    rounds = check_count("rounds", rounds, 1, 1000)
    out, ns = compile_and_run(source, _DRIVER, x, x.size, rounds, optimize)
    return CRun(out, ns, rounds)


def compile_and_run(source: CSource | list[CSource], driver: str, data: np.ndarray, n_out: int,
                    rounds: int, optimize: bool = True) -> tuple[np.ndarray, float]:
    """Compile ``driver`` with the export(s) (``NAME`` in it replaced by the first one's name),
    run it on the doubles ``data``; the ``n_out`` doubles it writes and the time per step [ns] it prints.

    The exports' files are read once, without following links, and must still hold what each
    export wrote (:meth:`CSource.texts`, ``ValueError`` otherwise); those bytes are compiled from
    a private temporary directory of this call, so a file changed meanwhile cannot enter the
    program and no header of the exports' directory can stand in for a system header.
    Safe to call from several threads.
    """
    sources = source if isinstance(source, list) else [source]
    source = sources[0]
    texts = [src.texts() for src in sources]
    cc = gcc()
    if cc is None:
        raise FileNotFoundError(f"running {source.name} needs gcc on the PATH to compile the exported code; install gcc")
    flags = (*CFLAGS, "-O2" if check_bool("optimize", optimize) else "-O0")
    objects = [_object(cc, src.name, h, c, flags) for src, (h, c) in zip(sources, texts)]
    with tempfile.TemporaryDirectory(prefix="pf-export-") as tmp:
        d = Path(tmp)
        for src, (h, _c) in zip(sources, texts):
            (d / f"{src.name}.h").write_bytes(h)
        (d / "driver.c").write_text(driver.replace("NAME", source.name))
        exe = d / "driver"
        cmd = [cc, *flags, str(d / "driver.c"), *map(str, objects), "-lm", "-o", str(exe)]
        _gcc(cmd, "the driver of " + source.name)
        np.ascontiguousarray(data, dtype=float).tofile(d / "in.bin")
        done = subprocess.run([str(exe), str(d / "in.bin"), str(d / "out.bin"), str(data.size), str(rounds)],
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"the compiled driver of {source.name} failed with exit code {done.returncode}")
        out = np.fromfile(d / "out.bin", dtype=float)
    if out.size != n_out:
        raise RuntimeError(f"the compiled driver of {source.name} wrote {out.size} numbers, expected {n_out}")
    return out, float(done.stdout)


def _gcc(cmd: list[str], what: str) -> None:
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"gcc failed to compile {what}:\n{done.stderr.strip()}")


_OBJ_LOCK = threading.Lock()
_OBJ_DIR: list[tempfile.TemporaryDirectory] = []


def _object(cc: str, name: str, header: bytes, body: bytes, flags: tuple[str, ...]) -> Path:
    """The object file of an export's texts, compiled once per process and content (the generated
    plant takes seconds at ``-O2``), in a private directory of this process.

    One thread compiles at a time (the first use in a process raced on the shared directory);
    each compile writes into a directory of its own and renames the object into place.
    """
    key = hashlib.sha256(hashlib.sha256(header).digest() + hashlib.sha256(body).digest()
                         + repr(flags).encode()).hexdigest()[:20]
    with _OBJ_LOCK:
        if not _OBJ_DIR:
            _OBJ_DIR.append(tempfile.TemporaryDirectory(prefix="pf-export-obj-"))
        obj = Path(_OBJ_DIR[0].name) / f"{name}-{key}.o"
        if not obj.exists():
            with tempfile.TemporaryDirectory(dir=_OBJ_DIR[0].name) as tmp:
                d = Path(tmp)
                (d / f"{name}.h").write_bytes(header)
                (d / f"{name}.c").write_bytes(body)
                _gcc([cc, *flags, "-c", str(d / f"{name}.c"), "-o", str(d / "part.o")], f"{name}.c")
                (d / "part.o").replace(obj)
    return obj


def evaluate(source: CSource, x: Any) -> np.ndarray:
    """The forces [N] of the exported model along ``x`` [m] from its CasADi Function, in Python.

    The same computation as the C code (:func:`run_c`), evaluated by CasADi's virtual machine:
    the two agree to rounding.

    Parameters
    ----------
    source : CSource
        What :func:`prefriction.export.c_source` wrote.
    x : array_like
        Positions [m]; the state is the virgin state at ``x[0]``.

    Returns
    -------
    numpy.ndarray
        The friction force [N] at each position.
    """
    source = _source(source)
    x = _positions(x, MAX_EVALUATE)
    fun = source.function
    w0 = virgin_state(source.model, float(x[0]))
    run = fun.mapaccum("stream", x.size)
    _w, F = run(ca.DM(w0), ca.DM(x).T)
    return np.asarray(F, dtype=float).ravel()

