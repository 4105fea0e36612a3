"""Analytics of the Dahl model with ``gamma = 1`` (Section 3 of the paper), vectorised over numpy arrays.

Equation numbers are those of M. Ruderman, "Energy dissipation and hysteresis cycles in
pre-sliding transients of kinetic friction", Appl. Math. 68 (2023) 845-860. SI units: rest
stiffness ``sigma`` [N/m], Coulomb force ``Fc`` [N], positions [m], forces [N], energies [J].

The normalised reversal map ``a = |F_i| / Fc -> a' = |F_{i+1}| / Fc`` of the unforced oscillator
(2.1) is universal (independent of ``sigma``, ``Fc`` and the mass): the potential energy (3.9)
at reversal ``i`` is ``(Fc^2/sigma) H(-a)`` with ``H(f) = -f - ln(1 - f)``, and the next reversal
stores the same energy on the loading side, ``H(a') = H(-a)`` (energy balance (2.3), (2.9)).
:func:`next_amplitude` solves it to about 1e-15 relative for every ``a`` in (0, 1];
:func:`next_amplitude_paper` is the paper's explicit approximation (3.11)-(3.13).

Every function checks its arguments first: ``TypeError`` for ``None``, strings, booleans,
complex numbers or ragged arrays, ``ValueError`` for non-finite entries, values outside the
documented range, shapes that do not broadcast, ``sigma`` and ``Fc`` whose units ``Fc/sigma``,
``Fc^2/sigma`` leave the double-precision range, and results that would overflow; each message
names the argument, its value and the allowed range.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from prefriction._validation import (
    check_array_interval,
    check_bool,
    check_broadcast,
    check_count,
    check_interval,
    check_positive,
    check_real_array,
)

__all__ = [
    "MAX_POTENTIAL_FACTOR",
    "MAX_STEPS",
    "amplitude_sequence",
    "asymptotic_amplitude",
    "branch_energy",
    "branch_force",
    "max_potential_energy",
    "next_amplitude",
    "next_amplitude_paper",
    "next_reversal_position_paper",
    "omega",
    "omega_star",
    "potential_energy",
    "reversal_abscissa",
    "zero_crossing",
]

#: Most steps of :func:`amplitude_sequence` in one call (80 MB, about 10 s).
MAX_STEPS = 10_000_000

#: ``1 - ln 2``: the largest potential energy at a reversal is this times ``Fc^2 / sigma``.
MAX_POTENTIAL_FACTOR = 1.0 - math.log(2.0)

# Taylor coefficients of the exact map a' = sum_k _MAP_SERIES[k-1] a^k (k = 1..26): exact
# rationals 1, -2/3, 4/9, -44/135, 104/405, -40/189, ... from reverting H(a') = H(-a) order by
# order (coefficient k of a' is fixed by order k+1 of the power series of H). Radius of
# convergence 1 (|c_k| ~ 1/k); used for a <= 0.2 (26 terms) and a <= 0.01 (9 terms), where the
# relative truncation error is below 1e-18.
_MAP_SERIES = (
    1.0, -0.6666666666666666, 0.4444444444444444, -0.32592592592592595, 0.25679012345679014,
    -0.21164021164021163, 0.17984714873603763, -0.15626886145404664, 0.1380974154636706,
    -0.12367106429109173, 0.11194448206924527, -0.10222750667857032, 0.09404628321338172,
    -0.08706478047189273, 0.08103813977135456, -0.07578375581573293, 0.07116269936142636,
    -0.0670674121661032, 0.0634133366375539, -0.06013308746712411, 0.0571723085484626,
    -0.05448667314703977, 0.05203967568062399, -0.04980098181908212, 0.04774517897483555,
    -0.04585081830260209,
)
_SERIES_MAX = 0.2
# Starting guess for a > 0.2: Pade approximant [4/2] of a'/a built from the series above
# (relative error < 6e-5 on [0.2, 1]); three Newton steps then reach rounding level.
_PADE_NUM = (1.0, 0.73883792, -0.03454201, -0.00660162, 0.00226267)
_PADE_DEN = (1.0, 1.40550459, 0.4580166)
_NEWTON_STEPS = 2


def _as_sigma_fc(sigma: Any, Fc: Any) -> tuple[float, float]:
    """``sigma`` [N/m] and ``Fc`` [N] as floats > 0 whose units ``Fc / sigma`` [m], ``sigma / Fc``
    [1/m] and ``Fc^2 / sigma`` [J] are finite and normal in double precision."""
    sigma, Fc = check_positive("sigma", sigma), check_positive("Fc", Fc)
    units = (Fc / sigma, sigma / Fc, Fc / sigma * Fc)
    if not all(math.isfinite(u) and u >= _TINY for u in units):
        raise ValueError(
            f"sigma = {sigma!r} N/m and Fc = {Fc!r} N are out of range together: the units Fc/sigma [m], "
            f"sigma/Fc [1/m] and Fc^2/sigma [J] must lie in [{_TINY!r}, {_HUGE!r}] (double precision), "
            f"got {units[0]!r}, {units[1]!r} and {units[2]!r}"
        )
    return sigma, Fc


_TINY = 2.2250738585072014e-308  # smallest normal double
_HUGE = 1.7976931348623157e308


def _direction(direction: Any) -> float:
    if isinstance(direction, (bool, np.bool_)) or direction not in (1, -1):
        raise ValueError(f"direction must be +1 or -1 (sign of the velocity), got {direction!r}")
    return float(direction)


def _normalised_position(name: str, x: Any, sigma: float, Fc: float) -> np.ndarray:
    """``sigma x / Fc`` of the positions ``x`` [m]: finite entries whose normalised value is finite."""
    x = check_real_array(name, x, "m")
    with np.errstate(over="ignore"):  # an overflow is refused below, naming the entry
        y = sigma * x / Fc
    bad = ~np.isfinite(y)
    if np.any(bad):
        raise ValueError(
            f"{name} = {float(x[bad].flat[0])!r} m is too large for sigma = {sigma!r} N/m and Fc = {Fc!r} N: "
            f"sigma {name} / Fc overflows (allowed: |{name}| <= {_HUGE * Fc / sigma:.6g} m)"
        )
    return y


def _finite_result(name: str, x: np.ndarray, out: np.ndarray, what: str) -> np.ndarray:
    """``out`` if every entry is finite; else ``ValueError`` naming the entry of ``x`` behind it."""
    bad = ~np.isfinite(out)
    if np.any(bad):
        raise ValueError(
            f"{name} = {float(np.broadcast_to(x, out.shape)[bad][0])!r} m lies too far before the zero crossing: "
            f"{what} exceeds the double-precision range (allowed: {name} with a finite {what}, i.e. "
            f"sigma {name} / Fc >= about -700)"
        )
    return out


def branch_force(x: Any, x_i: Any, F_i: Any, sigma: float, Fc: float, direction: int = 1) -> np.ndarray:
    """Friction force on the branch after a reversal, (3.4); (3.5) for ``direction = +1``.

    ``F(x) = s (Fc - (Fc - s F_i) exp(-s sigma (x - x_i) / Fc))`` with ``s = direction``.

    Parameters
    ----------
    x : array_like
        Positions [m] on the branch (``s (x - x_i) >= 0``).
    x_i : array_like
        Position of the reversal that starts the branch [m].
    F_i : array_like
        Friction force at that reversal [N], ``|F_i| <= Fc``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].
    direction : {1, -1}, default 1
        Sign of the velocity on the branch.

    Returns
    -------
    numpy.ndarray
        Friction force [N].

    Raises
    ------
    ValueError
        If ``x`` lies behind the reversal (``direction (x - x_i) < 0``), ``|F_i| > Fc``, or the
        shapes of ``x``, ``x_i``, ``F_i`` do not broadcast.
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    s = _direction(direction)
    F_i = check_array_interval("F_i", F_i, -Fc, Fc)
    x = check_real_array("x", x, "m")
    x_i = check_real_array("x_i", x_i, "m")
    check_broadcast(x=x, x_i=x_i, F_i=F_i)
    with np.errstate(over="ignore", invalid="ignore"):
        y = sigma * (x - x_i) / Fc
    behind = ~(s * y >= 0.0)
    if np.any(behind):
        raise ValueError(
            f"x must lie on the branch, direction (x - x_i) >= 0 [m] (and sigma (x - x_i) / Fc finite), got "
            f"x = {float(np.broadcast_to(x, y.shape)[behind][0])!r} m with x_i = "
            f"{float(np.broadcast_to(x_i, y.shape)[behind][0])!r} m and direction = {int(s)}"
        )
    # s F = Fc - (Fc - s F_i) e^{-s y} = s F_i + (Fc - s F_i)(1 - e^{-s y})
    return s * (s * F_i - (Fc - s * F_i) * np.expm1(-s * y))


def zero_crossing(x_i: Any, F_i: Any, sigma: float, Fc: float, direction: int = 1) -> np.ndarray:
    """Position where the branch force (3.4) crosses zero, (3.6).

    ``x_0 = x_i - s (Fc / sigma) ln(Fc / (Fc - s F_i))``; for ``s = +1`` this is (3.6). A
    zero crossing exists ahead of the reversal when ``s F_i < 0``.

    Parameters
    ----------
    x_i : array_like
        Position of the reversal [m].
    F_i : array_like
        Friction force at the reversal [N], ``-Fc <= F_i < Fc`` for ``s = +1``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].
    direction : {1, -1}, default 1
        Sign of the velocity on the branch.

    Returns
    -------
    numpy.ndarray
        Zero-crossing position [m].

    Raises
    ------
    ValueError
        If ``direction F_i >= Fc`` (a branch that starts at the Coulomb force never crosses zero).
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    s = _direction(direction)
    F_i = check_array_interval("F_i", F_i, -Fc, Fc)
    x_i = check_real_array("x_i", x_i, "m")
    check_broadcast(x_i=x_i, F_i=F_i)
    _check_not_saturated(F_i, s, Fc)
    return x_i + s * (Fc / sigma) * np.log1p(-s * F_i / Fc)


def _check_not_saturated(F_i: np.ndarray, s: float, Fc: float) -> None:
    """A branch that starts at ``s F_i = Fc`` stays there: no zero crossing, (3.6) and (3.8) diverge."""
    if np.any(s * F_i >= Fc):
        raise ValueError(
            f"F_i must satisfy direction F_i < Fc = {Fc!r} N (a branch that starts at the Coulomb force "
            f"never crosses zero), got F_i = {float(s * Fc)!r} N with direction = {int(s)} "
            f"(allowed: -Fc <= direction F_i < Fc)"
        )


def reversal_abscissa(F_i: Any, sigma: float, Fc: float) -> np.ndarray:
    """Reversal position relative to the next zero crossing ``x_{0,i} = 0``, (3.8).

    ``x_i = (Fc / sigma) ln(Fc / (Fc - F_i)) < 0`` for ``-Fc <= F_i < 0`` (positive velocity
    after the reversal).

    Parameters
    ----------
    F_i : array_like
        Friction force at the reversal [N], in [-Fc, Fc).
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray
        ``x_i`` [m].
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    F_i = check_array_interval("F_i", F_i, -Fc, Fc)
    _check_not_saturated(F_i, 1.0, Fc)
    return -(Fc / sigma) * np.log1p(-F_i / Fc)


def branch_energy(x: Any, sigma: float, Fc: float) -> np.ndarray:
    """Antiderivative of the loading branch, (3.7), zero at the force zero crossing ``x = 0``.

    ``E_f+(x) = Fc x + (Fc^2 / sigma) exp(-sigma x / Fc) - Fc^2 / sigma``, evaluated as
    ``(Fc^2 / sigma)(y + expm1(-y))`` with ``y = sigma x / Fc`` (no cancellation for small ``x``).
    For ``x < 0`` (between a reversal and the zero crossing) it is the energy the branch returns.

    Parameters
    ----------
    x : array_like
        Position relative to the force zero crossing [m].
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray
        Energy [J], ``>= 0``.
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    y = _normalised_position("x", x, sigma, Fc)
    with np.errstate(over="ignore", invalid="ignore"):
        out = (Fc * Fc / sigma) * _g(y)
    return _finite_result("x", y * (Fc / sigma), out, "the energy")


def _g(y: np.ndarray) -> np.ndarray:
    """``g(y) = y + e^{-y} - 1`` without cancellation (series for ``|y| < 0.5``)."""
    y = np.asarray(y, dtype=float)
    small = np.abs(y) < 0.5
    ys = np.where(small, y, 0.0)
    # g(y) = y^2 sum_{k>=0} (-y)^k / (k+2)!
    acc = np.zeros_like(ys)
    for k in range(22, -1, -1):
        acc = acc * -ys + 1.0 / math.factorial(k + 2)
    return np.where(small, ys * ys * acc, y + np.expm1(-y))


def _phi(z: np.ndarray) -> np.ndarray:
    """``Phi(z) = sum_{k>=0} z^k / (k + 2) = (-ln(1 - z) - z) / z^2``, so ``H(f) = f^2 Phi(f)``."""
    z = np.asarray(z, dtype=float)
    small = np.abs(z) <= 0.25
    zs = np.where(small, z, 0.5)
    acc = np.zeros_like(zs)
    for k in range(28, -1, -1):
        acc = acc * zs + 1.0 / (k + 2)
    zl = np.where(small, 0.5, z)
    with np.errstate(divide="ignore"):
        direct = (-np.log1p(-zl) - zl) / (zl * zl)
    return np.where(small, acc, direct)


def potential_energy(F: Any, sigma: float, Fc: float) -> np.ndarray:
    """Potential energy at a reversal with friction force ``F``, (3.9).

    ``E_p = (Fc^2 / sigma)(ln(Fc / (Fc + |F|)) + |F| / Fc)``: (3.9) written for either
    direction of the reversal (the paper takes ``F_i <= 0``). It is the energy the new branch
    returns as kinetic energy until its force zero crossing, and the peak kinetic energy of the
    following half-cycle. Evaluated as ``a^2 Phi(-a)``, ``a = |F| / Fc``, accurate also for tiny ``a``.

    Parameters
    ----------
    F : array_like
        Friction force at the reversal [N], ``|F| <= Fc``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray
        ``E_p`` [J], at most :func:`max_potential_energy`.
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    F = check_array_interval("F", F, -Fc, Fc)
    a = np.abs(F) / Fc
    return (Fc * Fc / sigma) * a * a * _phi(-a)


def max_potential_energy(sigma: float, Fc: float) -> float:
    """Largest potential energy at a reversal, ``(1 - ln 2) Fc^2 / sigma`` (after (3.9)).

    Reached at ``|F_i| = Fc``; the sharp form of the bound (2.12), whose general form
    ``Fc^2 / (2 sigma)`` uses the minimal unloading stiffness ``sigma``.

    Parameters
    ----------
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    float
        Energy [J] (``0.306853 Fc^2 / sigma``).
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    return MAX_POTENTIAL_FACTOR * Fc * Fc / sigma


def _check_amplitude(a: Any) -> np.ndarray:
    return check_array_interval("a", a, 0.0, 1.0)


def next_amplitude(a: Any) -> np.ndarray:
    """Exact normalised reversal map ``|F_i| / Fc -> |F_{i+1}| / Fc`` of the unforced oscillator.

    Solves ``H(a') = H(-a)``, ``H(f) = -f - ln(1 - f)``: the energy balance (2.3) between the
    potential energy (3.9) released after reversal ``i`` and the energy (3.7) stored up to
    reversal ``i+1``; the same root as (3.10) (``a' = 1 - exp(-y)``, ``y = c + 1 + W0(-e^{-1-c})``,
    ``c = H(-a)``), without the cancellation of the Lambert-W form near its branch point.
    Independent of ``sigma``, ``Fc`` and the mass.

    Numerics: for ``a <= 0.2`` the convergent power series ``a' = a - 2a^2/3 + 4a^3/9 - ...``
    (26 exact terms); above, Newton on ``b sqrt(Phi(b)) = a sqrt(Phi(-a))`` (well conditioned,
    ``Phi(z) = (-ln(1 - z) - z) / z^2``) from a Pade starting guess. Relative error about 1e-15
    on [1e-12, 1] (see the tests), and ``a' = a`` to rounding as ``a -> 0``.

    Parameters
    ----------
    a : array_like
        Normalised amplitude ``|F_i| / Fc`` in [0, 1].

    Returns
    -------
    numpy.ndarray
        ``|F_{i+1}| / Fc``, with ``0 <= a' < a`` for ``a > 0`` (``a' = 0.5936243`` at ``a = 1``).

    Raises
    ------
    ValueError
        If an entry of ``a`` lies outside [0, 1] or is not finite.
    """
    a = _check_amplitude(a)
    out = np.empty(a.shape)
    small = a <= _SERIES_MAX
    for lo, hi, terms in ((-1.0, 0.01, 9), (0.01, _SERIES_MAX, len(_MAP_SERIES))):
        band = (a > lo) & (a <= hi)
        if np.any(band):
            x = a[band]
            acc = np.zeros_like(x)
            for c in reversed(_MAP_SERIES[:terms]):
                acc = acc * x + c
            out[band] = x * acc
    if not np.all(small):
        out[~small] = _newton_map(a[~small])
    return out


def _newton_map(a: np.ndarray) -> np.ndarray:
    """Newton on ``S(b) = sqrt(H(b)) = sqrt(H(-a))`` for ``a`` in (0.2, 1].

    Here ``b > 0.17`` and ``a > 0.2``, so the direct forms of ``H`` lose at most a factor 11
    to cancellation (``H(f) = f^2 Phi(f)`` with ``Phi`` direct).
    """
    R = np.sqrt(a - np.log1p(a))
    num = (((_PADE_NUM[4] * a + _PADE_NUM[3]) * a + _PADE_NUM[2]) * a + _PADE_NUM[1]) * a + _PADE_NUM[0]
    den = (_PADE_DEN[2] * a + _PADE_DEN[1]) * a + _PADE_DEN[0]
    b = a * num / den
    for _ in range(_NEWTON_STEPS):
        S = np.sqrt(-np.log1p(-b) - b)
        # dS/db = H'(b) / (2 S) = b / (2 (1 - b) S)
        b = b - (S - R) * 2.0 * S * (1.0 - b) / b
    return b


def next_amplitude_paper(a: Any, *, sigma_over_Fc: float | None = None) -> np.ndarray:
    """The paper's explicit approximation of the reversal map, (3.11)-(3.13).

    The exponential ``Omega`` of (3.10) is replaced by the line ``Omega*`` of (3.11), giving the
    next reversal position (3.13) and, through (3.5), the next amplitude
    ``a' = 1 - exp(-sigma x_{i+1} / Fc)``.

    Erratum: as printed, (3.13) reads ``x_{i+1} = (E_p / Fc)(1 - (Fc / sigma) r^{3/5})^{-1}``,
    ``r = Fc / (Fc - F_i)``, which is dimensionally inconsistent (``Fc / sigma`` is a length).
    Solving (3.12) with ``K`` from (3.11) gives ``x_{i+1} = E_p / (Fc (1 - r^{3/5}))``; in
    normalised units ``sigma x_{i+1} / Fc = H(-a) / (1 - (1 + a)^{-3/5})``, independent of
    ``sigma`` and ``Fc``. The printed form agrees with it only when ``sigma / Fc = 1`` [1/m].
    Against :func:`next_amplitude` the corrected form errs by 0.15 % at ``a = 1``, 5 % at
    ``a = 0.6``, 12 % at ``a = 0.2`` and tends to a factor 5/6 as ``a -> 0``.

    Parameters
    ----------
    a : array_like
        Normalised amplitude ``|F_i| / Fc`` in [0, 1].
    sigma_over_Fc : float, optional
        If given, evaluate (3.13) as printed with this ratio ``sigma / Fc`` [1/m] (SI); by
        default the dimensionally consistent form.

    Returns
    -------
    numpy.ndarray
        Approximate ``|F_{i+1}| / Fc`` (``nan``-free; 0 at ``a = 0``).
    """
    a = _check_amplitude(a)
    y = _paper_normalised_position(a, sigma_over_Fc)
    return -np.expm1(-y)


def _paper_normalised_position(a: np.ndarray, sigma_over_Fc: float | None) -> np.ndarray:
    """``sigma x_{i+1} / Fc`` from (3.13) (corrected, or as printed with ``sigma / Fc`` given)."""
    Ep = a * a * _phi(-a)  # (3.9) in units Fc^2 / sigma
    with np.errstate(invalid="ignore", divide="ignore"):
        if sigma_over_Fc is None:
            # 1 - (1 + a)^{-3/5} = -expm1(-0.6 log1p(a)); ratio -> 5 a / 6 as a -> 0
            den = -np.expm1(-0.6 * np.log1p(a))
        else:
            k = check_positive("sigma_over_Fc", sigma_over_Fc)
            den = 1.0 - np.exp(-0.6 * np.log1p(a)) / k
        y = np.where(a > 0, Ep / np.where(a > 0, den, 1.0), 0.0)
    return y


def next_reversal_position_paper(F_i: Any, sigma: float, Fc: float, *, printed: bool = False) -> np.ndarray:
    """Next reversal position relative to the zero crossing, the paper's (3.13).

    Parameters
    ----------
    F_i : array_like
        Friction force at reversal ``i`` [N], ``-Fc <= F_i <= 0`` (the paper's orientation).
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].
    printed : bool, default False
        Evaluate (3.13) as printed (with its extra factor ``Fc / sigma`` in SI units) instead of
        the corrected ``x_{i+1} = E_p / (Fc (1 - r^{3/5}))``; see :func:`next_amplitude_paper`.

    Returns
    -------
    numpy.ndarray
        Approximate ``x_{i+1}`` [m] (the exact one is ``(Fc / sigma) y`` with ``y`` the root of (3.10)).
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    F_i = check_array_interval("F_i", F_i, -Fc, 0.0)
    printed = check_bool("printed", printed)
    y = _paper_normalised_position(-F_i / Fc, sigma / Fc if printed else None)
    return (Fc / sigma) * y


def omega(x: Any, sigma: float, Fc: float) -> np.ndarray:
    """Exponential term of (3.10): ``Omega(x) = exp(-sigma x / Fc)``.

    Parameters
    ----------
    x : array_like
        Position relative to the zero crossing [m].
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray
        ``Omega(x)`` (dimensionless).
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    y = _normalised_position("x", x, sigma, Fc)
    with np.errstate(over="ignore"):
        out = np.exp(-y)
    return _finite_result("x", y * (Fc / sigma), out, "exp(-sigma x / Fc)")


def omega_star(x: Any, F_i: Any, sigma: float, Fc: float) -> np.ndarray:
    """Linear approximation (3.11) of ``Omega``: ``Omega*(x) = 1 - K x``.

    ``K(sigma, Fc, F_i) = (sigma / Fc) exp(0.6 ln(Fc / (Fc - F_i)))``.

    Parameters
    ----------
    x : array_like
        Position relative to the zero crossing [m].
    F_i : array_like
        Friction force at the last reversal [N], ``-Fc <= F_i <= 0``.
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].

    Returns
    -------
    numpy.ndarray
        ``Omega*(x)`` (dimensionless).
    """
    sigma, Fc = _as_sigma_fc(sigma, Fc)
    F_i = check_array_interval("F_i", F_i, -Fc, 0.0)
    y = _normalised_position("x", x, sigma, Fc)
    check_broadcast(x=y, F_i=F_i)
    # K x = (sigma x / Fc) (1 + a)^-0.6 with (1 + a)^-0.6 in [0.66, 1]: finite when sigma x / Fc is
    return 1.0 - np.exp(-0.6 * np.log1p(-F_i / Fc)) * y


def amplitude_sequence(a0: float, n: int) -> np.ndarray:
    """Normalised reversal amplitudes ``a_0, a_1, ..., a_n`` of the recursion (3.14).

    ``a_{k+1} = next_amplitude(a_k)``, with the potential energies (3.14)
    ``E_p(k) = (Fc^2 / sigma) (a_k - ln(1 + a_k))``. Relative error after ``1e5`` steps
    from ``a_0 = 1`` below 1e-12 (rounding only; the map contracts relative errors).

    Parameters
    ----------
    a0 : float
        First amplitude ``|F_0| / Fc`` in [0, 1].
    n : int
        Number of steps, ``>= 0``.

    Returns
    -------
    numpy.ndarray
        Array of length ``n + 1``.
    """
    a = check_interval("a0", a0, 0.0, 1.0)
    n = check_count("n", n, minimum=0, maximum=MAX_STEPS, why=f"{8 * MAX_STEPS // 10**6} MB and about 10 s")
    out = np.empty(n + 1)
    out[0] = a
    series = _MAP_SERIES[::-1]
    k = 0
    # large amplitudes: vectorised kernel on one element (few steps only)
    while k < n and a > _SERIES_MAX:
        a = float(_newton_map(np.array([a]))[0])
        k += 1
        out[k] = a
    # small amplitudes: scalar Horner of the map series (same formula as next_amplitude)
    while k < n:
        acc = 0.0
        for c in series:
            acc = acc * a + c
        a = a * acc
        k += 1
        out[k] = a
    return out


def asymptotic_amplitude(n: Any, a0: float = 1.0) -> np.ndarray:
    """Asymptotic law of the reversal amplitudes: ``a_n ~ 3 / (2 n)``, with its corrections.

    From ``1/a' = 1/a + 2/3 + (4/135) a^2 + O(a^3)`` (no ``O(a)`` term, hence no logarithm),
    ``1/a_n = (2/3) m - 1 / (15 m) + O(m^-3)`` with ``m = n + n0``: so
    ``a_n = 15 m / (10 m^2 - 1)``. The offset ``n0`` depends on ``a0``; it is fixed by
    iterating the exact map until ``a < 0.005`` and matching there. Relative error below
    ``1e-3 / n^3 + 1e-13`` (checked against :func:`amplitude_sequence`).

    Parameters
    ----------
    n : array_like
        Reversal counts ``>= 0`` (integers or reals).
    a0 : float, default 1.0
        First amplitude in (0, 1].

    Returns
    -------
    numpy.ndarray
        Approximate ``a_n``.
    """
    a0 = check_interval("a0", a0, 0.0, 1.0)
    if a0 == 0.0:
        raise ValueError("a0 must lie in (0, 1] for the asymptotic law, got 0.0 (a_n = 0 for all n)")
    n = check_real_array("n", n, lo=0.0)
    k, a = 0, a0
    while a > 0.005:
        a = float(next_amplitude(a))
        k += 1
    u = 1.0 / a
    m_k = (15.0 * u + math.sqrt(225.0 * u * u + 40.0)) / 20.0  # root of (2/3) m - 1/(15 m) = u
    m = n + (m_k - k)
    return 15.0 * m / (10.0 * m * m - 1.0)
