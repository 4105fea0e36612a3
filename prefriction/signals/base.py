"""The base class :class:`Signal` (structure, numbers, expression, ``+``) and the base of the
analytic kinds, whose numbers are named float fields."""

from __future__ import annotations

import warnings
from abc import ABC, abstractmethod
from collections.abc import Hashable
from typing import Any, Optional

import numpy as np

from prefriction.signals._checks import is_real
from prefriction.signals._ops import CASADI_TYPES, CasadiOps, NumpyOps, vector
from prefriction.signals.values import SignalValues

def _rebuild(cls: type, state: dict) -> "Signal":
    """Inverse of :meth:`Signal.__reduce__`."""
    obj = cls.__new__(cls)
    obj._set(**state)
    return obj


class Signal(SignalValues, ABC):
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
