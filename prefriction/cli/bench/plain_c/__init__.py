"""The plain-C reference of ``prefriction bench``: the unforced Dahl oscillator in C.

``dahl_rk54.c`` (in this folder) integrates the normalised unforced Dahl oscillator (gamma >= 1)
from reversal to reversal with the adaptive Runge-Kutta 5(4) of CasADi's ``erk`` integrator:
the same tableau, dense output, error norm and step control, on the same states (velocity and
log-gap) and scaling as the compact model of :func:`prefriction.simulate`, and Newton's method
on the dense output for each reversal. :func:`c_reversals` compiles it once per machine with
the C compiler CasADi's JIT uses (``$CC`` or ``gcc``, ``-O2``; the library is kept in the
compiled-code cache) and calls it through :mod:`ctypes`. It is the limit a compiled simulator
of the same algorithm can reach: ``prefriction bench`` prints the ratio of ``simulate`` to it
(``docs/bench.md#plain-c``).
"""

from __future__ import annotations

import ctypes
import functools
import os
import shutil
from pathlib import Path
from typing import Optional

import numpy as np

from prefriction.models import Oscillator
from prefriction.simulation import library_store as store
from prefriction.simulation.compiled import library
from prefriction.units import Scales

__all__ = ["SOURCE", "c_available", "c_reversals"]

SOURCE = Path(__file__).with_name("dahl_rk54.c")
"""The C source of the reference."""
_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def _compiler() -> Optional[str]:
    return shutil.which(os.environ.get("CC", "gcc"))


def c_available() -> bool:
    """True if a C compiler (``$CC`` or ``gcc``) is on the PATH."""
    return _compiler() is not None


@functools.lru_cache(maxsize=1)
def _library() -> ctypes.CDLL:
    """The compiled reference, built once per machine into the compiled-code cache (its checks apply)."""
    if _compiler() is None:
        raise RuntimeError("the plain-C reference needs a C compiler ($CC or gcc) on the PATH")
    dll, info = library("plain_c_dahl_rk54", SOURCE.read_text(), "the plain-C reference",
                        functools.partial(store.load_verified, symbols=("dahl_reversals",)),
                        "no plain-C row", cflags=("-O2", "-shared", "-fPIC"))
    if dll is None:
        raise RuntimeError(f"the plain-C reference could not be compiled: {info.reason}")
    dll.dahl_reversals.restype = ctypes.c_long
    dll.dahl_reversals.argtypes = [ctypes.c_double] * 4 + [ctypes.c_int] + [_DOUBLE_P] * 3
    return dll


def c_reversals(system: Oscillator, v0: float, n: int, rtol: float = 1e-8, F0: float = 0.0
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The first ``n`` reversals of an unforced Dahl oscillator (gamma >= 1) from the C reference.

    Parameters
    ----------
    system : Oscillator
        Unforced, with a :class:`prefriction.Dahl` model of gamma >= 1.
    v0 : float
        Initial velocity [m/s] (nonzero, or ``F0`` nonzero).
    n : int
        Number of reversals, >= 1.
    rtol : float, optional
        Tolerance; the integration runs at ``eps = 0.1 rtol``, as :func:`prefriction.simulate`.
    F0 : float, optional
        Initial friction force [N], ``|F0| < Fc``.

    Returns
    -------
    (t, x, F, steps)
        Reversal times [s], positions [m], forces [N] and the number of accepted steps.

    Raises
    ------
    ValueError
        For a forced system, a model other than Dahl with gamma >= 1, or ``n < 1``.
    RuntimeError
        Without a C compiler, or if a branch does not reverse within 1e6 steps.
    """
    from prefriction.models import Dahl

    model = system.friction
    if not isinstance(model, Dahl) or model.gamma < 1.0 or system.u is not None:
        raise ValueError(f"the plain-C reference runs the unforced Dahl oscillator with gamma >= 1, got {system!r}")
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    sc = Scales.of(system)
    t, x, F = (np.empty(n) for _ in range(3))
    ptr = [a.ctypes.data_as(_DOUBLE_P) for a in (t, x, F)]
    steps = _library().dahl_reversals(model.gamma, v0 / sc.v, F0 / sc.F, 0.1 * rtol, n, *ptr)
    if steps < 0:
        raise RuntimeError("the plain-C reference: a branch did not reverse within 1e6 steps")
    return t * sc.t, x * sc.x, F * sc.F, int(steps)
