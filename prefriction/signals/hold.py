"""Zero-order hold: :class:`ZeroOrderHold`, constant between switching times, with jumps."""

from __future__ import annotations

from typing import Any, Optional, Union

import numpy as np

from prefriction._validation import check_real_array
from prefriction.signals._checks import UNIT, number, time_end
from prefriction.signals.base import LinearPieces
from prefriction.signals.samples import _times_values

__all__ = ["ZeroOrderHold"]


class ZeroOrderHold(LinearPieces):
    """Piecewise-constant signal with jumps: ``u[k]`` on ``[t[k], t[k+1])`` (a zero-order hold).

    Before ``t[0]`` the signal is ``u[0]``, from ``t[-1]`` on it holds ``u[-1]``. Bang-bang and
    sampled forces are of this kind (:class:`Samples` is continuous, linear between samples).
    Like :class:`Samples`, the values are not compiled: every zero-order hold shares the
    simulator's piecewise-linear structure, and the switching times are :meth:`breaks`, where
    the simulator restarts its integration.

    Parameters
    ----------
    t : array_like
        Switching times [s]: 1-D, finite, strictly increasing, 1 to
        :data:`~prefriction.signals.MAX_SAMPLES` entries.
    u : array_like
        Values [signal units] held from each switching time on: 1-D, finite, same length as ``t``.
    name : str, optional
        Name of the signal in error messages (e.g. ``"u"``); default: none.
    unit : str, optional
        Unit of the values in error messages, default ``"signal units"``.

    Examples
    --------
    >>> import prefriction as pf
    >>> u = pf.signals.ZeroOrderHold([0.0, 0.01, 0.02], [5.0, -5.0, 0.0])   # [s], [N]
    >>> float(u(0.005)), float(u(0.01)), float(u(0.03))
    (5.0, -5.0, 0.0)
    """

    __slots__ = ("_t", "_u")

    def __init__(self, t: Any, u: Any, *, name: Optional[str] = None, unit: str = UNIT) -> None:
        nt, nu = (f"{name} switching times t", f"{name} values") if name else ("t", "u")
        ts, us = _times_values(nt, t, nu, u, unit, 1, "entry")
        self._set(_t=ts, _u=us)

    @property
    def t(self) -> np.ndarray:
        """Switching times [s] (read-only)."""
        return self._t

    @property
    def u(self) -> np.ndarray:
        """Values held from each switching time on [signal units] (read-only)."""
        return self._u

    def _value(self, t: np.ndarray) -> np.ndarray:
        k = np.clip(np.searchsorted(self._t, t, side="right") - 1, 0, self._t.size - 1)
        return self._u[k]

    def linear_piece(self, ta: float, tb: float) -> tuple[float, float]:
        """``(value, 0)`` on ``[ta, tb]`` [s]: the value held at the midpoint (no jump inside)."""
        return float(self._value(np.array(0.5 * (ta + tb)))), 0.0

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Constant piece on ``[ta, tb]`` as ``(tl [s], a [signal units], b = 0)`` (:meth:`Signal.piece`).

        Parameters
        ----------
        ta, tb : float
            Start and end [s] of the interval, ``ta <= tb``, with no switching time strictly inside.

        Returns
        -------
        numpy.ndarray
            ``(ta, value held on the interval, 0)``.
        """
        ta = number("ta", ta, "s")
        tb = number("tb", tb, "s", f">= ta = {ta!r}", lambda v: v >= ta)
        return np.array([ta, self.linear_piece(ta, tb)[0], 0.0])

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value at the time(s) ``t`` [s] (right-continuous at the jumps), shaped like ``t``."""
        value = self._value(check_real_array("t", t, "s"))
        return float(value) if np.ndim(value) == 0 else value

    def velocity(self, t: Any) -> Union[float, np.ndarray]:
        """0 [signal units / s] at every time ``t`` [s]: the held values jump, they do not slope."""
        value = np.zeros(np.shape(check_real_array("t", t, "s")))
        return float(value) if value.ndim == 0 else value

    def breaks(self) -> np.ndarray:
        """Copy of the switching times :attr:`t` [s], where the value jumps."""
        return self._t.copy()

    def bound(self, t_end: float) -> float:
        """Largest magnitude over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`; exact)."""
        t_end = time_end(t_end)
        k0, k1 = (int(np.clip(np.searchsorted(self._t, t, side="right") - 1, 0, self._t.size - 1)) for t in (0.0, t_end))
        return float(np.abs(self._u[k0:k1 + 1]).max())

    def __repr__(self) -> str:
        t0, t1, lo, hi = (float(x) for x in (self._t[0], self._t[-1], self._u.min(), self._u.max()))
        return f"ZeroOrderHold(n={self._t.size}, t=[{t0!r} .. {t1!r}], u=[{lo!r} .. {hi!r}])"
