"""Exact reference trajectory at the velocity reversals of the unforced Dahl oscillator (2.1).

Everything is computed in the normalised units of :mod:`prefriction.units` (the unforced
system is then parameter-free apart from ``gamma``) and returned in SI units.

Positions and forces come from the energy balance (2.3) on closed-form branches
(:mod:`prefriction.analysis.branch`): a half-cycle that starts at rest with normalised force ``-a``
ends at rest at the force ``b`` with ``H(b) = H(-a)``; for ``gamma = 1`` this is the map
:func:`prefriction.analysis.dahl.next_amplitude`. Times are quadratures of
``t = int dxi / sqrt(2 K(xi))`` (``K`` the kinetic energy) split at the force zero crossing,
with the integrable ``1/sqrt`` endpoint singularities removed by ``xi = xi_end - L u^2``, and
``K`` near each end written as a positive integral of the force over the remaining distance
(no cancellation). Gauss-Legendre rules, vectorised over all half-cycles at once.

The first half-cycle starts from an arbitrary state and may go deep into gross sliding: there
the log-gap ``L = -ln(1 - f)`` is the variable (``1 - f`` underflows) on panels graded
geometrically towards both ends, and for ``gamma < 1`` the Coulomb slide beyond saturation
(constant deceleration) is added in closed form. ``gamma = 0`` (Prandtl stop) is entirely in
closed form.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from prefriction.analysis import dahl
from prefriction.analysis.branch import (
    branch_distance,
    branch_potential,
    gauss_legendre_01,
    int_exp,
    loading_end_for_energy,
    log_gap,
    potential_of_log_gap,
)
from prefriction.analysis.exact_input import MAX_REVERSALS, MAX_SPEED, check_initial_state
from prefriction.models import Dahl, Oscillator, check_dahl_oscillator
from prefriction.reversals import ReversalTable
from prefriction.units import Scales

__all__ = ["MAX_REVERSALS", "MAX_SPEED", "check_initial_state", "exact_reversals"]


_N = 32  # Gauss-Legendre order of the panel rules (first half-cycle)
_N_REG = 24  # order of the vectorised half-cycle rules (integrands analytic on ellipses rho >= 3)
_F_REGULAR = 0.75  # half-cycles ending below this force use the vectorised rule
_CHUNK = 2048  # half-cycles per vectorised block (memory: _CHUNK * _N_REG^2 doubles)


def exact_reversals(system: Oscillator, v0: float, n: int, *, x0: float = 0.0, F0: float = 0.0) -> ReversalTable:
    """First ``n`` velocity reversals of the unforced Dahl oscillator (2.1), exactly.

    The reference trajectory against which simulations are measured: reversal times,
    positions and forces to about 1e-15 relative (positions relative to
    ``max(|x|, Fc / sigma)``; tested to 1e-13 against mpmath), for every ``gamma >= 0``, from
    tiny oscillations to first excursions deep in gross sliding. Positions and forces follow from the energy balance
    (2.3), (2.9) on the closed-form branches of (3.2) ((3.4)-(3.10) for ``gamma = 1``), times
    from Gauss-Legendre quadrature of ``dt = dx / |v|`` with the endpoint singularities removed.

    Parameters
    ----------
    system : Oscillator
        Unforced oscillator (``system.u is None``) with :class:`prefriction.Dahl` friction, or
        with :class:`prefriction.MaxwellSlip` friction (closed-form event sequence,
        :func:`prefriction.analysis.maxwell_slip_exact.maxwell_slip_reversals`).
    v0 : float
        Initial velocity [m/s].
    n : int
        Number of reversals, ``>= 1``.
    x0 : float, default 0.0
        Initial position [m].
    F0 : float, default 0.0
        Initial friction force [N], ``|F0| <= Fc``. With ``v0 = 0`` the motion starts in the
        direction ``-sign(F0)``.

    Returns
    -------
    ReversalTable
        Times ``t`` [s], positions ``x`` [m], forces ``F`` [N], potential energies ``E_p`` [J]
        ((3.9) for ``gamma = 1``) and energies dissipated per half-cycle ``E_d`` [J] (2.10), and
        the initial energy ``E_0`` [J].

    Raises
    ------
    TypeError
        If ``system`` is not an :class:`Oscillator` with :class:`Dahl` friction, or an argument
        has the wrong type.
    ValueError
        If the system is forced, ``n < 1``, ``v0``/``x0``/``F0`` are not finite, ``|F0| > Fc``, or
        ``v0 = 0`` and ``F0 = 0`` (the oscillator is at rest and nothing moves).

    Examples
    --------
    >>> import prefriction as pf
    >>> system = pf.Oscillator(pf.Dahl(sigma=1e4, Fc=1.0), mass=1.0)
    >>> table = pf.exact_reversals(system, 0.0, 3, F0=-1.0)  # released at rest from -Fc
    >>> [round(float(F), 7) for F in table.F]  # the map 1 -> 0.5936243 -> ...
    [0.5936243, -0.4239535, 0.3300787]
    """
    from prefriction.models.maxwell_slip import MaxwellSlip

    if isinstance(system, Oscillator) and isinstance(system.friction, MaxwellSlip):
        from prefriction.analysis.maxwell_slip_exact import maxwell_slip_reversals

        return maxwell_slip_reversals(system, v0, n, x0=x0, F0=F0)
    if isinstance(system, Oscillator) and not isinstance(system.friction, Dahl):
        raise TypeError(
            f"system.friction must be a prefriction.Dahl or MaxwellSlip model: exact_reversals has an exact "
            f"reference for Dahl and MaxwellSlip only, got {system.friction!r} of type "
            f"{type(system.friction).__name__}; use prefriction.simulate"
        )
    check_dahl_oscillator(system, "exact_reversals")
    if system.u is not None:
        raise ValueError(
            "system must be unforced: exact_reversals covers the unforced system (2.1) only, got an oscillator "
            "with an input force u (allowed: system.u is None); use prefriction.simulate for forced motion"
        )
    sc = Scales.of(system)
    v0, x0, F0, n = check_initial_state(system, sc, v0, x0, F0, n)
    Fc, gamma = system.friction.Fc, system.friction.gamma
    if gamma >= 1.0 and v0 != 0.0 and F0 == math.copysign(Fc, v0):
        raise ValueError(
            f"F0 = {F0!r} N equals Fc in the direction of v0 = {v0!r} m/s: for gamma = {gamma!r} >= 1 the "
            "Dahl force reaches Fc only asymptotically, so this state stores infinite branch energy "
            "(allowed: |F0| < Fc, or F0 opposing v0)"
        )
    s0 = math.copysign(1.0, v0) if v0 != 0.0 else -math.copysign(1.0, F0)
    f0 = s0 * F0 / Fc
    vn = abs(v0) / sc.v
    if gamma == 0.0:
        t, dist, b, E0 = _prandtl_stop(f0, vn, n)
    else:
        t, dist, b, E0 = _general(f0, vn, n, gamma)
    # reversal k ends half-cycle k - 1, travelled in direction s0 (-1)^(k-1)
    signs = s0 * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    # running sums in extended precision: 1e4 half-cycles add no visible rounding
    x = x0 + _cumsum(signs * dist) * sc.x
    F = signs * b * Fc
    Ep = branch_potential(-b, gamma)
    Ed = np.empty(n)
    Ed[0] = E0 - Ep[0]
    Ed[1:] = Ep[:-1] - Ep[1:]
    if gamma == 0.0:
        # the stop dissipates only while sliding: exactly v1^2 / 2 = E0 - 1/2 in the first half-cycle
        Ed[0] = max(E0 - 0.5, 0.0)
    if not (np.all(np.isfinite(x)) and math.isfinite(E0 * sc.E)):
        raise ValueError(
            f"v0 = {v0!r} m/s and x0 = {x0!r} m carry the oscillator beyond the double-precision range "
            f"(first excursion {float(dist[0]) * sc.x:.6g} m, initial energy {E0 * sc.E:.6g} J); allowed: smaller |v0| or |x0|"
        )
    return ReversalTable(
        t=_cumsum(t) * sc.t, x=x, F=F, E_p=Ep * sc.E, E_d=Ed * sc.E, E_0=float(E0 * sc.E)
    )


def _cumsum(values: np.ndarray) -> np.ndarray:
    """Cumulative sum accumulated in ``numpy.longdouble``, rounded once to double."""
    return np.cumsum(values.astype(np.longdouble)).astype(float)


# --------------------------------------------------------------------------------------------
# gamma = 0: Prandtl stop, closed form
# --------------------------------------------------------------------------------------------


def _prandtl_stop(f0: float, v: float, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Half-cycle durations, distances, end forces and initial energy for ``gamma = 0``.

    Below saturation the branch is a unit spring: the state ``(f, v)`` turns clockwise at unit
    rate, so the time to the reversal is the angle ``atan2(v, f)``. If the energy exceeds
    ``1/2`` the force saturates at ``f = 1`` with speed ``v1 = sqrt(2E - 1)`` after the angle
    between ``(f0, v0)`` and ``(1, v1)``, then slides with unit deceleration for the time
    ``v1`` and the distance ``v1^2 / 2``. Every later half-cycle lasts ``pi``.
    """
    E0 = 0.5 * (f0 * f0 + v * v)
    t = np.full(n, math.pi)
    if E0 <= 0.5:
        b1 = math.hypot(f0, v)
        t[0] = math.atan2(v, f0)
        d1 = b1 - f0
    else:
        b1 = 1.0
        v1 = math.sqrt(v * v - (1.0 - f0) * (1.0 + f0))  # sqrt(2 E - 1)
        # angle between (1, v1) and (f0, v): cross = v - v1 f0 (= (1 - f0^2) 2E / (v + v1 f0)
        # without cancellation for f0 > 0), dot = f0 + v v1
        cross = v - v1 * f0 if f0 <= 0.0 else (1.0 - f0) * (1.0 + f0) * 2.0 * E0 / (v + v1 * f0)
        t[0] = math.atan2(cross, f0 + v * v1) + v1
        d1 = (1.0 - f0) + 0.5 * v1 * v1
    b = np.full(n, b1)
    dist = np.full(n, 2.0 * b1)
    dist[0] = d1
    return t, dist, b, E0


# --------------------------------------------------------------------------------------------
# gamma > 0
# --------------------------------------------------------------------------------------------


def _general(f0: float, v: float, n: int, gamma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Durations, distances, end forces of the ``n`` half-cycles and the initial energy, ``gamma > 0``."""
    KE0 = 0.5 * v * v
    E0 = KE0 + float(branch_potential(np.array(f0), gamma))
    t1, d1, b1 = _first_segment(f0, KE0, gamma)
    a = _amplitudes(b1, n, gamma)  # a[k] = |force| / Fc at reversal k + 1
    t = np.empty(n)
    dist = np.empty(n)
    t[0], dist[0] = t1, d1
    if n > 1:
        start, end = a[:-1], a[1:]
        regular = end <= _F_REGULAR
        idx = np.flatnonzero(regular) + 1
        for lo in range(0, idx.size, _CHUNK):
            sl = idx[lo : lo + _CHUNK]
            t[sl] = _time_unloading_from_rest(a[sl - 1], gamma) + _time_loading_to_rest(a[sl], gamma)
        dist[1:] = branch_distance(-start, end, gamma)
        for k in np.flatnonzero(~regular) + 1:  # large half-cycles (small gamma only): panels
            tk, _, _ = _first_segment(-a[k - 1], 0.0, gamma)
            t[k] = tk
    return t, dist, a, E0


def _amplitudes(b1: float, n: int, gamma: float) -> np.ndarray:
    """Reversal amplitudes ``b_1, ..., b_n``: ``b_{k+1}`` solves ``H(b_{k+1}) = H(-b_k)``."""
    if gamma == 1.0:
        return dahl.amplitude_sequence(b1, n - 1)
    out = np.empty(n)
    out[0] = b1
    coef, a_max = _map_series(gamma)
    series = coef[::-1]
    a = b1
    for k in range(1, n):
        if a > a_max:
            a = float(loading_end_for_energy(branch_potential(np.array(-a), gamma), gamma).f)
        else:
            acc = 0.0
            for c in series:
                acc = acc * a + c
            a = a * acc
        out[k] = a
    return out


@lru_cache(maxsize=32)
def _map_series(gamma: float, terms: int = 48) -> tuple[tuple[float, ...], float]:
    """Taylor coefficients of the reversal map ``a -> b``, ``H(b) = H(-a)``, and where to use them.

    ``H(f) = sum_{k>=2} h_k f^k`` with ``h_k = (gamma)_{k-2} / ((k-2)! k)``; the coefficient
    ``beta_k`` of ``b = a + beta_2 a^2 + ...`` is fixed by order ``k + 1`` (``h_2 = 1/2``).
    Returns ``(beta_1 .. beta_terms)`` and the largest ``a`` (at most 0.2) for which the
    truncated tail is below 1e-18 relative.
    """
    N = terms + 1
    h = np.zeros(N + 1)
    c = 1.0
    for j in range(N - 1):  # h[k] for k = 2 .. N
        h[j + 2] = c / (j + 2)
        c *= (gamma + j) / (j + 1)
    target = h * (-1.0) ** np.arange(N + 1)  # H(-a)
    beta = np.zeros(N + 1)
    beta[1] = 1.0
    for k in range(2, N):
        comp = np.zeros(N + 1)
        power = beta.copy()  # b^1
        for j in range(2, N + 1):
            power = np.convolve(power, beta)[: N + 1]
            comp += h[j] * power
        beta[k] = target[k + 1] - comp[k + 1]
    coef = tuple(float(x) for x in beta[1:N])
    tail = max(abs(coef[-1]), abs(coef[-2]), 1e-300)
    a_max = min(0.2, (1e-18 / tail) ** (1.0 / (len(coef) - 1)))
    return coef, a_max


def _powg(w: np.ndarray, gamma: float) -> np.ndarray:
    """``w^-gamma`` for ``w > 0`` (cheap forms for gamma = 1/2, 1, 2)."""
    if gamma == 1.0:
        return 1.0 / w
    if gamma == 2.0:
        return 1.0 / (w * w)
    if gamma == 0.5:
        return 1.0 / np.sqrt(w)
    return np.exp(-gamma * np.log(w))


def _time_unloading_from_rest(a: np.ndarray, gamma: float) -> np.ndarray:
    """Time from rest at ``f = -a`` to the force zero crossing (normalised), vectorised.

    With ``f = -a + a s``, ``s = u^2``: the kinetic energy is ``a^2 s kappa(s)``,
    ``kappa(s) = int_0^1 (1 - s tau) (1 + a (1 - s tau))^-gamma dtau``, and
    ``T = int_0^1 2 du / ((1 + a (1 - u^2))^gamma sqrt(2 kappa(u^2)))``: smooth integrands,
    positive terms only (``pi / 2`` as ``a -> 0``).
    """
    u, wu = gauss_legendre_01(_N_REG)
    tau, wt = gauss_legendre_01(_N_REG)
    s = u * u
    A = a[:, None, None]
    st = s[None, :, None] * tau[None, None, :]
    kappa = ((1.0 - st) * _powg(1.0 + A * (1.0 - st), gamma)) @ wt
    w = 1.0 + a[:, None] * (1.0 - s[None, :])
    return (2.0 * _powg(w, gamma) / np.sqrt(2.0 * kappa)) @ wu


def _time_loading_to_rest(b: np.ndarray, gamma: float) -> np.ndarray:
    """Time from the force zero crossing to rest at ``f = b <= 0.75`` (normalised), vectorised.

    With ``f = b (1 - s)``, ``s = u^2``: the kinetic energy is ``b^2 s kappa(s)``,
    ``kappa(s) = int_0^1 (1 - s tau)(1 - b + b s tau)^-gamma dtau`` and
    ``T = int_0^1 2 du / ((1 - b + b u^2)^gamma sqrt(2 kappa(u^2)))``.
    """
    u, wu = gauss_legendre_01(_N_REG)
    tau, wt = gauss_legendre_01(_N_REG)
    s = u * u
    B = b[:, None, None]
    st = s[None, :, None] * tau[None, None, :]
    kappa = ((1.0 - st) * _powg(1.0 - B + B * st, gamma)) @ wt
    w = 1.0 - b[:, None] + b[:, None] * s[None, :]
    return (2.0 * _powg(w, gamma) / np.sqrt(2.0 * kappa)) @ wu


# --------------------------------------------------------------------------------------------
# one half-cycle from an arbitrary state (first excursion, gross sliding): graded panels
# --------------------------------------------------------------------------------------------


def _first_segment(f0: float, KE0: float, gamma: float) -> tuple[float, float, float]:
    """Duration, distance and end force of the half-cycle from force ``f0`` with kinetic energy ``KE0``."""
    if f0 == 1.0:  # saturated (gamma < 1): Coulomb slide at unit deceleration
        return math.sqrt(2.0 * KE0), KE0, 1.0
    t = 0.0
    d = 0.0
    if f0 < 0.0:
        t += _time_unloading(-f0, KE0, gamma)
        d += float(branch_distance(np.array(f0), np.array(0.0), gamma))
        L_s, K_s = 0.0, KE0 + float(branch_potential(np.array(f0), gamma))
    else:
        L_s, K_s = float(log_gap(np.array(f0))), KE0
    tl, dl, b = _loading(L_s, K_s, gamma)
    return t + tl, d + dl, b


def _graded_panels(length: float, first: float, both: bool) -> np.ndarray:
    """Panel edges on ``[0, length]``, geometric (ratio 2) from ``first`` towards the far end.

    With ``both`` the grading is symmetric (finest at both ends).
    """
    if not both:
        edges = [0.0]
        h = min(first, length)
        while h < length:
            edges.append(h)
            h *= 2.0
        edges.append(length)
        return np.array(edges)
    half = 0.5 * length
    left = _graded_panels(half, first, False)
    return np.concatenate([left, length - left[-2::-1]])


def _panel_rule(edges: np.ndarray, singular_first: bool) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of composite Gauss-Legendre on ``edges``; on the first panel
    ``x = h u^2`` (weight ``2 h u``) removes a ``1/sqrt(x)`` singularity at 0."""
    u, wu = gauss_legendre_01(_N)
    lo, hi = edges[:-1, None], edges[1:, None]
    x = lo + (hi - lo) * u[None, :]
    w = (hi - lo) * wu[None, :]
    if singular_first:
        h = edges[1]
        x[0] = h * u * u
        w[0] = 2.0 * h * u * wu
    return x.ravel(), w.ravel()


def _time_unloading(a: float, K_s: float, gamma: float) -> float:
    """Time from force ``-a`` with kinetic energy ``K_s`` to the zero crossing.

    ``f = -a + a u^2``: ``T = int_0^1 2 a u du / (w^gamma sqrt(2 (K_s + a^2 u^2 kappa(u^2))))``,
    on panels graded towards ``u = 0`` down to the width ``sqrt(K_s) / a`` of the start layer.
    """
    if a == 0.0:
        return 0.0
    first = 0.5 if K_s == 0.0 else min(0.5, max(math.sqrt(K_s) / a / 4.0, 2.0**-60))
    edges = _graded_panels(1.0, first, False)
    u, wu = _panel_rule(edges, singular_first=False)
    tau, wt = gauss_legendre_01(_N)
    s = u * u
    st = s[:, None] * tau[None, :]
    kappa = ((1.0 - st) * _powg(1.0 + a * (1.0 - st), gamma)) @ wt
    w = 1.0 + a * (1.0 - s)
    if K_s == 0.0:  # from rest: 2 a u / sqrt(2 a^2 u^2 kappa) = 2 / sqrt(2 kappa)
        return float(np.sum(wu * 2.0 * _powg(w, gamma) / np.sqrt(2.0 * kappa)))
    au = a * u
    return float(np.sum(wu * 2.0 * au * _powg(w, gamma) / np.sqrt(2.0 * (K_s + au * au * kappa))))


def _stored(L: np.ndarray, D: np.ndarray, gamma: float) -> np.ndarray:
    """``int_L^{L + D} (1 - e^{-l}) e^{(gamma - 1) l} dl``: energy stored along the loading side.

    Above ``l = 1`` in closed form (two terms differing by a factor >= e), below by
    Gauss-Legendre on a positive integrand: no cancellation, ``D`` may be ``inf``.
    """
    c = gamma - 1.0
    L = np.asarray(L, dtype=float)
    D = np.asarray(D, dtype=float)
    top = L + D
    lo_hi = np.maximum(L, 1.0)
    span_hi = np.where(L >= 1.0, D, np.maximum(top - 1.0, 0.0))
    with np.errstate(over="ignore", invalid="ignore"):
        hi = np.exp(c * lo_hi) * int_exp(c, span_hi) - np.exp((c - 1.0) * lo_hi) * int_exp(c - 1.0, span_hi)
    hi = np.where(span_hi > 0.0, hi, 0.0)
    span_lo = np.where(L < 1.0, np.where(top <= 1.0, D, 1.0 - L), 0.0)  # D itself: no rounding
    x, wx = gauss_legendre_01(_N)
    ell = L[..., None] + span_lo[..., None] * x
    lo = span_lo * ((-np.expm1(-ell) * np.exp(c * ell)) @ wx)
    return hi + lo


def _loading(L_s: float, K_s: float, gamma: float) -> tuple[float, float, float]:
    """Time, distance and end force from log-gap ``L_s`` with kinetic energy ``K_s`` to rest."""
    c = gamma - 1.0
    if K_s == 0.0:
        return 0.0, 0.0, float(-np.expm1(-L_s))
    if gamma < 1.0:
        K_sat = float(_stored(np.array(L_s), np.array(np.inf), gamma))
        if K_s >= K_sat:
            return _loading_saturated(L_s, K_s - K_sat, gamma)
    span = _span_for_energy(L_s, K_s, gamma)
    first = min(0.25 * span, 1.0 / max(1.0, abs(c)))
    edges = _graded_panels(span, first, True)
    D, wD = _panel_rule(edges, singular_first=True)  # D: log-gap distance to the end
    L = np.where(D < 0.5 * span, (L_s + span) - D, L_s + (span - D))
    K = _stored(L, D, gamma)
    t = float(np.sum(wD * np.exp(c * L) / np.sqrt(2.0 * K)))
    dist = float(math.exp(c * L_s) * int_exp(c, np.array(span)))
    return t, dist, float(-np.expm1(-(L_s + span)))


def _span_for_energy(L_s: float, K_s: float, gamma: float) -> float:
    """Log-gap span ``D`` with ``_stored(L_s, D) = K_s`` (safeguarded Newton)."""
    c = gamma - 1.0
    if L_s == 0.0:
        return float(loading_end_for_energy(np.array(K_s), gamma).L)
    E = float(potential_of_log_gap(np.array(L_s), gamma)) + K_s
    guess = float(loading_end_for_energy(np.array(E), gamma).L) - L_s
    slope_s = -math.expm1(-L_s) * math.exp(c * L_s)
    D = guess if guess > 0.0 and guess > 1e-3 * abs(L_s) else K_s / slope_s
    lo, hi = 0.0, math.inf
    for _ in range(100):
        r = float(_stored(np.array(L_s), np.array(D), gamma)) - K_s
        if r > 0:
            hi = D
        else:
            lo = D
        top = L_s + D
        step = r / (-math.expm1(-top) * math.exp(c * top))
        Dn = D - step
        if not lo < Dn < hi:
            Dn = 0.5 * (lo + hi) if math.isfinite(hi) else 2.0 * max(D, lo)
        if abs(Dn - D) <= 1e-16 * Dn:
            return Dn
        D = Dn
    return D


def _loading_saturated(L_s: float, S: float, gamma: float) -> tuple[float, float, float]:
    """``gamma < 1``: from log-gap ``L_s`` to saturation, then a Coulomb slide of length ``S``.

    In the distance ``z`` before saturation, ``w = ((1 - gamma) z)^(1/(1 - gamma))`` and the
    kinetic energy is ``K = S + z (1 - (1 - gamma) w / (2 - gamma))`` (no cancellation); the
    slide at unit deceleration lasts ``sqrt(2 S)``.
    """
    p = 1.0 / (1.0 - gamma)
    z_s = math.exp(-(1.0 - gamma) * L_s) / (1.0 - gamma)
    edges = _graded_panels(z_s, z_s * 2.0**-60, False)
    z, wz = _panel_rule(edges, singular_first=True)
    w = ((1.0 - gamma) * z) ** p
    K = S + z * (1.0 - (1.0 - gamma) * w / (2.0 - gamma))
    t = float(np.sum(wz / np.sqrt(2.0 * K))) + math.sqrt(2.0 * S)
    return t, z_s + S, 1.0

