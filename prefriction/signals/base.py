"""The base class :class:`Signal` (structure, numbers, expression, ``+``) and the base of the
analytic kinds, whose numbers are named float fields."""

from __future__ import annotations

import math
import warnings
from abc import ABC, abstractmethod
from collections.abc import Hashable
from typing import Any, Optional, Union

import casadi
import numpy as np

from prefriction._validation import check_real_array
from prefriction.signals._checks import is_real
from prefriction.signals._ops import CASADI_TYPES, CasadiOps, MathOps, NumpyOps, vector

def _rebuild(cls: type, state: dict) -> "Signal":
    """Inverse of :meth:`Signal.__reduce__`."""
    obj = cls.__new__(cls)
    obj._set(**state)
    return obj


class Signal(ABC):
    """Scalar signal of time: structure (:attr:`key`) compiled once, numbers given at run time.

    Subclasses are immutable. Signals add with ``+`` (to a signal or a plain number), giving a
    :class:`Sum`; ``sum([...])`` works too.
    """

    __slots__ = ()
    __array_ufunc__ = None  # numpy scalars defer to Signal.__radd__

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")

    def _set(self, **fields: Any) -> None:
        for name, value in fields.items():
            object.__setattr__(self, name, value)

    def __reduce__(self) -> tuple:
        """Pickle by the slot values (process pools and dask ship signals to workers)."""
        names = [n for cls in type(self).__mro__ for n in getattr(cls, "__slots__", ())]
        return (_rebuild, (type(self), {n: getattr(self, n) for n in names if hasattr(self, n)}))

    # --- structure ---------------------------------------------------------------------------

    @property
    def key(self) -> Hashable:
        """Structure of the signal: what changes the generated code, never its numbers."""
        return (type(self).__name__,)

    @property
    @abstractmethod
    def n_params(self) -> int:
        """Number of run-time parameters (fixed per :attr:`key`)."""

    @property
    def n_piece(self) -> int:
        """Number of per-interval numbers of :meth:`piece` (0 for analytic signals)."""
        return 0

    # --- numbers -----------------------------------------------------------------------------

    @abstractmethod
    def params(self) -> np.ndarray:
        """Run-time parameters.

        Returns
        -------
        numpy.ndarray
            The numbers of this signal in SI units, length :attr:`n_params`.
        """

    def linear_piece(self, ta: float, tb: float) -> Optional[tuple[float, float]]:
        """``(value at ta, slope)`` on ``[ta, tb]`` if the signal is piecewise linear there
        (no :meth:`breaks` strictly inside), else ``None``.

        Piecewise-linear kinds (:class:`Constant`, :class:`Step`, :class:`Ramp`,
        :class:`Samples` and their sums) share one compiled plant: the simulator passes their
        pieces per interval (:func:`compiled_form`).
        """
        return None

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Per-interval numbers for a time interval inside which the signal is smooth.

        Parameters
        ----------
        ta, tb : float
            Start and end [s] of the interval, ``ta <= tb``, with no :meth:`breaks` strictly inside.

        Returns
        -------
        numpy.ndarray
            Length :attr:`n_piece` (empty for analytic signals).
        """
        return np.zeros(0)

    # --- expression --------------------------------------------------------------------------

    def expr(self, t: Any, theta: Any, piece: Any = ()) -> Any:
        """Value from the structure only, for CasADi symbols or numbers.

        Uses none of this instance's numbers, so one expression built on symbols serves every
        signal with the same :attr:`key`.

        Parameters
        ----------
        t : float, numpy.ndarray or casadi.SX
            Time [s].
        theta : array_like or casadi.SX
            Parameters, length :attr:`n_params` (as :meth:`params`).
        piece : array_like or casadi.SX, optional
            Per-interval numbers, length :attr:`n_piece` (as :meth:`piece`).

        Returns
        -------
        float, numpy.ndarray or casadi.SX
            The value: casadi if any argument is a casadi object (then ``t`` must be scalar),
            otherwise numpy with the shape of ``t`` (a float for a scalar ``t``).
        """
        casadi = any(isinstance(x, CASADI_TYPES) for x in (t, theta, piece))
        theta = vector(theta, self.n_params, "theta", casadi)
        piece = vector(piece, self.n_piece, "piece", casadi)
        if casadi:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", FutureWarning)
                return self._expr(t, theta, piece, CasadiOps)
        t = np.asarray(t, dtype=float)
        value = np.asarray(self._expr(t, theta, piece, NumpyOps), dtype=float)
        value = np.broadcast_to(value, t.shape).copy()
        return float(value) if value.ndim == 0 else value

    @abstractmethod
    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        """Value at ``t`` with validated ``theta``, ``piece`` and the operations ``ops``."""

    # --- numeric -----------------------------------------------------------------------------

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value, vectorised.

        Parameters
        ----------
        t : float or array_like
            Time(s) [s].

        Returns
        -------
        float or numpy.ndarray
            The value(s), shaped like ``t`` (a float for a scalar ``t``).
        """
        if isinstance(t, float) and self.n_piece == 0 and math.isfinite(t):  # one time: no numpy (~30 us)
            return float(self._expr(t, self.params().tolist(), (), MathOps))
        return self.expr(check_real_array("t", t, "s"), self.params())

    def velocity(self, t: Any) -> Union[float, np.ndarray]:
        """Time derivative of the signal [signal units / s] at the time(s) ``t`` [s], vectorised.

        Exact: CasADi's derivative of :meth:`expr` for the analytic kinds, the slope of the
        current line for piecewise-linear ones (:meth:`linear_piece`). At a kink (a break, the
        end of a ramp) the slope just after ``t``; a jump (:class:`Step`, :class:`ZeroOrderHold`)
        counts 0. A position reference's velocity [m/s], e.g. for a compensator or exported code.

        Parameters
        ----------
        t : float or array_like
            Time(s) [s].

        Returns
        -------
        float or numpy.ndarray
            The derivative(s), shaped like ``t`` (a float for a scalar ``t``).
        """
        tt = np.asarray(check_real_array("t", t, "s"), dtype=float)
        breaks = self.breaks()
        after = np.append(breaks, np.inf)[np.searchsorted(breaks, tt, side="right")]  # next break after t
        value = np.full(tt.shape, np.nan)
        for i, ti in np.ndenumerate(tt):  # piecewise-linear kinds: the slope of the line after ti
            piece = self.linear_piece(float(ti), float(after[i]) if np.isfinite(after[i]) else float(ti) + 1.0)
            if piece is None:
                break
            value[i] = piece[1]
        rest = np.isnan(value)
        if rest.any() and self.n_piece > 0:  # a kind with per-interval numbers is piecewise linear
            value[rest] = 0.0
        elif rest.any():  # analytic: CasADi's derivative of the expression
            ts, th = casadi.SX.sym("t"), casadi.SX.sym("theta", self.n_params)
            d = casadi.Function("velocity", [ts, th], [casadi.jacobian(self.expr(ts, th), ts)])
            flat = tt[rest]
            value[rest] = np.array(d.map(flat.size)(flat.reshape(1, -1), self.params()), dtype=float).ravel()
        return float(value) if value.ndim == 0 else value

    def breaks(self) -> np.ndarray:
        """Times at which the signal or its first derivative jumps.

        Returns
        -------
        numpy.ndarray
            Sorted times [s]; integration must be split there.
        """
        return np.zeros(0)

    @abstractmethod
    def bound(self, t_end: float) -> float:
        """Upper bound (or good estimate) of the magnitude of the signal.

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            Bound of ``max |value|`` over ``[0, t_end]`` [signal units].
        """

    # --- algebra -----------------------------------------------------------------------------

    _sum: Any = None
    """:class:`Sum`, set by :mod:`prefriction.signals.algebra` (the kinds derive from Signal)."""
    _constant: Any = None
    """:class:`Constant`, set by :mod:`prefriction.signals.piecewise`."""

    def __add__(self, other: Any) -> "Signal":
        if isinstance(other, Signal):
            return Signal._sum(self, other)
        if is_real(other):
            return Signal._sum(self, Signal._constant(other))
        return NotImplemented

    def __radd__(self, other: Any) -> "Signal":
        if type(other) is int and other == 0:  # start value of sum([...])
            return self
        if is_real(other):
            return Signal._sum(Signal._constant(other), self)
        return NotImplemented

    def _fields(self) -> dict:
        return {}

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._fields().items())
        return f"{type(self).__name__}({args})"


class Analytic(Signal):
    """A signal given by named float fields, in the order of :meth:`params`."""

    __slots__ = ()
    _names: tuple = ()

    @property
    def n_params(self) -> int:
        """Number of run-time parameters."""
        return len(self._names)

    def params(self) -> np.ndarray:
        """Run-time parameters.

        Returns
        -------
        numpy.ndarray
            The numbers of the signal in SI units, in the order of the constructor.
        """
        return np.array([getattr(self, n) for n in self._names], dtype=float)

    def _fields(self) -> dict:
        return {n: getattr(self, n) for n in self._names}


class NoParams(Signal):
    """A signal without run-time parameters: its numbers are per-interval (:meth:`piece`) or
    compiled into its structure."""

    __slots__ = ()

    @property
    def n_params(self) -> int:
        """No run-time parameters."""
        return 0

    def params(self) -> np.ndarray:
        """Run-time parameters (none).

        Returns
        -------
        numpy.ndarray
            Empty array.
        """
        return np.zeros(0)


class LinearPieces(NoParams):
    """A signal compiled as one line per interval: ``a + b (t - tl)`` from the per-interval
    numbers ``(tl, a, b)`` of :meth:`piece`; no run-time parameters."""

    __slots__ = ()

    @property
    def n_piece(self) -> int:
        """Three per-interval numbers ``(tl, a, b)``."""
        return 3

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return piece[1] + piece[2] * (t - piece[0])
