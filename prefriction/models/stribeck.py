"""The Stribeck curve of a friction model, in SI units and normalised, for floats and CasADi.

``S(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)`` [N], a magnitude (``S > 0``), from the Coulomb
force ``Fc``, the static force ``Fs``, the Stribeck velocity ``vs`` and the shape exponent
``delta`` (2: the Gaussian form); in steady sliding the friction force is ``sign(v) S(v) +
sigma2 v``. Its normalised form, built from run-time numbers, is ``S~(v~) = 1 + (Fs/Fc - 1)
exp(-((v~ V/vs)^2)^(delta/2))`` with the velocity unit ``V`` (``docs/models.md``). Used by
:class:`prefriction.GMS` (Al-Bender, Lampaert and Swevers 2005).
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

__all__ = ["StribeckCurve"]


def _exp(x: Any) -> Any:
    """``exp`` of a float or a CasADi symbol."""
    return ca.exp(x) if isinstance(x, (ca.SX, ca.MX)) else math.exp(x)


def _pow(x: Any, y: Any) -> Any:
    """``x ** y`` for ``x >= 0`` (0 at ``x = 0``), of floats or CasADi symbols; ``inf`` instead of
    ``OverflowError``. On symbols the power sits in ``if_else(x > 0, ...)``: the derivative of
    ``x ** y`` with respect to ``y`` is ``log(x) x^y``, NaN at ``x = 0``, and CasADi's event
    location differentiates the indicators (a NaN there stops the integrator at ``v = 0``)."""
    if isinstance(x, (ca.SX, ca.MX)) or isinstance(y, (ca.SX, ca.MX)):
        return ca.if_else(x > 0.0, x ** y, 0.0)
    x = float(x)
    if x <= 0.0:
        return 0.0
    try:
        return x ** float(y)
    except OverflowError:
        return math.inf


class StribeckCurve:
    """Mixin of a model with the fields ``Fc``, ``Fs``, ``vs``, ``delta`` and ``sigma2``: its
    Stribeck curve (module notes) and steady-sliding force."""

    Fc: float
    Fs: float
    vs: float
    delta: float
    sigma2: float

    def stribeck(self, v: Any) -> np.ndarray:
        """Stribeck curve ``S(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)`` [N] (a magnitude) at the
        velocities ``v`` [m/s] (numpy)."""
        v = np.asarray(v, dtype=float)
        return self.Fc + (self.Fs - self.Fc) * np.exp(-np.abs(v / self.vs) ** self.delta)

    def steady_force(self, v: Any) -> np.ndarray:
        """Friction force [N] in steady sliding at the constant velocity ``v`` [m/s] (numpy):
        ``sign(v) S(v) + sigma2 v`` (GMS: every element slipping at ``sign(v) alpha_i S(v)``)."""
        v = np.asarray(v, dtype=float)
        return np.sign(v) * self.stribeck(v) + self.sigma2 * v

    @staticmethod
    def _S(v: Any, q: Any, i: int) -> Any:
        """Normalised Stribeck curve ``S~(v~) = 1 + (Fs/Fc - 1) exp(-((v~ V/vs)^2)^(delta/2))``
        from the run-time numbers ``q[i:i + 3] = (Fs/Fc - 1, V/vs, delta/2)``."""
        r = v * q[i + 1]
        return 1.0 + q[i] * _exp(-_pow(r * r, q[i + 2]))
