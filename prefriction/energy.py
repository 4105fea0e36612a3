"""Energy analysis of pre-sliding trajectories (paper section 2, (2.3)-(2.12)).

Works on any trajectory, given either as dense samples ``(t, x, v, F)`` in SI units or as
the states at the velocity reversals (a :class:`prefriction.ReversalTable`).

Building blocks (model-free unless said otherwise):

- :func:`find_reversals`: velocity reversals ``x'(t_i) = 0`` located between samples;
- :func:`kinetic_energy`, :func:`integrated_power` (2.8, time form), :func:`work_integral`
  (2.8, displacement form);
- :func:`loop_integral`: dissipation ``oint F dx`` of a closed hysteresis cycle (2.5)/(2.7);
  zero for a linear spring (2.6);
- :func:`branch_energy`, :func:`total_energy` (Dahl model): energy stored on a branch relative
  to its force zero crossing, (3.9) for ``gamma = 1``;
- :func:`dissipation` (2.10), :func:`series` (2.11), :func:`bound_check` (2.12);
- :func:`analyze_samples`, :func:`analyze_table`: all of it at once, as an :class:`EnergyReport`.

Conventions (as in :class:`prefriction.ReversalTable`): reversal ``k`` ends half-cycle ``k - 1`` and starts
half-cycle ``k``; ``E_p[k]`` is the potential energy at reversal ``k``, i.e. the energy the new
branch returns as kinetic energy until its force zero crossing; ``E_d[k]`` (this module) is
the energy dissipated in the half-cycle from reversal ``k`` to reversal ``k + 1``, which is the
paper's ``E_d(i)`` in (2.10). :class:`prefriction.ReversalTable` indexes ``E_d`` by the
half-cycle that *ends* at a reversal instead: ``table.E_d[k + 1]`` is ``E_d[k]`` here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from scipy.integrate import cumulative_simpson, cumulative_trapezoid

from ._branch import branch_potential
from ._validation import check_positive
from .models import Dahl, Oscillator
from .reversals import ReversalTable

__all__ = [
    "BoundCheck",
    "EnergyReport",
    "SampledReversals",
    "analyze_samples",
    "analyze_table",
    "bound_check",
    "branch_energy",
    "dissipation",
    "find_reversals",
    "integrated_power",
    "kinetic_energy",
    "loop_integral",
    "series",
    "total_energy",
    "work_integral",
]

_METHODS = ("trapezoid", "simpson")
_ROUNDING = 64 * np.finfo(float).eps


# --------------------------------------------------------------------------- validation


def _sample_array(name: str, values: Any) -> np.ndarray:
    """Return ``values`` as a finite 1-D float array of length >= 2, or raise naming ``name``."""
    if isinstance(values, (str, bytes)) or values is None:
        raise TypeError(f"{name} must be a 1-D array of real numbers, got {values!r}")
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a 1-D array of real numbers, got {values!r}") from exc
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got an array of shape {arr.shape}")
    if arr.size < 2:
        raise ValueError(f"{name} must hold at least 2 samples, got {arr.size}")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} must be finite, got {name}[{i}] = {float(arr[i])!r} (allowed: finite reals)")
    return arr


def _samples(**arrays: Any) -> list[np.ndarray]:
    """Validate sample arrays: the first is time (strictly increasing), all of equal length."""
    names = list(arrays)
    out = [_sample_array(name, arrays[name]) for name in names]
    n = out[0].size
    for name, arr in zip(names[1:], out[1:]):
        if arr.size != n:
            raise ValueError(
                f"{name} has length {arr.size} but {names[0]} has length {n} "
                "(all sample arrays must have the same length)"
            )
    if names[0] == "t":
        dt = np.diff(out[0])
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ValueError(
                f"t must be strictly increasing, got t[{i + 1}] = {float(out[0][i + 1])!r} <= t[{i}] = {float(out[0][i])!r}"
            )
    return out


def _check_method(method: Any) -> str:
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
    return method


def _check_dahl(system: Any) -> tuple[Dahl, float]:
    """Return the Dahl friction model and the mass of ``system``; ``TypeError`` otherwise."""
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
    if not isinstance(system.friction, Dahl):
        raise TypeError(
            "system.friction must be a prefriction.Dahl model (the branch potential is known for Dahl only), "
            f"got {system.friction!r}"
        )
    return system.friction, system.mass


def _check_friction(friction: Any) -> Dahl:
    if not isinstance(friction, Dahl):
        raise TypeError(f"friction must be a prefriction.Dahl model, got {friction!r} of type {type(friction).__name__}")
    return friction


# --------------------------------------------------------------------------- reversals


@dataclass(frozen=True, eq=False)
class SampledReversals:
    """Velocity reversals located in a sampled trajectory.

    Attributes
    ----------
    t : numpy.ndarray
        Reversal times [s].
    x : numpy.ndarray or None
        Positions at the reversals [m] (``None`` if no positions were given).
    F : numpy.ndarray or None
        Friction forces at the reversals [N] (``None`` if no forces were given).
    direction : numpy.ndarray
        Sign of the velocity after each reversal, +1 or -1 (int).
    index : numpy.ndarray
        Index ``i`` of the last sample before each reversal, ``t[i] < t_rev <= t[i + 1]``
        (int). Samples ``index[k] + 1 .. index[k + 1]`` belong to half-cycle ``k``.
    initial_direction : int
        Sign of the first non-zero velocity sample (+1 or -1), the direction of the first
        excursion; 0 if every velocity sample is zero.
    """

    t: np.ndarray
    x: Optional[np.ndarray]
    F: Optional[np.ndarray]
    direction: np.ndarray
    index: np.ndarray
    initial_direction: int

    def __len__(self) -> int:
        return len(self.t)


def _hermite_root(h: np.ndarray, dx: np.ndarray, va: np.ndarray, vb: np.ndarray) -> np.ndarray:
    """Root ``s`` in [0, 1] of the derivative of the cubic Hermite interpolant of x.

    On an interval of length ``h`` with end velocities ``va``, ``vb`` of opposite signs and
    displacement ``dx``, the velocity of the interpolant is the quadratic
    ``q(s) = 6 s (1 - s) dx/h + (3 s^2 - 4 s + 1) va + (3 s^2 - 2 s) vb``, with ``q(0) = va``
    and ``q(1) = vb``; it has exactly one root in (0, 1), found by bisection.
    """
    d = dx / h
    lo = np.zeros_like(va)
    hi = np.ones_like(va)
    sa = np.sign(va)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        q = 6.0 * mid * (1.0 - mid) * d + (3.0 * mid * mid - 4.0 * mid + 1.0) * va + (3.0 * mid * mid - 2.0 * mid) * vb
        same = np.sign(q) == sa
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


def find_reversals(t: Any, v: Any, *, x: Any = None, F: Any = None) -> SampledReversals:
    """Locate the velocity reversals (sign changes of ``v``) of a sampled trajectory.

    A reversal is a change of sign between two consecutive *non-zero* velocity samples, so a
    velocity that touches zero (or rests at zero) without changing sign is not a reversal,
    and a reversal that lands exactly on zero samples is counted once (at the first zero
    sample). A sign change between two samples is located by interpolation: with positions,
    as the root of the velocity of the cubic Hermite interpolant of ``x`` (third order);
    without, linearly in ``v``. The position there is the Hermite interpolant; the force is
    extrapolated along the incoming branch linearly in ``x`` (``F`` is a function of ``x`` on
    a branch, so this is accurate to second order in the step); linearly in ``t`` when the
    incoming branch has a single sample or no positions are given.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    v : array_like
        Velocities [m/s], length N.
    x : array_like, optional
        Positions [m], length N.
    F : array_like, optional
        Friction forces [N], length N.

    Returns
    -------
    SampledReversals
        Reversal times, positions, forces, direction after each reversal and the index of
        the sample before it.

    Raises
    ------
    ValueError
        Arrays of unequal length, shorter than 2, not finite, not 1-D, or ``t`` not strictly
        increasing.
    """
    named = {"t": t, "v": v}
    if x is not None:
        named["x"] = x
    if F is not None:
        named["F"] = F
    arrays = dict(zip(named, _samples(**named)))
    t, v = arrays["t"], arrays["v"]
    xs, Fs = arrays.get("x"), arrays.get("F")

    sgn = np.sign(v).astype(int)
    nz = np.flatnonzero(sgn)
    initial = int(sgn[nz[0]]) if nz.size else 0
    a, b = nz[:-1], nz[1:]
    flip = sgn[a] != sgn[b]
    a, b = a[flip], b[flip]
    direction = sgn[b]
    on_zero = b > a + 1  # zero samples between: the reversal is the first of them
    t_r = np.empty(a.size)
    x_r = None if xs is None else np.empty(a.size)
    F_r = None if Fs is None else np.empty(a.size)

    z = a[on_zero] + 1
    t_r[on_zero] = t[z]
    if xs is not None:
        x_r[on_zero] = xs[z]
    if Fs is not None:
        F_r[on_zero] = Fs[z]

    ia = a[~on_zero]
    ib = ia + 1
    h = t[ib] - t[ia]
    if xs is not None:
        s = _hermite_root(h, xs[ib] - xs[ia], v[ia], v[ib])
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        x_r[~on_zero] = h00 * xs[ia] + h10 * h * v[ia] + h01 * xs[ib] + h11 * h * v[ib]
    else:
        s = v[ia] / (v[ia] - v[ib])
    t_r[~on_zero] = t[ia] + s * h
    if Fs is not None:
        Fi = Fs[ia] + s * (Fs[ib] - Fs[ia])
        if xs is not None:
            prev = ia - 1
            ok = prev >= 0
            ok[ok] &= ((sgn[prev[ok]] == sgn[ia[ok]]) | (sgn[prev[ok]] == 0)) & (xs[prev[ok]] != xs[ia[ok]])
            p, q = prev[ok], ia[ok]
            slope = (Fs[q] - Fs[p]) / (xs[q] - xs[p])
            Fi[ok] = Fs[q] + slope * (x_r[~on_zero][ok] - xs[q])
        F_r[~on_zero] = Fi
    return SampledReversals(t=t_r, x=x_r, F=F_r, direction=direction, index=a, initial_direction=initial)


# --------------------------------------------------------------------------- energies along samples


def kinetic_energy(v: Any, *, mass: float) -> np.ndarray:
    """Kinetic energy ``E_k = m v^2 / 2`` [J], the first term of (2.3).

    Parameters
    ----------
    v : array_like
        Velocities [m/s].
    mass : float
        Moving mass [kg], ``0 < mass < inf``.

    Returns
    -------
    numpy.ndarray
        ``E_k`` [J], same shape as ``v``.
    """
    m = check_positive("mass", mass)
    v = np.asarray(v, dtype=float)
    return 0.5 * m * v * v


def _cumulative(t: np.ndarray, y: np.ndarray, method: str) -> np.ndarray:
    if method == "simpson" and t.size >= 3:
        return cumulative_simpson(y, x=t, initial=0.0)
    return cumulative_trapezoid(y, t, initial=0.0)


def integrated_power(
    t: Any, v: Any, F: Any, *, method: str = "trapezoid", reset_at_reversals: bool = False
) -> np.ndarray:
    """Restoring-force energy by integrated power, ``E_f(t) = int F v dt`` [J] (2.8).

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing.
    v : array_like
        Velocities [m/s].
    F : array_like
        Friction (restoring) forces [N].
    method : {"trapezoid", "simpson"}
        Cumulative trapezoid rule, or cumulative Simpson rule (scipy, any sample spacing).
    reset_at_reversals : bool, default False
        If False, integrate from ``t[0]``. If True, restart at every velocity reversal
        (located by :func:`find_reversals`), so that ``E_f`` is the energy of (2.3)
        counted from the last reversal; for unforced motion ``E_k + E_f = E_k(t[0])``
        before the first reversal and ``E_k + E_f = 0`` after it.

    Returns
    -------
    numpy.ndarray
        ``E_f`` at every sample [J], 0 at ``t[0]`` (and at each reversal if reset).
    """
    method = _check_method(method)
    t, v, F = _samples(t=t, v=v, F=F)
    p = F * v
    if not reset_at_reversals:
        return _cumulative(t, p, method)
    rev = find_reversals(t, v)
    out = np.empty_like(p)
    starts = np.concatenate(([0], rev.index + 1, [t.size]))
    for k in range(starts.size - 1):
        lo, hi = int(starts[k]), int(starts[k + 1])
        if hi <= lo:
            continue
        base = 0.0 if k == 0 else 0.5 * p[lo] * (t[lo] - rev.t[k - 1])
        out[lo:hi] = base + _cumulative(t[lo:hi], p[lo:hi], method)
    return out


def work_integral(x: Any, F: Any) -> np.ndarray:
    """Restoring-force energy along the path, ``E_f = int F dx`` [J] (2.8, displacement form).

    Cumulative trapezoid rule over the samples in their order (the path may reverse).

    Parameters
    ----------
    x : array_like
        Positions [m], in path order.
    F : array_like
        Forces [N] at those positions.

    Returns
    -------
    numpy.ndarray
        ``int_{x[0]}^{x[j]} F dx`` along the path for every sample ``j`` [J].
    """
    x, F = _samples(x=x, F=F)
    return np.concatenate(([0.0], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(x))))


def loop_integral(x: Any, F: Any, *, closure_tol: float = 1e-6) -> float:
    """Energy dissipated on a closed hysteresis cycle, ``E_d(C) = oint_C F dx`` [J] (2.5)/(2.7).

    The path ``(x[j], F[j])`` must return to its start (cycle ``C = (x_i, x_{i+1}, x_{i+2})``
    with ``x_{i+2} = x_i``). The integral is the trapezoid rule over the closed polygon, i.e.
    the shoelace formula: the enclosed area, positive for a clockwise loop in the ``(x, F)``
    plane (ascending branch above the descending one, (2.7)), zero for any single-valued
    (memory-free) force such as the linear spring of (2.6).

    Parameters
    ----------
    x : array_like
        Positions [m] along the cycle, length >= 3.
    F : array_like
        Forces [N] along the cycle.
    closure_tol : float, default 1e-6
        Allowed gap between the first and last point, relative to the ranges of ``x`` and
        ``F`` over the cycle, ``0 <= closure_tol < inf``.

    Returns
    -------
    float
        ``oint F dx`` [J]; the closing chord from the last point to the first is included.

    Raises
    ------
    ValueError
        If the path is not closed within ``closure_tol`` (the message gives the gap), or
        the arrays are invalid.
    """
    x, F = _samples(x=x, F=F)
    tol = float(closure_tol)
    if not (math.isfinite(tol) and tol >= 0.0):
        raise ValueError(f"closure_tol must be finite and >= 0, got {closure_tol!r} (allowed range: 0 <= closure_tol < inf)")
    if x.size < 3:
        raise ValueError(f"a closed cycle needs at least 3 points, got {x.size}")
    span_x = float(np.ptp(x))
    span_F = float(np.ptp(F))
    gap_x = abs(x[-1] - x[0])
    gap_F = abs(F[-1] - F[0])
    if gap_x > tol * span_x or gap_F > tol * span_F:
        raise ValueError(
            f"the cycle is not closed: |x[-1] - x[0]| = {gap_x:.3g} m (range {span_x:.3g} m), "
            f"|F[-1] - F[0]| = {gap_F:.3g} N (range {span_F:.3g} N), allowed relative gap "
            f"closure_tol = {tol:g}; pass one full cycle C = (x_i, x_i+1, x_i+2 = x_i)"
        )
    xc = np.append(x, x[0])
    Fc = np.append(F, F[0])
    return float(np.sum(0.5 * (Fc[1:] + Fc[:-1]) * np.diff(xc)))


def branch_energy(F: Any, direction: Any, *, friction: Dahl) -> np.ndarray:
    """Energy stored on a Dahl branch relative to its force zero crossing [J].

    ``E = (Fc^2 / sigma) H_gamma(s F / Fc)`` with ``H_gamma(f) = int_0^f phi (1 - phi)^-gamma dphi``
    and ``s`` the direction of motion on the branch. At a reversal, with ``s`` the *new*
    direction, this is the potential energy ``E_p`` of the paper, (3.9) for ``gamma = 1``:
    ``(Fc^2/sigma) (a - ln(1 + a))`` with ``a = |F_i| / Fc``.

    Parameters
    ----------
    F : array_like
        Friction forces [N], ``|F| <= Fc``.
    direction : array_like
        Direction of motion on the branch, +1 or -1 (broadcast against ``F``).
    friction : Dahl
        The friction model (``sigma`` [N/m], ``Fc`` [N], ``gamma``).

    Returns
    -------
    numpy.ndarray
        Stored energy [J], >= 0.
    """
    friction = _check_friction(friction)
    F = np.asarray(F, dtype=float)
    s = np.asarray(direction, dtype=float)
    if not np.all(np.abs(s) == 1.0):
        bad = s[np.abs(s) != 1.0].flat[0]
        raise ValueError(f"direction must be +1 or -1 (every entry), got {float(bad)!r}")
    Fc = friction.Fc
    if np.any(~(np.abs(F) <= Fc * (1.0 + _ROUNDING))):
        bad = F[~(np.abs(F) <= Fc * (1.0 + _ROUNDING))].flat[0]
        raise ValueError(f"F must lie in [-Fc, Fc] = [{-Fc!r}, {Fc!r}] (every entry), got {float(bad)!r}")
    f = np.clip(s * F / Fc, -1.0, 1.0)
    return (Fc * Fc / friction.sigma) * np.asarray(branch_potential(f, friction.gamma), dtype=float)


def _sample_directions(v: np.ndarray) -> np.ndarray:
    """Branch direction at every sample: sign of v; a zero takes the next non-zero sign."""
    sgn = np.sign(v)
    nz = np.flatnonzero(sgn)
    if nz.size == 0:
        raise ValueError("v is zero at every sample: nothing moves, no branch direction is defined")
    nxt = np.minimum(np.searchsorted(nz, np.arange(v.size)), nz.size - 1)
    return sgn[nz[nxt]]


def total_energy(t: Any, v: Any, F: Any, *, system: Oscillator) -> np.ndarray:
    """Mechanical energy ``E_k + E_branch`` of a Dahl oscillator at every sample [J].

    ``E_branch`` is :func:`branch_energy` with the direction of motion (a sample with
    ``v = 0`` belongs to the branch that follows it). Unforced (2.1), this is constant
    along each branch and drops by the half-cycle dissipation ``E_d`` (2.10) at each
    reversal; right after reversal ``k`` it equals ``E_p[k]``. Its drift along a branch
    measures the energy error of a simulation.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing.
    v : array_like
        Velocities [m/s].
    F : array_like
        Friction forces [N].
    system : Oscillator
        The oscillator (mass and Dahl friction model).

    Returns
    -------
    numpy.ndarray
        ``E_k + E_branch`` at every sample [J]. For ``gamma >= 1`` it is infinite where a
        sample has ``s F = Fc`` exactly (deep gross sliding rounds the force to ``Fc``).

    Raises
    ------
    ValueError
        Invalid arrays, ``|F| > Fc``, or ``v = 0`` at every sample (no direction).
    """
    friction, mass = _check_dahl(system)
    t, v, F = _samples(t=t, v=v, F=F)
    return kinetic_energy(v, mass=mass) + branch_energy(F, _sample_directions(v), friction=friction)


# --------------------------------------------------------------------------- energies at reversals


def dissipation(E_p: Any, *, input_work: Any = None) -> np.ndarray:
    """Energy dissipated in each half-cycle between reversals [J] (2.10).

    ``E_d[k] = E_p[k] - E_p[k + 1]`` (+ ``input_work[k]``, the work of an external force over
    the half-cycle, for forced motion).

    Parameters
    ----------
    E_p : array_like
        Potential energy at consecutive reversals [J], length n >= 1.
    input_work : array_like, optional
        Work of the external force in each half-cycle [J], length n - 1.

    Returns
    -------
    numpy.ndarray
        Length n - 1.
    """
    E_p = np.asarray(E_p, dtype=float)
    if E_p.ndim != 1:
        raise ValueError(f"E_p must be a 1-D array, got shape {E_p.shape}")
    E_d = E_p[:-1] - E_p[1:]
    if input_work is not None:
        w = np.asarray(input_work, dtype=float)
        if w.shape != E_d.shape:
            raise ValueError(f"input_work has shape {w.shape}, expected {E_d.shape} (one value per half-cycle)")
        E_d = E_d + w
    return E_d


def series(E_p: Any, E_d: Any) -> tuple[np.ndarray, np.ndarray]:
    """Partial sums of the dissipation series (2.11), ``E_p(i) = sum_{n >= i} E_d(n)``.

    With n reversals the data hold ``E_d(i)`` for ``i < n - 1`` only, so the series is
    truncated: ``S[i] = sum_{j=i}^{n-2} E_d[j]`` and the remainder ``R[i] = E_p[i] - S[i]``
    is the part of the series not yet dissipated. If (2.10) holds, ``R[i] = E_p[n-1]`` for
    every ``i`` (to rounding), and (2.11) states ``R -> 0`` as more reversals are added.

    Parameters
    ----------
    E_p : array_like
        Potential energy at the reversals [J], length n.
    E_d : array_like
        Dissipation per half-cycle [J], length n - 1 (``E_d[k]`` from reversal k to k + 1).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Partial sums ``S`` and remainders ``R``, each of length n [J].
    """
    E_p = np.asarray(E_p, dtype=float)
    E_d = np.asarray(E_d, dtype=float)
    if E_d.shape != (E_p.size - 1,) or E_p.ndim != 1:
        raise ValueError(f"E_d must have length len(E_p) - 1 = {E_p.size - 1}, got shape {E_d.shape}")
    S = np.concatenate((np.cumsum(E_d[::-1])[::-1], [0.0]))
    return S, E_p - S


@dataclass(frozen=True)
class BoundCheck:
    """How far the potential energy at the reversals stays below the bound (2.12).

    Attributes
    ----------
    bound : float
        The paper's bound ``Fc^2 / (2 k_min)`` [J] with ``k_min = sigma``, the least tangent
        stiffness of the Dahl model on an unloading branch (any ``gamma >= 0``).
    bound_sharp : float
        The least upper bound for this ``gamma``, ``(Fc^2/sigma) H_gamma(-1)`` [J]
        (``(1 - ln 2) Fc^2/sigma`` for ``gamma = 1``; equal to ``bound`` for ``gamma = 0``).
    max_E_p : float
        Largest potential energy at a reversal [J].
    index : int
        Reversal at which it occurs.
    ratio : float
        ``max_E_p / bound`` (<= 1 when (2.12) holds).
    margin : float
        ``bound - max_E_p`` [J] (>= 0 when (2.12) holds).
    ratio_sharp : float
        ``max_E_p / bound_sharp``.
    holds : bool
        ``max_E_p <= bound`` up to rounding. (2.12) is stated strictly; equality is reached
        by ``gamma = 0`` after saturation, see ``strict``.
    strict : bool
        ``max_E_p < bound``.
    holds_sharp : bool
        ``max_E_p <= bound_sharp`` up to rounding.
    E_0 : float or None
        Energy of the initial state [J], if known. The first excursion from the initial
        velocity is not bounded by (2.12) (gross sliding), so it is reported, not checked.
    initial_ratio : float or None
        ``E_0 / bound``; > 1 means the first excursion starts in gross sliding.
    """

    bound: float
    bound_sharp: float
    max_E_p: float
    index: int
    ratio: float
    margin: float
    ratio_sharp: float
    holds: bool
    strict: bool
    holds_sharp: bool
    E_0: Optional[float]
    initial_ratio: Optional[float]

    def format(self) -> str:
        """Readable summary of the check, one line per bound."""
        lines = [
            f"(2.12) E_p <= Fc^2/(2 sigma) = {self.bound:.6e} J: "
            f"{'holds' if self.holds else 'VIOLATED'}{'' if self.strict or not self.holds else ' (with equality)'}, "
            f"max E_p = {self.max_E_p:.6e} J at reversal {self.index + 1}, ratio {self.ratio:.6f}, margin {self.margin:.3e} J",
            f"sharp bound (Fc^2/sigma) H_gamma(-1) = {self.bound_sharp:.6e} J: "
            f"{'holds' if self.holds_sharp else 'VIOLATED'}, ratio {self.ratio_sharp:.6f}",
        ]
        if self.E_0 is not None:
            note = "gross sliding in the first excursion, not covered by (2.12)" if self.initial_ratio > 1 else "within the bound"
            lines.append(f"initial energy E_0 = {self.E_0:.6e} J = {self.initial_ratio:.4g} x bound ({note})")
        return "\n".join(lines)


def bound_check(E_p: Any, *, friction: Dahl, E_0: Optional[float] = None) -> BoundCheck:
    """Check the bound (2.12) ``E_p(i) < Fc^2 / (2 k_min)`` and report by how much it holds.

    For the Dahl model (3.2) with ``gamma >= 0`` the tangent stiffness on an unloading branch
    (``s F <= 0``) is ``sigma (1 - f)^gamma >= sigma``, so ``k_min = sigma``. The sharp bound
    is the potential energy of a reversal at full saturation, ``(Fc^2/sigma) H_gamma(-1)``,
    ``(1 - ln 2) Fc^2/sigma = 0.306853 Fc^2/sigma`` for ``gamma = 1`` (paper, after (3.9)).

    Parameters
    ----------
    E_p : float or array_like
        Potential energy at the reversals [J], length >= 1.
    friction : Dahl
        The friction model.
    E_0 : float, optional
        Energy of the initial state [J]; reported (ratio to the bound), never checked.

    Returns
    -------
    BoundCheck
    """
    friction = _check_friction(friction)
    E_p = np.atleast_1d(np.asarray(E_p, dtype=float))
    if E_p.ndim != 1 or E_p.size < 1:
        raise ValueError(f"E_p must be a number or a non-empty 1-D array, got shape {E_p.shape}")
    scale = friction.Fc**2 / friction.sigma
    bound = 0.5 * scale
    sharp = scale * float(branch_potential(-1.0, friction.gamma))
    i = int(np.argmax(E_p))
    top = float(E_p[i])
    e0 = None if E_0 is None else float(E_0)
    return BoundCheck(
        bound=bound,
        bound_sharp=sharp,
        max_E_p=top,
        index=i,
        ratio=top / bound,
        margin=bound - top,
        ratio_sharp=top / sharp,
        holds=top <= bound * (1.0 + _ROUNDING),
        strict=top < bound,
        holds_sharp=top <= sharp * (1.0 + _ROUNDING),
        E_0=e0,
        initial_ratio=None if e0 is None else e0 / bound,
    )


# --------------------------------------------------------------------------- report


@dataclass(frozen=True, eq=False)
class EnergyReport:
    """Energy balance of a trajectory at its velocity reversals (paper section 2).

    Attributes
    ----------
    source : str
        ``"samples"`` or ``"reversal table"``.
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N], length n.
    direction : numpy.ndarray
        Sign of the velocity after each reversal (+1 or -1).
    E_p : numpy.ndarray
        Potential energy at each reversal [J]: the branch potential of the Dahl model,
        (3.9) for ``gamma = 1`` (samples), or the table's ``E_p``.
    E_d : numpy.ndarray
        Energy dissipated in the half-cycle from reversal k to k + 1 [J], length n - 1,
        (2.10): ``E_p[k] + W_u[k] - E_p[k+1]`` (samples; ``W_u`` the input's work, zero
        unforced) or the table's ``E_d[1:]``. Under forcing a reversal can occur before the
        force zero crossing; the Dahl branch potential then rises at the reversal and that
        ``E_d`` is negative (the Dahl model has no dissipation rate ``D >= 0``, paper after (2.3)).
    E_0 : float
        Energy of the initial state [J].
    E_d_initial : float
        Energy dissipated in the first excursion, from the initial state to the first
        reversal [J] (may include gross sliding; not part of (2.10)-(2.12)).
    series_partial, series_remainder : numpy.ndarray
        Truncated series (2.11), see :func:`series`.
    residual_2_10 : float
        ``max_k |E_p[k] - E_d[k] - E_p[k+1] + W_u[k]|`` relative to ``max(E_p)``: how well the
        dissipation and potential energies agree with (2.10) (0 by construction for samples).
    E_p_check : numpy.ndarray or None
        Independent estimate of ``E_p``: the peak kinetic energy in each complete unforced
        half-cycle (samples, length n - 1, paper's note after (3.9)), or the branch potential
        of the tabulated ``F_i`` (table, length n). ``None`` for forced samples.
    E_p_check_label : str
        What ``E_p_check`` is.
    E_p_check_max_rel_dev : float or None
        ``max |E_p_check - E_p| / max(E_p)`` over the entries compared.
    bound : BoundCheck
        The bound (2.12) and the initial energy.
    """

    source: str
    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    direction: np.ndarray
    E_p: np.ndarray
    E_d: np.ndarray
    E_0: float
    E_d_initial: float
    series_partial: np.ndarray
    series_remainder: np.ndarray
    residual_2_10: float
    E_p_check: Optional[np.ndarray]
    E_p_check_label: str
    E_p_check_max_rel_dev: Optional[float]
    bound: BoundCheck

    def __len__(self) -> int:
        return len(self.t)

    @property
    def E_p_decreasing(self) -> bool:
        """True if ``E_p`` strictly decreases from reversal to reversal (clockwise hysteresis)."""
        return bool(np.all(np.diff(self.E_p) < 0.0))

    def format(self, max_rows: int = 20) -> str:
        """Return the report as a readable text table and summary (at most ``max_rows`` rows)."""
        head = (
            f"{'i':>5} {'t [s]':>13} {'x [m]':>13} {'F [N]':>13} {'E_p [J]':>12} "
            f"{'E_d(i) [J]':>12} {'sum E_d(n>=i)':>13} {'E_p/bound':>10}"
        )
        n = len(self)
        half = max(1, max_rows // 2)
        idx = list(range(n)) if n <= max_rows else list(range(half)) + list(range(n - half, n))
        lines = [f"Energy at reversals ({self.source}); E_d(i): half-cycle from reversal i to i+1", head, "-" * len(head)]
        prev = -1
        for i in idx:
            if i != prev + 1:
                lines.append(f"{'...':>5}")
            e_d = f"{self.E_d[i]:>12.5e}" if i < n - 1 else f"{'-':>12}"
            lines.append(
                f"{i + 1:>5} {self.t[i]:>13.7g} {self.x[i]:>13.6g} {self.F[i]:>13.6g} {self.E_p[i]:>12.5e} "
                f"{e_d} {self.series_partial[i]:>13.5e} {self.E_p[i] / self.bound.bound:>10.6f}"
            )
            prev = i
        lines.append("")
        lines.append(f"first excursion (initial state to reversal 1) dissipated {self.E_d_initial:.6e} J")
        if n:
            lines.append(f"E_p strictly decreasing: {'yes' if self.E_p_decreasing else 'NO'}")
            lines.append(f"(2.10) E_p(i) = E_d(i) + E_p(i+1): max relative residual {self.residual_2_10:.3e}")
            lines.append(
                f"(2.11) E_p(i) = sum E_d(n>=i) + remainder; over {max(n - 1, 0)} half-cycles the remainder is E_p(last) = "
                f"{self.E_p[-1]:.4e} J = {self.E_p[-1] / self.E_p[0] if self.E_p[0] > 0 else 0.0:.3e} E_p(first)"
            )
        if self.E_p_check_max_rel_dev is not None:
            lines.append(f"E_p vs {self.E_p_check_label}: max relative deviation {self.E_p_check_max_rel_dev:.3e}")
        lines.append(self.bound.format())
        return "\n".join(lines)


def _rel_residual(values: np.ndarray, scale: float) -> float:
    if values.size == 0:
        return 0.0
    return float(np.max(np.abs(values)) / scale) if scale > 0 else float(np.max(np.abs(values)))


def _input_power(system: Oscillator, t: np.ndarray, v: np.ndarray) -> np.ndarray:
    u = system.u
    if callable(u):
        values = np.array([float(u(ti)) for ti in t])
    else:
        values = np.interp(t, u[0], u[1])
    return values * v


def _work_to_reversals(t: np.ndarray, p: np.ndarray, rev: SampledReversals, method: str) -> np.ndarray:
    """Integral of the power ``p`` from ``t[0]`` to each reversal (``p = 0`` at a reversal)."""
    cum = _cumulative(t, p, method)
    i = rev.index
    return cum[i] + 0.5 * p[i] * (rev.t - t[i])


def _peak_kinetic(t: np.ndarray, ek: np.ndarray, rev: SampledReversals) -> np.ndarray:
    """Peak kinetic energy in each complete half-cycle, refined by a parabola through 3 samples."""
    out = np.empty(max(len(rev) - 1, 0))
    for k in range(out.size):
        lo, hi = int(rev.index[k]) + 1, int(rev.index[k + 1]) + 1
        j = lo + int(np.argmax(ek[lo:hi]))
        out[k] = ek[j]
        if lo < j < hi - 1:
            hm, hp = t[j - 1] - t[j], t[j + 1] - t[j]
            dm, dp = (ek[j - 1] - ek[j]) / hm, (ek[j + 1] - ek[j]) / hp
            c = (dp - dm) / (hp - hm)  # E(tau) = E_j + b tau + c tau^2 through the 3 samples
            if c < 0.0:
                b_ = dp - c * hp
                out[k] = max(ek[j], ek[j] - b_ * b_ / (4.0 * c))
    return out


def analyze_samples(
    t: Any, x: Any, v: Any, F: Any, *, system: Oscillator, method: str = "trapezoid"
) -> EnergyReport:
    """Energy analysis of a sampled trajectory of a Dahl oscillator (2.1), in SI units.

    Detects the reversals (:func:`find_reversals`), evaluates the potential energy at each
    (:func:`branch_energy`, (3.9) for ``gamma = 1``), the dissipation per half-cycle (2.10)
    (plus the input's work ``int u v dt`` over the half-cycle if the system is forced), the
    truncated series (2.11) and the bound (2.12). Unforced, the peak kinetic energy of each
    complete half-cycle is an independent, model-free estimate of ``E_p`` (paper, note after
    (3.9)), reported as ``E_p_check``.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    x : array_like
        Positions [m], length N.
    v : array_like
        Velocities [m/s], length N.
    F : array_like
        Friction forces [N], length N, ``|F| <= Fc``.
    system : Oscillator
        The oscillator that produced the samples (mass, Dahl friction, input ``u``).
    method : {"trapezoid", "simpson"}
        Quadrature of the input's work (forced systems only).

    Returns
    -------
    EnergyReport

    Raises
    ------
    ValueError
        Invalid arrays (see :func:`find_reversals`), no reversal in the samples, or
        ``|F| > Fc``.
    TypeError
        ``system`` is not an Oscillator with a Dahl friction model.
    """
    friction, mass = _check_dahl(system)
    method = _check_method(method)
    t, x, v, F = _samples(t=t, x=x, v=v, F=F)
    over = np.abs(F) > friction.Fc * (1.0 + _ROUNDING)
    if np.any(over):
        i = int(np.flatnonzero(over)[0])
        raise ValueError(
            f"F must lie in [-Fc, Fc] = [{-friction.Fc!r}, {friction.Fc!r}] (every sample), got F[{i}] = {float(F[i])!r}"
        )
    rev = find_reversals(t, v, x=x, F=F)
    if len(rev) == 0:
        raise ValueError(
            f"v changes sign nowhere in the {t.size} samples (t from {float(t[0])!r} to {float(t[-1])!r} s): "
            "no reversal to analyse; simulate longer"
        )
    # the samples obey |F| <= Fc; extrapolation to a reversal may overshoot near saturation
    E_p = branch_energy(np.clip(rev.F, -friction.Fc, friction.Fc), rev.direction, friction=friction)
    s0 = rev.initial_direction
    E_0 = float(kinetic_energy(v[0], mass=mass) + branch_energy(F[0], s0, friction=friction))
    if system.forced:
        W = _work_to_reversals(t, _input_power(system, t, v), rev, method)
        w_first, w_half = float(W[0]), np.diff(W)
        check, label, dev = None, "peak kinetic energy (unforced only)", None
    else:
        w_first, w_half = 0.0, np.zeros(len(rev) - 1)
        check = _peak_kinetic(t, kinetic_energy(v, mass=mass), rev)
        label = "peak kinetic energy per half-cycle"
        dev = _rel_residual(check - E_p[: check.size], float(np.max(E_p))) if check.size else None
    E_d = dissipation(E_p, input_work=w_half)
    S, R = series(E_p, E_d)
    return EnergyReport(
        source="samples",
        t=rev.t,
        x=rev.x,
        F=rev.F,
        direction=rev.direction,
        E_p=E_p,
        E_d=E_d,
        E_0=E_0,
        E_d_initial=E_0 + w_first - float(E_p[0]),
        series_partial=S,
        series_remainder=R,
        residual_2_10=_rel_residual(E_p[:-1] + w_half - E_d - E_p[1:], float(np.max(E_p))),
        E_p_check=check,
        E_p_check_label=label,
        E_p_check_max_rel_dev=dev,
        bound=bound_check(E_p, friction=friction, E_0=E_0),
    )


def analyze_table(table: ReversalTable, *, system: Oscillator) -> EnergyReport:
    """Energy analysis of a trajectory given at its reversals (a :class:`ReversalTable`).

    Takes ``E_p`` and the dissipation from the table (``table.E_d[k + 1]`` is the half-cycle
    from reversal k to k + 1), checks (2.10) between them, forms the series (2.11), checks the
    bound (2.12), and recomputes ``E_p`` independently from the tabulated forces as the branch
    potential of the Dahl model ((3.9) for ``gamma = 1``), reported as ``E_p_check``.

    Parameters
    ----------
    table : ReversalTable
        Reversal states in SI units, e.g. from :func:`prefriction.exact_reversals`.
    system : Oscillator
        The oscillator of the table (Dahl friction model).

    Returns
    -------
    EnergyReport

    Raises
    ------
    ValueError
        Empty table, a non-finite entry, or times not strictly increasing.
    TypeError
        ``table`` is not a ReversalTable, or ``system`` not an Oscillator with a Dahl model.
    """
    friction, _ = _check_dahl(system)
    if not isinstance(table, ReversalTable):
        raise TypeError(f"table must be a prefriction.ReversalTable, got {table!r} of type {type(table).__name__}")
    if len(table) < 1:
        raise ValueError("table holds no reversal (length 0); need at least 1")
    for name in ("t", "x", "F", "E_p", "E_d", "E_0"):
        bad = ~np.isfinite(np.atleast_1d(np.asarray(getattr(table, name), dtype=float)))
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"table.{name} must be finite, got a non-finite entry at index {i} (reversal {i + 1})")
    t = np.asarray(table.t, dtype=float)
    if np.any(np.diff(t) <= 0.0):
        i = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
        raise ValueError(f"table.t must be strictly increasing, got t[{i + 1}] = {float(t[i + 1])!r} <= t[{i}] = {float(t[i])!r}")
    x = np.asarray(table.x, dtype=float)
    F = np.asarray(table.F, dtype=float)
    E_p = np.asarray(table.E_p, dtype=float)
    E_d = np.asarray(table.E_d, dtype=float)[1:]
    n = t.size
    # direction after reversal k is opposite to the motion that ended there
    direction = np.empty(n, dtype=int)
    if n >= 2:
        direction[1:] = -np.sign(np.diff(x)).astype(int)
        direction[0] = -direction[1]
    else:
        direction[0] = -1 if F[0] > 0 else 1
    direction[direction == 0] = np.where(F[direction == 0] > 0, -1, 1)
    check = branch_energy(F, direction, friction=friction)
    top = float(np.max(E_p))
    S, R = series(E_p, E_d)
    E_0 = float(table.E_0)
    return EnergyReport(
        source="reversal table",
        t=t,
        x=x,
        F=F,
        direction=direction,
        E_p=E_p,
        E_d=E_d,
        E_0=E_0,
        E_d_initial=float(table.E_d[0]),
        series_partial=S,
        series_remainder=R,
        residual_2_10=_rel_residual(E_p[:-1] - E_d - E_p[1:], top),
        E_p_check=check,
        E_p_check_label="branch potential of the tabulated F_i, (3.9) for gamma = 1",
        E_p_check_max_rel_dev=_rel_residual(check - E_p, top),
        bound=bound_check(E_p, friction=friction, E_0=E_0),
    )
