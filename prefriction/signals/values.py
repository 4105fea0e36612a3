"""Numeric values of a :class:`~prefriction.signals.Signal`: the value and the time derivative at
given times (the mixin :class:`SignalValues` of the base class)."""

from __future__ import annotations

import math
from typing import Any, Union

import casadi
import numpy as np

from prefriction._validation import check_real_array
from prefriction.signals._ops import MathOps

__all__ = ["SignalValues"]


class SignalValues:
    """Value and velocity of a signal at numeric times, from the structure's expression and the
    signal's numbers (mixin of :class:`~prefriction.signals.Signal`, which supplies ``expr``,
    ``_expr``, ``params``, ``n_params``, ``n_piece``, ``breaks`` and ``linear_piece``)."""

    __slots__ = ()

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
