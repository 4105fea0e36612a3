"""Branch functions of the Dahl model (3.2) for any shape factor ``gamma >= 0``, normalised units.

On a branch of fixed direction ``s`` write ``f = s F / Fc`` and ``w = 1 - f`` (the gap to
saturation). Dahl (3.2) reads ``df/dxi = w^gamma`` with ``xi`` the normalised distance travelled
(units ``Fc / sigma``). Everything here follows from three integrals, evaluated without
cancellation:

- distance ``xi(f1 -> f2) = int_{f1}^{f2} (1 - phi)^-gamma dphi``;
- branch potential ``H(f) = int_0^f phi (1 - phi)^-gamma dphi >= 0`` (energy in units
  ``Fc^2 / sigma`` relative to the force zero crossing, (3.9) for ``gamma = 1``);
- on the loading side the log-gap ``L = -ln(1 - f)`` replaces ``f``: ``dxi = e^{(gamma-1) L} dL``.
  ``L`` stays representable in gross sliding, where ``w = e^{-L}`` underflows and ``f`` rounds to 1.

For ``gamma < 1`` the branch saturates (``f = 1``) after the finite distance
``w^{1-gamma} / (1 - gamma)``; beyond it the force stays at ``Fc`` (Coulomb sliding) and ``H``
grows by one per unit distance. For ``gamma >= 1``, ``f -> 1`` only asymptotically.

Numerics: for ``f <= 3/4``, ``H = f^2 Q(f)`` with ``Q(f) = int_0^1 t (1 - f t)^-gamma dt`` by
Gauss-Legendre quadrature (positive integrand, analytic on a Bernstein ellipse of parameter
>= 3, so no cancellation for ``f`` down to 1e-300); for ``f > 3/4`` the closed form
``H = I_{gamma-1}(L) - I_{gamma-2}(L)`` with ``I_c(L) = int_0^L e^{c l} dl``, whose two terms
differ by a factor >= 1.6, each evaluated with ``expm1``/``exprel`` (stable as ``gamma -> 1, 2``).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.special import exprel

from prefriction._validation import check_nonnegative

__all__ = [
    "BranchEnd",
    "branch_distance",
    "branch_potential",
    "force_after_distance",
    "gauss_legendre_01",
    "int_exp",
    "loading_end_for_energy",
    "loading_force_for_energy",
    "log_gap",
    "log_gap_after_distance",
    "potential_of_log_gap",
    "potential_ratio",
    "saturation_energy",
]

_F_SPLIT = 0.75  # below: quadrature form f^2 Q(f); above: closed form in L = -ln(1 - f)


@lru_cache(maxsize=None)
def gauss_legendre_01(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1], accurate to about one ulp.

    Newton on the Legendre recurrence in extended precision (``numpy.longdouble``); the
    weights of ``numpy.polynomial.legendre.leggauss`` and ``scipy.special.roots_legendre``
    carry relative errors up to 1e-13, which would spoil 1e-15 quadratures.
    """
    ld = np.longdouble
    k = np.arange(1, n + 1, dtype=ld)
    x = np.cos(ld(np.pi) * (k - ld(0.25)) / (n + ld(0.5)))
    for _ in range(100):
        p0, p1 = np.ones_like(x), x.copy()
        for j in range(2, n + 1):
            p0, p1 = p1, ((2 * j - 1) * x * p1 - (j - 1) * p0) / j
        dp = n * (x * p1 - p0) / (x * x - 1)
        dx = p1 / dp
        x = x - dx
        if np.max(np.abs(dx)) < ld(1e-18):
            break
    p0, p1 = np.ones_like(x), x.copy()
    for j in range(2, n + 1):
        p0, p1 = p1, ((2 * j - 1) * x * p1 - (j - 1) * p0) / j
    dp = n * (x * p1 - p0) / (x * x - 1)
    w = 1 / ((1 - x * x) * dp * dp)
    t = np.asarray((x + 1) / 2, dtype=float)[::-1].copy()
    wt = np.asarray(w, dtype=float)[::-1].copy()
    t.setflags(write=False)
    wt.setflags(write=False)
    return t, wt


def _nodes_for(gamma: float) -> int:
    """Quadrature order for Q(f), f <= 3/4: the integrand has a pole of order gamma at t >= 4/3."""
    return int(min(32 + 4 * np.ceil(gamma), 240))


def _check_gamma(gamma: float) -> float:
    return check_nonnegative("gamma", gamma)


def int_exp(c: float, D: np.ndarray) -> np.ndarray:
    """``int_0^D e^{c l} dl`` for ``D >= 0`` (``D`` may be ``inf``), accurate for every ``c``.

    Uses ``D exprel(c D)`` for ``|c D| <= 1`` and ``expm1(c D) / c`` otherwise.
    """
    D = np.asarray(D, dtype=float)
    if c == 0.0:
        return D.copy()
    with np.errstate(invalid="ignore", over="ignore"):
        z = c * D
        small = np.abs(z) <= 1.0
        out = np.where(small, D * exprel(np.where(small, z, 0.0)), np.expm1(z) / c)
    return out


def log_gap(f: np.ndarray) -> np.ndarray:
    """Log-gap ``L = -ln(1 - f)`` (``inf`` at saturation ``f = 1``)."""
    f = np.asarray(f, dtype=float)
    with np.errstate(divide="ignore"):
        return -np.log1p(-f)


def potential_ratio(f: np.ndarray, gamma: float) -> np.ndarray:
    """``Q(f) = H_gamma(f) / f^2``, with ``Q(0) = 1/2``; finite and accurate for tiny ``|f|``.

    Parameters
    ----------
    f : array_like
        Normalised branch force ``s F / Fc`` in [-1, 1].
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    numpy.ndarray
        ``Q(f) = int_0^1 t (1 - f t)^-gamma dt`` (dimensionless); ``inf`` at ``f = 1`` for
        ``gamma >= 1``.
    """
    gamma = _check_gamma(gamma)
    f = np.asarray(f, dtype=float)
    out = np.empty(f.shape)
    low = f <= _F_SPLIT
    if gamma == 0.0:
        return np.full(f.shape, 0.5)
    if gamma == 1.0:
        return _ratio_gamma1(f)
    fl = f[low]
    if fl.size:
        t, wt = gauss_legendre_01(_nodes_for(gamma))
        integrand = t * np.exp(-gamma * np.log1p(-np.multiply.outer(fl, t)))
        out[low] = integrand @ wt
    fh = f[~low]
    if fh.size:
        with np.errstate(over="ignore"):
            out[~low] = potential_of_log_gap(log_gap(fh), gamma) / (fh * fh)
    return out


_SERIES_N = 57
_SERIES_W = 1.0 / (np.arange(_SERIES_N) + 2.0)


def _ratio_gamma1(f: np.ndarray) -> np.ndarray:
    """``Q(f) = (-ln(1 - f) - f) / f^2 = sum_k f^k / (k + 2)`` (``gamma = 1``), series for ``|f| <= 1/2``.

    Direct form above ``|f| = 1/2``, where the cancellation costs at most a factor 5.
    """
    small = np.abs(f) <= 0.5
    fs = np.where(small, f, 0.0)
    # powers fs^0 .. fs^56 by a running product (one numpy call, not a 57-step Horner loop):
    # 0.5^57 / 59 < 1e-19; each power carries at most ~56 ulp, on terms that decay like 2^-k
    powers = np.empty(fs.shape + (_SERIES_N,))
    powers[..., 0] = 1.0
    powers[..., 1:] = fs[..., None]
    np.cumprod(powers, axis=-1, out=powers)
    acc = powers @ _SERIES_W
    fl = np.where(small, 0.75, f)
    with np.errstate(divide="ignore"):
        direct = (-np.log1p(-fl) - fl) / (fl * fl)
    return np.where(small, acc, direct)


def branch_potential(f: np.ndarray, gamma: float) -> np.ndarray:
    """Branch potential ``H_gamma(f) = int_0^f phi (1 - phi)^-gamma dphi`` (normalised energy).

    The energy stored by the Dahl branch (3.2) between its force zero crossing and the
    normalised force ``f``, in units ``Fc^2 / sigma``. For ``gamma = 1`` it is
    ``-f - ln(1 - f)``; ``H(-a)`` is the paper's potential energy (3.9) at a reversal of
    amplitude ``a = |F_i| / Fc``. Relative accuracy about 1e-15 for every ``f`` in [-1, 1]
    (``H`` underflows to 0 for ``|f| < 1e-154``; use :func:`potential_ratio` there).

    Parameters
    ----------
    f : array_like
        Normalised branch force ``s F / Fc`` in [-1, 1].
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    numpy.ndarray
        ``H_gamma(f) >= 0``; at ``f = 1``: ``1 / ((1 - gamma)(2 - gamma))`` for ``gamma < 1``,
        ``inf`` for ``gamma >= 1``.
    """
    f = np.asarray(f, dtype=float)
    q = potential_ratio(f, gamma)
    with np.errstate(over="ignore", invalid="ignore"):
        return np.where(np.isinf(q), np.inf, f * f * q)


def potential_of_log_gap(L: np.ndarray, gamma: float) -> np.ndarray:
    """``H_gamma`` as a function of the log-gap ``L = -ln(1 - f) >= 0`` (loading side).

    ``H = int_0^L (1 - e^{-l}) e^{(gamma - 1) l} dl``. Exact also when ``f = 1 - e^{-L}``
    rounds to 1 (gross sliding, e.g. ``L = 1e6``).

    Parameters
    ----------
    L : array_like
        Log-gap ``L >= 0`` (``inf`` allowed: saturation).
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    numpy.ndarray
        ``H`` in units ``Fc^2 / sigma``.
    """
    gamma = _check_gamma(gamma)
    L = np.asarray(L, dtype=float)
    out = np.empty(L.shape)
    low = L <= -np.log1p(-_F_SPLIT)
    if np.any(low):
        fl = -np.expm1(-L[low])
        out[low] = fl * fl * potential_ratio(fl, gamma)
    Lh = L[~low]
    if Lh.size:
        c = gamma - 1.0
        with np.errstate(over="ignore", invalid="ignore"):
            a = int_exp(c, Lh)
            b = int_exp(c - 1.0, Lh)
            out[~low] = np.where(np.isinf(a), a, a - b)
    return out


def saturation_energy(gamma: float) -> float:
    """``H_gamma(1) = 1 / ((1 - gamma)(2 - gamma))`` for ``gamma < 1`` (``inf`` for ``gamma >= 1``).

    The normalised energy (units ``Fc^2 / sigma``) a loading branch stores from its zero
    crossing up to saturation ``|F| = Fc``.
    """
    gamma = _check_gamma(gamma)
    return 1.0 / ((1.0 - gamma) * (2.0 - gamma)) if gamma < 1.0 else float("inf")


def branch_distance(f1: np.ndarray, f2: np.ndarray, gamma: float) -> np.ndarray:
    """Normalised distance ``xi = int_{f1}^{f2} (1 - phi)^-gamma dphi`` along a branch.

    Closed form ``w1^{1-gamma} int_0^D e^{(gamma-1) l} dl`` with ``D = ln(w1 / w2)
    = log1p((f2 - f1) / w2)``, accurate also for ``f2 - f1`` tiny and ``gamma`` near 1.
    For ``gamma = 1`` it is ``ln((1 - f1) / (1 - f2))``, the distance of (3.4)/(3.5).

    Parameters
    ----------
    f1, f2 : array_like
        Normalised branch forces, ``-1 <= f1 <= f2 <= 1`` (``f2 = 1`` is saturation).
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    numpy.ndarray
        Distance in units ``Fc / sigma`` (``inf`` for ``f2 = 1`` and ``gamma >= 1``).
    """
    gamma = _check_gamma(gamma)
    f1 = np.asarray(f1, dtype=float)
    f2 = np.asarray(f2, dtype=float)
    w1 = 1.0 - f1
    w2 = 1.0 - f2
    with np.errstate(divide="ignore"):
        D = np.log1p((f2 - f1) / w2)
    return w1 ** (1.0 - gamma) * int_exp(gamma - 1.0, D)


def _advance(f1: np.ndarray, xi: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """Log-gap increment ``D = L2 - L1`` after distance ``xi`` and the slide beyond saturation."""
    f1 = np.asarray(f1, dtype=float)
    xi = np.asarray(xi, dtype=float)
    c = gamma - 1.0
    w1 = 1.0 - f1
    with np.errstate(divide="ignore", invalid="ignore"):  # w1 = 0, c < 0: already saturated (below)
        X = xi * w1**c  # int_0^D e^{c l} dl = X
    if c == 0.0:
        return X, np.zeros(np.broadcast(f1, xi).shape)
    z = c * X
    sat = (z <= -1.0) | ((w1 == 0.0) & (c < 0.0))  # a branch started at f1 = 1 (gamma < 1) stays there
    zz = np.where(sat, 0.0, z)
    with np.errstate(divide="ignore", invalid="ignore"):
        small = np.abs(zz) < 1e-4
        rel = np.where(small, 1.0 - zz / 2.0 + zz * zz / 3.0 - zz**3 / 4.0, np.log1p(zz) / np.where(small, 1.0, zz))
        D = np.where(sat, np.inf, X * rel)
        slide = np.where(sat, xi - w1 ** (1.0 - gamma) / (1.0 - gamma), 0.0)  # sat only if gamma < 1
    return D, slide


def force_after_distance(f1: np.ndarray, xi: np.ndarray, gamma: float) -> np.ndarray:
    """Normalised force after travelling ``xi >= 0`` along a branch from force ``f1``.

    Closed-form branch (3.4) for ``gamma = 1`` (``w2 = w1 e^{-xi}``), and in general
    ``w2^{1-gamma} = w1^{1-gamma} - (1 - gamma) xi``, evaluated as ``f2 = f1 + w1 (1 - e^{-D})``
    with ``D = ln(w1 / w2)`` from ``log1p``. Saturates at ``f2 = 1`` for ``gamma < 1``.

    Parameters
    ----------
    f1 : array_like
        Start force ``s F / Fc`` in [-1, 1].
    xi : array_like
        Distance in units ``Fc / sigma``, ``>= 0``.
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    numpy.ndarray
        ``f2`` in [f1, 1].
    """
    gamma = _check_gamma(gamma)
    f1 = np.asarray(f1, dtype=float)
    D, _ = _advance(f1, xi, gamma)
    return f1 + (1.0 - f1) * -np.expm1(-D)


def log_gap_after_distance(f1: np.ndarray, xi: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """Log-gap ``L2 = -ln(1 - f2)`` after distance ``xi`` from ``f1``, and the Coulomb slide.

    Exact in gross sliding, where ``1 - f2`` underflows.

    Parameters
    ----------
    f1 : array_like
        Start force ``s F / Fc`` in [-1, 1].
    xi : array_like
        Distance in units ``Fc / sigma``, ``>= 0``.
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    L2 : numpy.ndarray
        ``-ln(1 - f2)`` (``inf`` once saturated, ``gamma < 1``).
    slide : numpy.ndarray
        Distance travelled at ``f = 1`` beyond saturation (0 unless ``gamma < 1``), units ``Fc / sigma``.
    """
    gamma = _check_gamma(gamma)
    D, slide = _advance(f1, xi, gamma)
    return log_gap(f1) + D, slide


class BranchEnd(NamedTuple):
    """End of a loading branch that stores a given energy (see :func:`loading_end_for_energy`).

    Attributes
    ----------
    f : numpy.ndarray
        Normalised force ``s F / Fc`` in [0, 1] (1 after saturation or to double precision).
    L : numpy.ndarray
        Log-gap ``-ln(1 - f)`` (``inf`` once saturated); exact where ``1 - f`` underflows.
    xi : numpy.ndarray
        Distance from the force zero crossing, units ``Fc / sigma``, including the slide.
    slide : numpy.ndarray
        Coulomb slide distance at ``f = 1`` beyond saturation (0 unless ``gamma < 1``).
    """

    f: np.ndarray
    L: np.ndarray
    xi: np.ndarray
    slide: np.ndarray


def loading_end_for_energy(E: np.ndarray, gamma: float) -> BranchEnd:
    """Where a loading branch started at its zero crossing with energy ``E`` stops.

    Solves ``H_gamma(f) = E`` for ``f`` in [0, 1) (safeguarded Newton in ``ln L``); for
    ``gamma < 1`` and ``E >= H_gamma(1)`` the branch saturates and slides the distance
    ``E - H_gamma(1)`` at ``f = 1``. For ``gamma = 1`` this is the Lambert-W root of (3.10):
    ``L = E + 1 + W0(-e^{-(1 + E)})``.

    Parameters
    ----------
    E : array_like
        Normalised energy ``>= 0`` (units ``Fc^2 / sigma``), finite.
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    BranchEnd
        Force, log-gap, distance from the zero crossing and slide distance.
    """
    gamma = _check_gamma(gamma)
    E = np.asarray(E, dtype=float)
    if np.any(~np.isfinite(E) | (E < 0)):
        raise ValueError(f"E must be finite and >= 0 (every entry), got {E[~(np.isfinite(E) & (E >= 0))].flat[0]!r}")
    c = gamma - 1.0
    Hsat = saturation_energy(gamma)
    sat = E >= Hsat
    L = np.zeros(E.shape)
    todo = (E > 0) & ~sat
    if np.any(todo):
        L[todo] = _solve_log_gap(E[todo], gamma)
    L = np.where(sat, np.inf, L)
    slide = np.where(sat, E - Hsat if np.isfinite(Hsat) else 0.0, 0.0)
    f = -np.expm1(-L)
    xi = np.where(sat, 1.0 / (1.0 - gamma) + slide if gamma < 1 else np.inf, int_exp(c, np.where(sat, 0.0, L)))
    return BranchEnd(f, L, xi, slide)


def loading_force_for_energy(E: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """Force ``f`` in [0, 1] with ``H_gamma(f) = E`` on the loading side, and the slide distance.

    Shorthand for :func:`loading_end_for_energy` returning ``(f, slide)``.

    Parameters
    ----------
    E : array_like
        Normalised energy ``>= 0`` (units ``Fc^2 / sigma``).
    gamma : float
        Dahl shape factor (3.2), ``>= 0``.

    Returns
    -------
    f : numpy.ndarray
        Normalised force in [0, 1] (exactly 1 when saturated, ``gamma < 1``).
    slide : numpy.ndarray
        Coulomb slide distance beyond saturation, units ``Fc / sigma`` (0 unless saturated).
    """
    end = loading_end_for_energy(E, gamma)
    return end.f, end.slide


def _solve_log_gap(E: np.ndarray, gamma: float) -> np.ndarray:
    """Root ``L > 0`` of ``H(L) = E`` (``0 < E < H_sat``): safeguarded Newton on ``ln H`` vs ``ln L``."""
    c = gamma - 1.0
    lnE = np.log(E)
    # bracket [lo, hi] in u = ln L by expansion from an asymptotic guess
    guess = np.where(E < 0.5, np.sqrt(2.0 * E), np.where(c > 0, np.log1p(c * E) / max(c, 1e-300) + 1.0, E + 1.0))
    u = np.log(guess)
    lo = u - 1.0
    hi = u + 1.0
    for _ in range(200):
        flo = np.log(potential_of_log_gap(np.exp(lo), gamma)) - lnE
        bad = flo > 0
        if not np.any(bad):
            break
        lo = np.where(bad, lo - 2.0, lo)
    for _ in range(200):
        with np.errstate(over="ignore"):
            fhi = np.log(potential_of_log_gap(np.exp(hi), gamma)) - lnE
        bad = fhi < 0
        if not np.any(bad):
            break
        hi = np.where(bad, hi + 1.0, hi)
    u = np.clip(u, lo, hi)
    for _ in range(100):
        L = np.exp(u)
        H = potential_of_log_gap(L, gamma)
        r = np.log(H) - lnE
        lo = np.where(r < 0, u, lo)
        hi = np.where(r > 0, u, hi)
        dH = -np.expm1(-L) * np.exp(c * L)  # dH/dL = f e^{c L}
        with np.errstate(divide="ignore", invalid="ignore"):
            step = r * H / (dH * L)
        un = u - step
        out = ~((un > lo) & (un < hi)) | ~np.isfinite(un)
        un = np.where(out, 0.5 * (lo + hi), un)
        done = np.abs(un - u) <= 4e-16 * np.maximum(1.0, np.abs(un))
        u = un
        if np.all(done | (hi - lo <= 4e-16 * np.maximum(1.0, np.abs(u)))):
            break
    L = np.exp(u)
    # one Newton step in L itself removes the rounding of exp(u)
    dH = -np.expm1(-L) * np.exp(c * L)
    return L - (potential_of_log_gap(L, gamma) - E) / dH
