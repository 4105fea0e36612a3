"""Analytic derivatives of the exact reversal map of the unforced Dahl oscillator, gamma = 1.

In normalised units the unforced problem from ``x = 0``, ``F = 0`` with speed ``v~0`` has one
number, the initial energy ``c = v~0^2 / 2``. With ``H(f) = -f - ln(1 - f)``:

- first reversal: ``H(a_0) = c``, so ``da_0/dc = 1 / H'(a_0) = (1 - a_0) / a_0``;
- map ``H(a_{i+1}) = H(-a_i)`` (:func:`prefriction.dahl.next_amplitude`), by the implicit
  function theorem ``da_{i+1}/da_i = H'(-a_i) / -H'(a_{i+1}) = a_i (1 - a_{i+1}) / ((1 + a_i) a_{i+1})``;
- forces ``F~_i = s_i a_i`` (sign alternating), positions from the branch distances
  ``x~_0 = s_0 ln(1 / (1 - a_0))``, ``x~_{i+1} = x~_i - s_i (ln(1 + a_i) + ln(1 / (1 - a_{i+1})))``.

SI: ``F_i = Fc F~_i``, ``x_i = (Fc / sigma) x~_i`` and ``c = m sigma v0^2 / (2 Fc^2)``, which
gives the derivatives with respect to ``sigma``, ``Fc``, the mass and ``v0``
(``docs/sensitivities.md#exact-map``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.special import lambertw

from prefriction.analysis import dahl
from prefriction._validation import check_count, check_finite
from prefriction.models import check_dahl_oscillator

__all__ = ["exact_sensitivities", "map_derivative"]

PARAMETERS = ("sigma", "Fc", "mass", "v0")


def map_derivative(a: Any) -> np.ndarray:
    """``da'/da`` of the exact reversal map ``a -> a' = next_amplitude(a)`` (gamma = 1).

    ``a (1 - a') / ((1 + a) a')`` from the implicit function theorem on ``H(a') = H(-a)``;
    1 at ``a = 0`` (the map is ``a - 2 a^2 / 3 + ...``).

    Parameters
    ----------
    a : array_like
        Normalised amplitudes ``|F_i| / Fc`` in [0, 1].

    Returns
    -------
    numpy.ndarray
        ``da'/da``, in (0, 1].
    """
    a = np.asarray(a, dtype=float)
    b = dahl.next_amplitude(a)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = a * (1.0 - b) / ((1.0 + a) * b)
    return np.where(a == 0.0, 1.0, d)


def _first_amplitude(c: float) -> float:
    """``a_0`` with ``H(a_0) = c``: ``a_0 = 1 - exp(-y)``, ``y = c + 1 + W0(-exp(-1 - c))``."""
    if c < 1e-4:  # series of the inverse: a = r - r^2/3 + r^3/36 ..., r = sqrt(2c), Newton to polish
        r = math.sqrt(2.0 * c)
        a = r - r * r / 3.0 + r ** 3 / 36.0
    else:
        y = c + 1.0 + float(lambertw(-math.exp(-1.0 - c), 0).real)
        a = -math.expm1(-y)
    for _ in range(3):  # Newton on H(a) = c, H'(a) = a / (1 - a)
        Ha = float(dahl.branch_energy(-math.log1p(-a), 1.0, 1.0))  # H(a) = g(-ln(1 - a))
        a -= (Ha - c) * (1.0 - a) / a
    return a


def exact_sensitivities(system: Any, v0: float, n: int) -> dict:
    """Reversal positions and forces of the unforced Dahl oscillator (gamma = 1) and their
    derivatives with respect to ``sigma``, ``Fc``, the mass and ``v0``, in closed form.

    The motion starts at ``x = 0``, ``F = 0`` with velocity ``v0``.

    Parameters
    ----------
    system : Oscillator
        Unforced oscillator with :class:`prefriction.Dahl` friction, gamma = 1.
    v0 : float
        Initial velocity [m/s], nonzero.
    n : int
        Number of reversals, ``1 <= n <= 10**6``.

    Returns
    -------
    dict
        ``"x"``, ``"F"``: arrays of length ``n`` [m], [N]; ``"dx"``, ``"dF"``: arrays of shape
        ``(n, 4)``, columns ``d/dsigma``, ``d/dFc``, ``d/dmass``, ``d/dv0`` (SI);
        ``"parameters"``: the column names.
    """
    friction = check_dahl_oscillator(system, "exact_sensitivities")
    if friction.gamma != 1.0 or system.u is not None:
        raise ValueError(
            f"exact_sensitivities needs the unforced Dahl oscillator with gamma = 1, got gamma = {friction.gamma!r}"
            f"{' and an input force' if system.u is not None else ''}; use prefriction.sensitivity.sensitivities"
        )
    v0 = check_finite("v0", v0)
    if v0 == 0.0:
        raise ValueError("v0 must be nonzero (the oscillator at rest at F = 0 does not move), got 0.0")
    n = check_count("n", n)
    if n > 10 ** 6:
        raise ValueError(f"n must be <= 1000000 (memory), got {n}")
    sigma, Fc, m = friction.sigma, friction.Fc, system.mass
    c = m * sigma * v0 * v0 / (2.0 * Fc * Fc)
    s0 = math.copysign(1.0, v0)
    a = np.empty(n)
    a[0] = _first_amplitude(c)
    a[1:] = dahl.amplitude_sequence(a[0], n - 1)[1:]
    da = np.empty(n)  # da_i / dc
    da[0] = (1.0 - a[0]) / a[0]
    if n > 1:
        da[1:] = da[0] * np.cumprod(map_derivative(a[:-1]))
    sgn = s0 * (-1.0) ** np.arange(n)  # direction of the branch that ends at reversal i
    # normalised position: x~_0 = s0 L(a0), x~_{i+1} = x~_i - s_i (log1p(a_i) + L(a_{i+1}))
    L = -np.log1p(-a)
    dL = da / (1.0 - a)
    steps = np.concatenate(([L[0]], np.log1p(a[:-1]) + L[1:]))
    dsteps = np.concatenate(([dL[0]], da[:-1] / (1.0 + a[:-1]) + dL[1:]))
    xn, dxn = np.cumsum(sgn * steps), np.cumsum(sgn * dsteps)
    Fn, dFn = sgn * a, sgn * da  # the force at reversal i points along the branch that ends there
    # dc/dtheta for theta = sigma, Fc, mass, v0
    dc = np.array([c / sigma, -2.0 * c / Fc, c / m, 2.0 * c / v0])
    X = Fc / sigma
    dX = np.array([-X / sigma, 1.0 / sigma, 0.0, 0.0])
    dF = np.outer(Fc * dFn, dc)
    dF[:, 1] += Fn
    dx = np.outer(X * dxn, dc) + np.outer(xn, dX)
    return {"x": X * xn, "F": Fc * Fn, "dx": dx, "dF": dF, "parameters": PARAMETERS}
