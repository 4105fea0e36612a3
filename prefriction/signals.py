"""Parametric input signals: structure compiled once, numbers given at run time.

A signal (an input force [N], a reference position [m], ...) is split in two parts:

- its *structure*, :attr:`Signal.key`: the kind of signal (``("Sine",)``, ``("Step",)``,
  ``("Sum", ("Sine",), ("Step",))``, ...). Only the structure shapes the CasADi code that
  :meth:`Signal.expr` generates, so the simulator compiles one function per key;
- its *numbers*, :meth:`Signal.params` (amplitudes, frequencies, switching times, ...) and, for
  sampled signals, the per-interval numbers :meth:`Signal.piece`. They are inputs of the compiled
  function, so each kind compiles once and takes its numbers at run time: two ``Sine`` signals
  with different amplitudes share one compiled function.

Kinds: :class:`Constant`, :class:`Step`, :class:`Ramp`, :class:`Sine`, :class:`Chirp`,
:class:`Samples` (piecewise linear data), :class:`Traced` (an arbitrary traceable Python
function; compiled once *per function object*) and :class:`Sum` (made with ``+``).
:func:`as_signal` converts the user-facing forms (number, ``(t, values)``, callable) to signals.

Example
-------
>>> import casadi as ca
>>> u = Sine(amplitude=0.5, frequency=2.0) + Step(time=1.0, before=0.0, after=0.1)
>>> t, theta = ca.SX.sym("t"), ca.SX.sym("theta", u.n_params)
>>> f = ca.Function("u", [t, theta], [u.expr(t, theta)])      # compiled once per key
>>> v = Sine(amplitude=2.0, frequency=0.1) + Step(time=0.0, before=1.0, after=-1.0)
>>> v.key == u.key and abs(float(f(0.3, v.params())) - v(0.3)) < 1e-12
True
"""

from __future__ import annotations

import math
import warnings
from abc import ABC, abstractmethod
from collections.abc import Hashable
from numbers import Real
from typing import Any, Callable, Optional, Union

import casadi as ca
import numpy as np

from prefriction._validation import check_real_array

__all__ = [
    "compiled_form",
    "Chirp",
    "Constant",
    "Ramp",
    "Samples",
    "Signal",
    "Sine",
    "Step",
    "Sum",
    "Traced",
    "as_signal",
    "MAX_SAMPLES",
]

#: Largest number of samples accepted by :class:`Samples`.
MAX_SAMPLES = 10_000_000

_UNIT = "signal units"


# --------------------------------------------------------------------------------------------
# validation helpers


def _is_real(value: Any) -> bool:
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (Real, np.floating, np.integer))


def _number(name: str, value: Any, unit: str, rule: str = "", ok: Callable[[float], bool] = lambda v: True) -> float:
    """``value`` as a finite float satisfying ``ok``; messages name ``name``, the value and ``rule``."""
    allowed = f"a finite real number{(' ' + rule) if rule else ''} [{unit}]"
    if not _is_real(value):
        raise TypeError(f"{name} must be {allowed}, got {value!r} of type {type(value).__name__}")
    v = float(value)
    if not (math.isfinite(v) and ok(v)):
        raise ValueError(f"{name} must be {allowed}, got {v!r}")
    return v


def _time_end(t_end: Any) -> float:
    return _number("t_end", t_end, "s", ">= 0", lambda v: v >= 0.0)


def _sample_array(name: str, values: Any, unit: str) -> np.ndarray:
    """A finite 1-D float array (copy, read-only); messages name ``name``."""
    if isinstance(values, (str, bytes)) or values is None:
        raise TypeError(f"{name} must be a 1-D array of finite real numbers [{unit}], got {values!r}")
    try:
        arr = np.asarray(values)
    except Exception as exc:  # ragged lists and the like
        raise TypeError(f"{name} must be a 1-D array of finite real numbers [{unit}], got {exc}") from None
    if arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must be a 1-D array of finite real numbers [{unit}], got an array of dtype {arr.dtype}"
        )
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array [{unit}], got shape {arr.shape}")
    if arr.size > MAX_SAMPLES:
        raise ValueError(f"{name} must have at most {MAX_SAMPLES} samples, got {arr.size}")
    arr = np.array(arr, dtype=float)
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(
            f"{name} must be finite (every entry) [{unit}], got {arr[bad][0]!r} at index {int(np.argmax(bad))}"
        )
    arr.setflags(write=False)
    return arr


# --------------------------------------------------------------------------------------------
# numeric / casadi dispatch


class _NumpyOps:
    sin = staticmethod(np.sin)
    where = staticmethod(np.where)
    fmax = staticmethod(np.maximum)
    fmin = staticmethod(np.minimum)


class _MathOps:  # scalar floats: the fast path of Signal.__call__ (loops evaluate per sample)
    sin = staticmethod(math.sin)
    fmax = staticmethod(max)
    fmin = staticmethod(min)

    @staticmethod
    def where(c: bool, a: float, b: float) -> float:
        return a if c else b


class _CasadiOps:
    sin = staticmethod(ca.sin)
    where = staticmethod(ca.if_else)
    fmax = staticmethod(ca.fmax)
    fmin = staticmethod(ca.fmin)


_CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def _vector(x: Any, n: int, name: str, casadi: bool) -> Any:
    """Parameter or piece vector ``x`` of length ``n``, as casadi (``casadi=True``) or numpy."""
    if casadi:
        x = x if isinstance(x, _CASADI_TYPES) else ca.DM(np.asarray(x, dtype=float).reshape(-1))
        size = x.numel()
    else:
        x = np.asarray(x, dtype=float).reshape(-1)
        size = x.size
    if size != n:
        raise ValueError(f"{name} must have length {n}, got {size}")
    return x


# --------------------------------------------------------------------------------------------
# base class


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
        casadi = any(isinstance(x, _CASADI_TYPES) for x in (t, theta, piece))
        theta = _vector(theta, self.n_params, "theta", casadi)
        piece = _vector(piece, self.n_piece, "piece", casadi)
        if casadi:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", FutureWarning)
                return self._expr(t, theta, piece, _CasadiOps)
        t = np.asarray(t, dtype=float)
        value = np.asarray(self._expr(t, theta, piece, _NumpyOps), dtype=float)
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
            return float(self._expr(t, self.params().tolist(), (), _MathOps))
        return self.expr(check_real_array("t", t, "s"), self.params())

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

    def __add__(self, other: Any) -> "Signal":
        if isinstance(other, Signal):
            return Sum(self, other)
        if _is_real(other):
            return Sum(self, Constant(other))
        return NotImplemented

    def __radd__(self, other: Any) -> "Signal":
        if type(other) is int and other == 0:  # start value of sum([...])
            return self
        if _is_real(other):
            return Sum(Constant(other), self)
        return NotImplemented

    def _fields(self) -> dict:
        return {}

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._fields().items())
        return f"{type(self).__name__}({args})"


class _Analytic(Signal):
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


# --------------------------------------------------------------------------------------------
# analytic kinds


class Constant(_Analytic):
    """Constant signal.

    Parameters
    ----------
    value : float
        The value [signal units], finite.
    """

    __slots__ = ("value",)
    _names = ("value",)

    def __init__(self, value: float) -> None:
        self._set(value=_number("value", value, _UNIT))

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[0]

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(value, 0)``: a constant is piecewise linear."""
        return self.value, 0.0

    def bound(self, t_end: float) -> float:
        """Magnitude of the value.

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            ``|value|`` [signal units].
        """
        _time_end(t_end)
        return abs(self.value)


class Step(_Analytic):
    """Step: ``before`` for ``t < time``, ``after`` for ``t >= time``.

    Parameters
    ----------
    time : float
        Switching time [s], ``>= 0``.
    before : float
        Value before the step [signal units].
    after : float
        Value from the step on [signal units].
    """

    __slots__ = ("time", "before", "after")
    _names = ("time", "before", "after")

    def __init__(self, time: float, before: float, after: float) -> None:
        self._set(
            time=_number("time", time, "s", ">= 0", lambda v: v >= 0.0),
            before=_number("before", before, _UNIT),
            after=_number("after", after, _UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return ops.where(t >= theta[0], theta[2], theta[1])

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(before or after, 0)`` by the midpoint of ``[ta, tb]``."""
        return (self.after if 0.5 * (ta + tb) >= self.time else self.before), 0.0

    def breaks(self) -> np.ndarray:
        """Switching time.

        Returns
        -------
        numpy.ndarray
            ``[time]`` [s].
        """
        return np.array([self.time])

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]``.

        Parameters
        ----------
        t_end : float
            End [s] of the time range.

        Returns
        -------
        float
            ``max(|before|, |after|)``, or ``|before|`` if the step comes after ``t_end``.
        """
        if _time_end(t_end) < self.time:
            return abs(self.before)
        return max(abs(self.before), abs(self.after))


class Ramp(_Analytic):
    """Ramp: ``offset`` for ``t < time``, ``offset + slope (t - time)`` afterwards.

    Parameters
    ----------
    time : float
        Start of the ramp [s], ``>= 0``.
    slope : float
        Slope [signal units / s].
    offset : float, optional
        Value before the ramp [signal units], default 0.
    """

    __slots__ = ("time", "slope", "offset")
    _names = ("time", "slope", "offset")

    def __init__(self, time: float, slope: float, offset: float = 0.0) -> None:
        self._set(
            time=_number("time", time, "s", ">= 0", lambda v: v >= 0.0),
            slope=_number("slope", slope, _UNIT + " / s"),
            offset=_number("offset", offset, _UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[2] + theta[1] * ops.fmax(t - theta[0], 0.0)

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(offset + slope (ta - time), slope)`` after ``time``, ``(offset, 0)`` before."""
        if 0.5 * (ta + tb) > self.time:
            return self.offset + self.slope * (ta - self.time), self.slope
        return self.offset, 0.0

    def breaks(self) -> np.ndarray:
        """Start of the ramp.

        Returns
        -------
        numpy.ndarray
            ``[time]`` [s].
        """
        return np.array([self.time])

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` (exact: the value is monotonic).

        Parameters
        ----------
        t_end : float
            End [s] of the time range.

        Returns
        -------
        float
            ``max(|offset|, |offset + slope max(t_end - time, 0)|)`` [signal units].
        """
        end = self.offset + self.slope * max(_time_end(t_end) - self.time, 0.0)
        return max(abs(self.offset), abs(end))


class Sine(_Analytic):
    """Sinusoid ``offset + amplitude sin(2 pi frequency t + phase)``.

    Parameters
    ----------
    amplitude : float
        Amplitude [signal units].
    frequency : float
        Frequency [Hz], ``> 0``.
    phase : float, optional
        Phase at ``t = 0`` [rad], default 0.
    offset : float, optional
        Mean value [signal units], default 0.
    """

    __slots__ = ("amplitude", "frequency", "phase", "offset")
    _names = ("amplitude", "frequency", "phase", "offset")

    def __init__(self, amplitude: float, frequency: float, phase: float = 0.0, offset: float = 0.0) -> None:
        self._set(
            amplitude=_number("amplitude", amplitude, _UNIT),
            frequency=_number("frequency", frequency, "Hz", "> 0", lambda v: v > 0.0),
            phase=_number("phase", phase, "rad"),
            offset=_number("offset", offset, _UNIT),
        )

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return theta[3] + theta[0] * ops.sin(2.0 * math.pi * theta[1] * t + theta[2])

    def bound(self, t_end: float) -> float:
        """Bound of the magnitude.

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            ``|offset| + |amplitude|`` [signal units].
        """
        _time_end(t_end)
        return abs(self.offset) + abs(self.amplitude)


class Chirp(_Analytic):
    """Linear-frequency sweep from ``f0`` to ``f1`` over ``[0, duration]``, then a sine at ``f1``.

    For ``t <= duration`` the value is ``amplitude sin(2 pi (f0 t + (f1 - f0) t^2 / (2 duration)))``;
    afterwards the sine continues at ``f1`` with a continuous phase.

    Parameters
    ----------
    amplitude : float
        Amplitude [signal units].
    f0 : float
        Frequency at ``t = 0`` [Hz], ``>= 0``.
    f1 : float
        Frequency from ``t = duration`` on [Hz], ``>= 0``; ``f0`` and ``f1`` not both 0.
    duration : float
        Length of the sweep [s], ``> 0``.
    """

    __slots__ = ("amplitude", "f0", "f1", "duration")
    _names = ("amplitude", "f0", "f1", "duration")

    def __init__(self, amplitude: float, f0: float, f1: float, duration: float) -> None:
        self._set(
            amplitude=_number("amplitude", amplitude, _UNIT),
            f0=_number("f0", f0, "Hz", ">= 0", lambda v: v >= 0.0),
            f1=_number("f1", f1, "Hz", ">= 0", lambda v: v >= 0.0),
            duration=_number("duration", duration, "s", "> 0", lambda v: v > 0.0),
        )
        if self.f0 == 0.0 and self.f1 == 0.0:
            raise ValueError(f"f0 and f1 must not both be 0 [Hz] (allowed: f0, f1 >= 0, f0 + f1 > 0), "
                             f"got f0={self.f0!r}, f1={self.f1!r}")

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        a, f0, f1, d = theta[0], theta[1], theta[2], theta[3]
        tc = ops.fmin(t, d)  # time within the sweep
        cycles = f0 * tc + (f1 - f0) * tc * tc / (2.0 * d) + f1 * ops.fmax(t - d, 0.0)
        return a * ops.sin(2.0 * math.pi * cycles)

    def breaks(self) -> np.ndarray:
        """End of the sweep (the chirp rate jumps there).

        Returns
        -------
        numpy.ndarray
            ``[duration]`` [s].
        """
        return np.array([self.duration])

    def bound(self, t_end: float) -> float:
        """Bound of the magnitude.

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            ``|amplitude|`` [signal units].
        """
        _time_end(t_end)
        return abs(self.amplitude)


# --------------------------------------------------------------------------------------------
# data and functions


class Samples(Signal):
    """Piecewise-linear signal through samples, held constant outside them (as ``numpy.interp``).

    The samples are not compiled: :meth:`piece` hands the simulator the linear piece of each
    interval between sample times, so all sampled signals share the key ``("Samples",)``.

    Parameters
    ----------
    t : array_like
        Sample times [s]: 1-D, finite, strictly increasing, 2 to :data:`MAX_SAMPLES` entries.
    u : array_like
        Sample values [signal units]: 1-D, finite, same length as ``t``.
    name : str, optional
        Name of the signal in error messages (e.g. ``"reference"``); default: none.
    unit : str, optional
        Unit of the values in error messages, default ``"signal units"``.
    """

    __slots__ = ("_t", "_u")

    def __init__(self, t: Any, u: Any, *, name: Optional[str] = None, unit: str = _UNIT) -> None:
        nt, nu = (f"{name} sample times t", f"{name} sample values") if name else ("t", "u")
        ts = _sample_array(nt, t, "s")
        us = _sample_array(nu, u, unit)
        if ts.size < 2:
            raise ValueError(f"{nt} must have at least 2 samples, got {ts.size}")
        if us.shape != ts.shape:
            raise ValueError(f"{nu} must have the same length as {nt} ({ts.size}), got {us.size}")
        steps = np.diff(ts)
        if not np.all(steps > 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise ValueError(
                f"{nt} must be strictly increasing, got {nt}[{k}] = {float(ts[k])!r} >= {nt}[{k + 1}] = {float(ts[k + 1])!r}"
            )
        self._set(_t=ts, _u=us)

    @property
    def t(self) -> np.ndarray:
        """Sample times [s] (read-only)."""
        return self._t

    @property
    def u(self) -> np.ndarray:
        """Sample values [signal units] (read-only)."""
        return self._u

    @property
    def n_params(self) -> int:
        """No run-time parameters: the numbers come per interval from :meth:`piece`."""
        return 0

    @property
    def n_piece(self) -> int:
        """Three per-interval numbers ``(tl, a, b)``."""
        return 3

    def params(self) -> np.ndarray:
        """Run-time parameters (none).

        Returns
        -------
        numpy.ndarray
            Empty array.
        """
        return np.zeros(0)

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """Value at ``ta`` and slope of the linear piece of :meth:`piece`."""
        tl, a, b = self.piece(ta, tb)
        return float(a + b * (ta - tl)), float(b)

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Linear piece ``a + b (t - tl)`` valid on ``[ta, tb]``.

        The piece is the one containing the midpoint of ``[ta, tb]``, so that ``ta`` may be a
        sample time exactly; outside the sample range the slope is 0.

        Parameters
        ----------
        ta, tb : float
            Start and end [s] of the interval, ``ta <= tb``, with no sample time strictly inside.

        Returns
        -------
        numpy.ndarray
            ``(tl [s], a [signal units], b [signal units / s])``.
        """
        ta = _number("ta", ta, "s")
        tb = _number("tb", tb, "s", f">= ta = {ta!r}", lambda v: v >= ta)
        ts, us = self._t, self._u
        mid = 0.5 * (ta + tb)
        if mid <= ts[0]:
            return np.array([ta, us[0], 0.0])
        if mid >= ts[-1]:
            return np.array([ta, us[-1], 0.0])
        k = int(np.clip(np.searchsorted(ts, mid, side="right") - 1, 0, ts.size - 2))
        slope = (us[k + 1] - us[k]) / (ts[k + 1] - ts[k])
        return np.array([ts[k], us[k], slope])

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return piece[1] + piece[2] * (t - piece[0])

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value, linear between samples and held outside them.

        Parameters
        ----------
        t : float or array_like
            Time(s) [s].

        Returns
        -------
        float or numpy.ndarray
            ``numpy.interp(t, self.t, self.u)``.
        """
        value = np.interp(check_real_array("t", t, "s"), self._t, self._u)
        return float(value) if np.ndim(value) == 0 else value

    def breaks(self) -> np.ndarray:
        """Sample times, where the slope jumps.

        Returns
        -------
        numpy.ndarray
            Copy of :attr:`t` [s].
        """
        return self._t.copy()

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` (exact).

        Parameters
        ----------
        t_end : float
            End [s] of the time range.

        Returns
        -------
        float
            ``max |value|`` over ``[0, t_end]`` [signal units].
        """
        t_end = _time_end(t_end)
        inside = (self._t >= 0.0) & (self._t <= t_end)
        ends = np.abs(np.interp([0.0, t_end], self._t, self._u))
        return float(max(ends.max(), np.abs(self._u[inside]).max(initial=0.0)))

    def __repr__(self) -> str:
        t0, t1, lo, hi = (float(x) for x in (self._t[0], self._t[-1], self._u.min(), self._u.max()))
        return f"Samples(n={self._t.size}, t=[{t0!r} .. {t1!r}], u=[{lo!r} .. {hi!r}])"


class Traced(Signal):
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

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        if isinstance(t, ca.SX):
            value = self.fun(t)
            return value if isinstance(value, ca.SX) else ca.SX(value)
        if ops is _CasadiOps:
            return self._f(t)
        if ops is _MathOps:
            return float(self._f(t))
        flat = t.reshape(1, -1)
        return np.asarray(self._f(flat), dtype=float).reshape(t.shape) if flat.size else np.zeros(t.shape)

    def bound(self, t_end: float) -> float:
        """Estimate of the magnitude from 1025 evenly spaced values (NaN ignored).

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            ``max |value|`` over the sample points [signal units].
        """
        values = np.abs(self(np.linspace(0.0, _time_end(t_end), 1025)))
        return float(np.max(values, initial=0.0, where=~np.isnan(values)))

    def __repr__(self) -> str:
        return f"Traced({getattr(self.fun, '__qualname__', repr(self.fun))})"


# --------------------------------------------------------------------------------------------
# sums


class Sum(Signal):
    """Sum of signals; nested sums are flattened. Usually made with ``+``.

    Parameters
    ----------
    *terms : Signal
        At least one signal.
    """

    __slots__ = ("terms",)

    def __init__(self, *terms: Signal) -> None:
        if not terms:
            raise ValueError("terms must hold at least one Signal, got none")
        flat = []
        for term in terms:
            if not isinstance(term, Signal):
                raise TypeError(f"terms must be Signals, got {term!r} of type {type(term).__name__}")
            flat.extend(term.terms if isinstance(term, Sum) else (term,))
        self._set(terms=tuple(flat))

    @property
    def key(self) -> Hashable:
        """``("Sum", key1, key2, ...)``."""
        return ("Sum", *(term.key for term in self.terms))

    @property
    def n_params(self) -> int:
        """Total number of run-time parameters of the terms."""
        return sum(term.n_params for term in self.terms)

    @property
    def n_piece(self) -> int:
        """Total number of per-interval numbers of the terms."""
        return sum(term.n_piece for term in self.terms)

    def params(self) -> np.ndarray:
        """Run-time parameters of the terms, concatenated.

        Returns
        -------
        numpy.ndarray
            Length :attr:`n_params`.
        """
        return np.concatenate([term.params() for term in self.terms])

    def linear_piece(self, ta: float, tb: float) -> Optional[tuple[float, float]]:
        """Sum of the terms' pieces if every term is piecewise linear, else ``None``."""
        a = b = 0.0
        for term in self.terms:
            lp = term.linear_piece(ta, tb)
            if lp is None:
                return None
            a, b = a + lp[0], b + lp[1]
        return a, b

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Per-interval numbers of the terms, concatenated.

        Parameters
        ----------
        ta, tb : float
            Start and end [s] of the interval, with no :meth:`breaks` strictly inside.

        Returns
        -------
        numpy.ndarray
            Length :attr:`n_piece`.
        """
        return np.concatenate([np.zeros(0)] + [term.piece(ta, tb) for term in self.terms])

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        total, i, j = 0.0, 0, 0
        for term in self.terms:
            n, m = term.n_params, term.n_piece
            total = total + term._expr(t, theta[i:i + n], piece[j:j + m], ops)
            i, j = i + n, j + m
        return total

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value: the sum of the terms' values.

        Parameters
        ----------
        t : float or array_like
            Time(s) [s].

        Returns
        -------
        float or numpy.ndarray
            Shaped like ``t`` (a float for a scalar ``t``).
        """
        value = sum(np.asarray(term(t), dtype=float) for term in self.terms)
        return float(value) if np.ndim(value) == 0 else value

    def breaks(self) -> np.ndarray:
        """Union of the terms' breaks.

        Returns
        -------
        numpy.ndarray
            Sorted unique times [s].
        """
        return np.unique(np.concatenate([np.zeros(0)] + [term.breaks() for term in self.terms]))

    def bound(self, t_end: float) -> float:
        """Sum of the terms' bounds.

        Parameters
        ----------
        t_end : float
            End [s] of the time range ``[0, t_end]``.

        Returns
        -------
        float
            Bound [signal units].
        """
        return float(sum(term.bound(t_end) for term in self.terms))

    def __repr__(self) -> str:
        return "Sum(" + ", ".join(repr(term) for term in self.terms) + ")"


# --------------------------------------------------------------------------------------------
# conversion


class _PiecewiseLinear(Signal):
    """A piecewise-linear signal as the simulator compiles it: one structure for every
    piecewise-linear kind, the value and slope of each interval as per-interval numbers."""

    __slots__ = ("base",)

    def __init__(self, base: Signal) -> None:
        self._set(base=base)

    @property
    def key(self) -> Hashable:
        return ("PiecewiseLinear",)

    @property
    def n_params(self) -> int:
        return 0

    @property
    def n_piece(self) -> int:
        return 3

    def params(self) -> np.ndarray:
        return np.zeros(0)

    def piece(self, ta: float, tb: float) -> np.ndarray:
        a, b = self.base.linear_piece(ta, tb)
        return np.array([ta, a, b])

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        return piece[1] + piece[2] * (t - piece[0])

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        return self.base(t)

    def breaks(self) -> np.ndarray:
        return self.base.breaks()

    def bound(self, t_end: float) -> float:
        return self.base.bound(t_end)

    def __repr__(self) -> str:
        return f"PiecewiseLinear({self.base!r})"


def compiled_form(sig: Optional[Signal]) -> Optional[Signal]:
    """The form in which the simulator compiles ``sig``: piecewise-linear signals (constants,
    steps, ramps, samples and their sums) all share the structure ``("PiecewiseLinear",)``,
    their numbers given per integration interval; other signals are compiled as they are.

    Parameters
    ----------
    sig : Signal or None
        The signal.

    Returns
    -------
    Signal or None
    """
    if sig is None or isinstance(sig, _PiecewiseLinear):
        return sig
    return _PiecewiseLinear(sig) if sig.linear_piece(0.0, 0.0) is not None else sig


def as_signal(value: Any, name: str, unit: str) -> Optional[Signal]:
    """Convert a user-facing signal argument to a :class:`Signal`.

    Parameters
    ----------
    value : None, Signal, float, (array_like, array_like) or callable
        ``None`` (no signal), a signal, a finite real number (a :class:`Constant`), samples
        ``(t, values)`` (a :class:`Samples`) or a callable of time [s] (a :class:`Traced`).
    name : str
        Argument name for error messages (e.g. ``"u"``, ``"reference"``).
    unit : str
        Unit of the values for error messages (e.g. ``"N"``, ``"m"``).

    Returns
    -------
    Signal or None
        ``None`` only for ``None``.

    Raises
    ------
    TypeError, ValueError
        With a message naming ``name``.
    """
    if value is None or isinstance(value, Signal):
        return value
    if _is_real(value):
        return Constant(_number(name, value, unit))
    if isinstance(value, tuple):
        if len(value) != 2:
            raise ValueError(f"{name} samples must be a pair (t, values), got a tuple of length {len(value)}")
        return Samples(value[0], value[1], name=name, unit=unit)
    if callable(value):
        return Traced(value, name=name)
    hint = " (for samples pass a pair (t, values) with the sample times)" if isinstance(value, (list, np.ndarray)) else ""
    raise TypeError(
        f"{name} must be None, a Signal (prefriction.signals), a finite real number [{unit}], a pair "
        f"(t, values) of sample arrays or a callable of time t [s]; got {value!r} of type "
        f"{type(value).__name__}{hint}"
    )
