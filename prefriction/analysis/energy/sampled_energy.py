"""Energies along a sampled trajectory: kinetic energy, integrated power and work (2.8), the
dissipation of a closed cycle (2.5)-(2.7), and the mechanical energy of a Dahl oscillator."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.integrate import cumulative_simpson, cumulative_trapezoid

from prefriction.analysis.energy.balance import branch_energy
from prefriction.analysis.energy.checks import check_method, check_samples, check_system, finite_energy, value_array
from prefriction.analysis.energy.sampled_reversals import find_reversals
from prefriction._validation import check_nonnegative, check_positive
from prefriction.models import Oscillator


def kinetic_energy(v: Any, *, mass: float) -> np.ndarray:
    """Kinetic energy ``E_k = m v^2 / 2`` [J], the first term of (2.3).

    Parameters
    ----------
    v : float or array_like
        Velocities [m/s], a finite number or a non-empty 1-D array of them.
    mass : float
        Moving mass [kg], ``0 < mass < inf``.

    Returns
    -------
    numpy.ndarray
        ``E_k`` [J], same shape as ``v``.

    Raises
    ------
    TypeError
        ``v`` or ``mass`` not real (``None``, strings, complex).
    ValueError
        NaN or inf in ``v``, an empty ``v``, or ``mass`` not finite and > 0.
    """
    m = check_positive("mass", mass)
    v = value_array("v", v)
    with np.errstate(over="ignore"):
        E = 0.5 * m * v * v
    return finite_energy("kinetic_energy", E, f"v (largest |v| = {float(np.max(np.abs(v))):.3g} m/s) and mass = {m:.3g} kg")


def cumulative(t: np.ndarray, y: np.ndarray, method: str) -> np.ndarray:
    """Cumulative integral of samples ``y`` over ``t``, 0 at ``t[0]``, by ``method`` (Simpson needs 3 samples)."""
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
    method = check_method(method)
    if not isinstance(reset_at_reversals, (bool, np.bool_)):
        raise TypeError(f"reset_at_reversals must be True or False, got {reset_at_reversals!r}")
    t, v, F = check_samples(t=t, v=v, F=F)
    with np.errstate(over="ignore", invalid="ignore"):
        p = F * v
        out = cumulative(t, p, method) if not reset_at_reversals else None
    inputs = (f"t, v and F (largest |v| {float(np.max(np.abs(v))):.3g} m/s, |F| {float(np.max(np.abs(F))):.3g} N, "
              f"span {float(t[-1] - t[0]):.3g} s)")
    if out is not None:
        return finite_energy("integrated_power", out, inputs)
    rev = find_reversals(t, v)
    out = np.empty_like(p)
    starts = np.concatenate(([0], rev.index + 1, [t.size]))
    for k in range(starts.size - 1):
        lo, hi = int(starts[k]), int(starts[k + 1])
        if hi <= lo:
            continue
        base = 0.0 if k == 0 else 0.5 * p[lo] * (t[lo] - rev.t[k - 1])
        with np.errstate(over="ignore", invalid="ignore"):
            out[lo:hi] = base + cumulative(t[lo:hi], p[lo:hi], method)
    return finite_energy("integrated_power", out, inputs)


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
    x, F = check_samples(x=x, F=F)
    with np.errstate(over="ignore", invalid="ignore"):
        E = np.concatenate(([0.0], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(x))))
    return finite_energy("work_integral", E, f"x and F (largest |x| {float(np.max(np.abs(x))):.3g} m, "
                                             f"|F| {float(np.max(np.abs(F))):.3g} N)")


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
    x, F = check_samples(x=x, F=F)
    tol = check_nonnegative("closure_tol", closure_tol)
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


def _sample_directions(v: np.ndarray) -> np.ndarray:
    """Branch direction at every sample: sign of v; a zero takes the next non-zero sign."""
    sgn = np.sign(v)
    nz = np.flatnonzero(sgn)
    if nz.size == 0:
        raise ValueError("v is zero at every sample: nothing moves, no branch direction is defined")
    nxt = np.minimum(np.searchsorted(nz, np.arange(v.size)), nz.size - 1)
    return sgn[nz[nxt]]


def total_energy(t: Any, v: Any, F: Any, *, system: Oscillator, x: Any = None) -> np.ndarray:
    """Mechanical energy ``E_k + E_branch`` of a Dahl oscillator at every sample [J].

    ``E_branch`` is :func:`branch_energy` with the direction of motion (a sample with
    ``v = 0`` belongs to the branch that follows it). Unforced (2.1), this is constant
    along each branch and drops by the half-cycle dissipation ``E_d`` (2.10) at each
    reversal; right after reversal ``k`` it equals ``E_p[k]``. Its drift along a branch
    measures the energy error of a simulation.

    In deep gross sliding the force rounds to ``s Fc``, where the stored energy of a model
    with unbounded energy there (Dahl with ``gamma >= 1``) is no longer a function of the force.
    Given the positions ``x``, such samples take the energy of the last sample of their branch
    where it is, plus the work ``int F dx`` since (trapezoid rule; along a branch
    ``d E_branch = F dx``, the definition of the branch energy (2.8)).

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
    x : array_like, optional
        Positions [m] at the samples (e.g. ``SimulationResult.x``): needed only where the force
        has rounded to the saturation force.

    Returns
    -------
    numpy.ndarray
        ``E_k + E_branch`` at every sample [J], finite.

    Raises
    ------
    ValueError
        Invalid arrays, ``|F| > Fc``, ``v = 0`` at every sample (no direction), or a sample
        with ``s F = Fc`` for a model whose stored energy is unbounded there without ``x`` (or
        on a branch that starts there); the message names the sample.
    """
    friction, mass = check_system(system)
    if x is None:
        t, v, F = check_samples(t=t, v=v, F=F)
        return kinetic_energy(v, mass=mass) + branch_energy(F, _sample_directions(v), friction=friction)
    t, v, F, x = check_samples(t=t, v=v, F=F, x=x)
    s = _sample_directions(v)
    unbounded = getattr(friction, "gamma", 0.0) >= 1.0  # Dahl: infinite stored energy at s F = Fc
    good = np.abs(F) < friction.Fc * (1.0 - 1e-12) if unbounded else np.ones(F.size, bool)
    E_b = np.zeros(F.size)
    E_b[good] = branch_energy(F[good], s[good], friction=friction)
    bad = np.flatnonzero(~good)
    if bad.size:
        work = np.concatenate(([0.0], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(x))))  # int F dx along the path
        starts = np.concatenate(([0], np.flatnonzero(np.diff(s)) + 1))  # first sample of each branch
        branch_start = starts[np.searchsorted(starts, np.arange(F.size), side="right") - 1]
        last_good = np.maximum.accumulate(np.where(good, np.arange(F.size), -1))
        anchor = last_good[bad]
        if np.any(anchor < branch_start[bad]):
            j = int(bad[np.flatnonzero(anchor < branch_start[bad])[0]])
            raise ValueError(f"F[{j}] = {float(F[j])!r} N has rounded to the saturation force on a branch that starts "
                             f"there: its stored energy cannot be computed from the samples (start the samples earlier)")
        E_b[bad] = E_b[anchor] + work[bad] - work[anchor]
    return kinetic_energy(v, mass=mass) + E_b
