"""Closed-form describing function of the Dahl model (3.2) with ``gamma = 1``.

Under the displacement ``x = A sin(theta)`` the settled Dahl cycle is symmetric. Its loading
branch (3.5) runs from ``(-A, -F_r)`` to ``(A, F_r)`` with the reversal force
``F_r = Fc tanh(k)``, ``k = sigma A / Fc``, and the cycle encloses the dissipated energy
``4 Fc (A - (Fc / sigma) tanh(k))``. The first harmonic of the force,
``F ~ b1 sin(theta) + a1 cos(theta)``, gives the describing function ``N(A) = (b1 + i a1) / A``
(python-control's convention):

- in-phase part ``b1 / A = (2 Fc / A) I_1(k) / cosh(k)`` (``I_1`` the modified Bessel
  function, from ``int_0^pi exp(k cos(phi)) cos(phi) dphi = pi I_1(k)``);
- quadrature part ``a1 / A = area / (pi A^2) = (4 Fc / (pi A)) (1 - tanh(k) / k)``.

``N`` depends on ``A`` only (rate independence). Limits: ``N -> sigma`` for ``k -> 0`` (the
rest stiffness) and ``N -> 4 i Fc / (pi A)`` for ``k -> inf`` (the Coulomb relay with its
quarter-period lead). Derivation: ``docs/describing.md#dahl``.
"""

from __future__ import annotations

import math
from typing import Any

import control
import numpy as np
from scipy.special import ive

from prefriction._validation import check_finite, check_positive, check_real_array

__all__ = ["DahlDescribingFunction", "dahl_cycle", "dahl_describing_function"]


def _k(A: Any, sigma: float, Fc: float) -> tuple[np.ndarray, np.ndarray]:
    """``A`` [m] as a float array and ``k = sigma A / Fc``; the arguments validated."""
    try:
        A = check_real_array("A", A, "m", lo=0.0)
    except ValueError as exc:
        if "entries (memory)" in str(exc):
            raise
        arr = np.asarray(A, dtype=float)
        bad = float(arr[~(np.isfinite(arr) & (arr >= 0.0))].flat[0])
        raise ValueError(f"A must lie in [0, inf) [m] (every entry finite), got {bad!r}") from None
    ratio = check_positive("sigma", sigma) / check_positive("Fc", Fc)
    with np.errstate(over="ignore"):  # k = inf beyond the double range: the limits are taken
        return A, ratio * A


def dahl_cycle(A: Any, sigma: float, Fc: float) -> tuple[np.ndarray, np.ndarray]:
    """Reversal force and enclosed area of the symmetric Dahl cycle (gamma = 1) of amplitude ``A``.

    Parameters
    ----------
    A : array_like
        Displacement amplitude [m], ``0 <= A < inf``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``F_r = Fc tanh(sigma A / Fc)`` [N] and the area ``4 Fc (A - (Fc / sigma) tanh(sigma A / Fc))``
        [J], the energy dissipated per cycle (evaluated without cancellation for small ``A``).
    """
    A, k = _k(A, sigma, Fc)
    th = np.tanh(k)
    # k - tanh k = k^3/3 - 2k^5/15 + 17k^7/315 - ...: series below 0.1 (relative error < 1e-16)
    small = k < 0.1
    ks = np.where(small, k, 0.0)
    series = ks ** 3 * (1.0 / 3.0 - ks * ks * (2.0 / 15.0 - ks * ks * (17.0 / 315.0 - ks * ks * 62.0 / 2835.0)))
    gap = np.where(small, series, k - th)
    return Fc * th, 4.0 * (Fc * Fc / sigma) * gap


def dahl_describing_function(A: Any, sigma: float, Fc: float) -> np.ndarray:
    """Describing function ``N(A)`` [N/m] of the Dahl model (3.2) with gamma = 1, closed form.

    ``N(A) = (2 Fc / A) [I_1(k) / cosh(k) + (2 i / pi)(1 - tanh(k) / k)]``, ``k = sigma A / Fc``:
    the first harmonic ``b1 sin + a1 cos`` of the settled friction force under
    ``x = A sin(theta)``, as ``(b1 + i a1) / A`` (python-control's convention). ``N(0) = sigma``.

    Parameters
    ----------
    A : array_like
        Displacement amplitude [m], ``0 <= A < inf``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray of complex
        ``N(A)`` [N/m]; real part the equivalent stiffness, imaginary part ``omega`` times the
        equivalent damping (energy per cycle ``pi A^2 Im N``).
    """
    A, k = _k(A, sigma, Fc)
    sigma = float(sigma)
    # in units of sigma, without A itself (no overflow of 1/A or underflow of A^2):
    # Re N / sigma = 2 I_1(k) / (k cosh k) = 4 ive(1, k) / (k (1 + exp(-2 k)))
    # Im N / sigma = (4 / pi) (k - tanh k) / k^2
    big = k > 1e6  # scipy's ive(1, k) is NaN above ~1e9: two terms of its asymptotic series (error < 1e-17)
    kb = np.where(big, k, 1.0)
    ive1 = np.where(big, (1.0 - 3.0 / (8.0 * kb) - 15.0 / (128.0 * kb) / kb) / np.sqrt(2.0 * math.pi * kb),
                    ive(1, np.where(big, 1.0, k)))
    small = k < 0.1
    ks = np.where(small, k, 1.0)
    # (k - tanh k) / k^2 = k/3 - 2k^3/15 + 17k^5/315 - 62k^7/2835: series below 0.1 (relative error < 1e-16)
    g2 = np.where(small, ks * (1.0 / 3.0 - ks * ks * (2.0 / 15.0 - ks * ks * (17.0 / 315.0 - ks * ks * 62.0 / 2835.0))),
                  (1.0 - np.tanh(k) / np.where(small, 1.0, k)) / np.where(small, 1.0, k))
    with np.errstate(invalid="ignore", divide="ignore"):
        re = np.where(k == 0.0, 1.0, 4.0 * ive1 / (np.where(k == 0.0, 1.0, k) * (1.0 + np.exp(-2.0 * k))))
    # small k: I_1(k)/(k cosh k) = 1/2 - k^2/16 + ..., so re = sigma (1 - k^2/8 + ...) stays accurate
    return sigma * re + 1j * sigma * (4.0 / math.pi) * g2


class DahlDescribingFunction(control.DescribingFunctionNonlinearity):
    """The Dahl model (3.2), gamma = 1, as a python-control describing-function nonlinearity.

    ``describing_function(A)`` is the closed form :func:`dahl_describing_function`.
    ``__call__(x)`` steps the hysteresis itself: each call moves the input to ``x`` [m] and
    returns the force [N] on the branch (3.4)/(3.5) through the last reversal, so that
    ``control.describing_function(F, A, try_method=False)`` computes the same ``N`` by
    python-control's own numerical harmonic analysis. The nonlinearity has memory
    (``_isstatic`` is False); it starts at ``x = 0``, ``F = 0``.

    Parameters
    ----------
    sigma : float
        Rest stiffness [N/m], ``0 < sigma < inf``.
    Fc : float
        Coulomb force [N], ``0 < Fc < inf``.
    """

    def __init__(self, sigma: float, Fc: float) -> None:
        super().__init__()
        self.sigma = check_positive("sigma", sigma)
        self.Fc = check_positive("Fc", Fc)
        self._x, self._F, self._s = 0.0, 0.0, 1.0
        self._xr, self._Fr = 0.0, 0.0  # start of the current branch

    def __repr__(self) -> str:
        return f"DahlDescribingFunction(sigma={self.sigma!r}, Fc={self.Fc!r})"

    def __call__(self, x: Any) -> float:
        x = check_finite("x", float(np.squeeze(x)))
        if x == self._x:
            return self._F
        s = 1.0 if x > self._x else -1.0
        if s != self._s:  # a reversal at the previous input
            self._xr, self._Fr, self._s = self._x, self._F, s
        # (3.4): s F = Fc - (Fc - s F_r) exp(-s sigma (x - x_r) / Fc)
        y = self.sigma * (x - self._xr) / self.Fc
        self._F = s * (s * self._Fr - (self.Fc - s * self._Fr) * math.expm1(-s * y))
        self._x = x
        return self._F

    def describing_function(self, A: float) -> complex:
        """``N(A)`` [N/m] in closed form (:func:`dahl_describing_function`)."""
        return complex(dahl_describing_function(A, self.sigma, self.Fc))

    def _isstatic(self) -> bool:
        return False
