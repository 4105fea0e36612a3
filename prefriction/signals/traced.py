"""An arbitrary Python function of time as a signal: :class:`Traced` (traced into CasADi)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Hashable
from typing import Any, Callable

import casadi as ca
import numpy as np

from prefriction.signals._checks import time_end
from prefriction.signals._ops import CasadiOps, MathOps
from prefriction.signals.base import NoParams, Signal

__all__ = ["Traced"]


class Traced(NoParams):
    """Arbitrary Python function of time, traced into CasADi.

    Unlike the parametric kinds, the function *is* the structure: the key is
    ``("Traced", fun)``, so every distinct function object compiles its own code (once per
    function; a new ``lambda`` each run compiles again). Prefer :class:`Constant`,
    :class:`Step`, :class:`Ramp`, :class:`Sine`, :class:`Chirp` or :class:`Samples` (and their
    sums), which compile once per kind and take their numbers at run time.

    The function must trace: on a ``casadi.SX`` symbol it must return a scalar equal to its
    value on floats (use arithmetic, numpy ufuncs such as ``np.sin``, ``casadi.if_else``; no
    ``math.*`` functions and no ``if``/``else`` on ``t``). No :meth:`breaks` are known.

    Parameters
    ----------
    fun : callable
        ``fun(t)`` with time ``t`` [s], hashable, returning the value [signal units].
    name : str, optional
        Name of the signal in error messages, default ``"fun"``.

    Raises
    ------
    TypeError
        If ``fun`` is not callable, not hashable, or does not trace into CasADi.
    """

    __slots__ = ("fun", "_f")
    _CHECK_TIMES = (0.0, 0.3183, 1.7)

    def __init__(self, fun: Callable[[Any], Any], *, name: str = "fun") -> None:
        if not callable(fun) or isinstance(fun, Signal):
            raise TypeError(f"{name} must be a callable of time t [s] (not a Signal), got {fun!r}")
        try:
            hash(fun)
        except TypeError:
            raise TypeError(f"{name} must be hashable (it is the key of the compiled code), got {fun!r}") from None
        advice = (
            "use arithmetic, numpy ufuncs such as np.sin, or casadi.if_else; no math.* functions and no "
            "if/else on t; or use the parametric classes of prefriction.signals (Sine, Step, Ramp, Chirp, "
            "Constant, and their sums) or Samples (t, values)"
        )
        t = ca.SX.sym("t")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            try:
                value = fun(t)
                value = value if isinstance(value, ca.SX) else ca.SX(value)
            except Exception as exc:  # any failure of user code on a symbol: not traceable
                raise TypeError(
                    f"{name} must accept a CasADi symbol for time t, got {fun!r}: calling it on one failed with "
                    f"{type(exc).__name__}: {str(exc).rstrip('.')}. To fix: {advice}."
                ) from None
        if value.numel() != 1:
            raise TypeError(f"{name} must return a scalar, got shape {value.shape} on a CasADi symbol from {fun!r}")
        f = ca.Function("traced", [t], [value])
        for t0 in self._CHECK_TIMES:
            traced = float(f(t0))
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", FutureWarning)
                    direct = np.asarray(fun(t0), dtype=float).reshape(-1)
            except Exception as exc:  # user code failing on a float
                raise TypeError(f"{name} failed on the float time t = {t0}: {type(exc).__name__}: {exc}") from None
            if direct.size != 1:
                raise TypeError(f"{name} must return a scalar, got shape {direct.shape} at t = {t0}")
            d = float(direct[0])
            same = (math.isnan(traced) and math.isnan(d)) or abs(traced - d) <= 1e-12 * max(1.0, abs(d))
            if not same:
                raise TypeError(
                    f"{name} does not trace into CasADi, got {fun!r}: on a symbol it gives {traced!r} at t = {t0}, called "
                    f"directly {d!r}. To fix: {advice}."
                )
        self._set(fun=fun, _f=f)

    @property
    def key(self) -> Hashable:
        """``("Traced", fun)``: each function object is its own structure."""
        return ("Traced", self.fun)

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        if isinstance(t, ca.SX):
            value = self.fun(t)
            return value if isinstance(value, ca.SX) else ca.SX(value)
        if ops is CasadiOps:
            return self._f(t)
        if ops is MathOps:
            return float(self._f(t))
        flat = t.reshape(1, -1)
        return np.asarray(self._f(flat), dtype=float).reshape(t.shape) if flat.size else np.zeros(t.shape)

    def bound(self, t_end: float) -> float:
        """Estimate of the magnitude over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`): the
        largest of 1025 evenly spaced values (NaN ignored)."""
        values = np.abs(self(np.linspace(0.0, time_end(t_end), 1025)))
        return float(np.max(values, initial=0.0, where=~np.isnan(values)))

    def __repr__(self) -> str:
        return f"Traced({getattr(self.fun, '__qualname__', repr(self.fun))})"
