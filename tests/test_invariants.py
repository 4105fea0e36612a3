"""Property tests (hypothesis) of the paper's energy invariants over wide parameter ranges.

- (2.6): a memory-free (single-valued) restoring force dissipates nothing on a closed cycle;
- (2.7): a clockwise Dahl hysteresis loop encloses a positive area, for every gamma > 0;
- (2.12): the potential energy at any reversal of a Dahl model stays below Fc^2/(2 sigma);
- on the exact reference trajectory (prefriction.exact_reversals): E_p strictly decreasing
  (gamma > 0), (2.10) and (2.11) to rounding, (2.12) after the first reversal, gamma = 0
  conserving energy after saturation, E_p equal to (3.9) for gamma = 1 (mpmath), and the
  energy analysis of prefriction.energy agreeing with the table.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq

from prefriction import Dahl, Oscillator, energy

EPS = np.finfo(float).eps
FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def log_uniform(lo: float, hi: float):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


# --------------------------------------------------------------------------- (2.6), (2.7)


@FAST
@given(
    steps=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=60),
    k=log_uniform(1e-2, 1e10),
    c=st.floats(0.0, 10.0),
    scale=log_uniform(1e-9, 1e3),
)
def test_memory_free_force_dissipates_nothing_on_closed_cycles(steps, k, c, scale):
    # a closed path reversing at random, force k x (1 + c (x/scale)^2): single-valued, so
    # oint F dx = 0 (2.6); the trapezoid rule is exact for the linear part and errs by at
    # most h^3/12 max|F''| per step for the cubic part.
    x = scale * np.concatenate(([0.0], np.cumsum(steps), [0.0]))
    F = k * x * (1.0 + c * (x / scale) ** 2)
    E = energy.loop_integral(x, F)
    rounding = 64 * EPS * float(np.sum(np.abs(F[1:] + F[:-1]) * np.abs(np.diff(x)))) + 1e-300
    d2F = 6.0 * c * k * float(np.max(np.abs(x))) / scale**2
    assert abs(E) <= rounding + d2F * float(np.sum(np.abs(np.diff(x)) ** 3)) / 12.0


def _gap_after(w0: float, xi: np.ndarray, gamma: float) -> np.ndarray:
    """w = 1 - s F/Fc after normalised distance xi on a Dahl branch (3.2), closed forms."""
    if gamma == 0.0:
        return np.maximum(w0 - xi, 0.0)
    if gamma == 0.5:
        return np.maximum(math.sqrt(w0) - xi / 2, 0.0) ** 2
    if gamma == 1.0:
        return w0 * np.exp(-xi)
    return w0 / (1.0 + w0 * xi)  # gamma = 2


@FAST
@given(
    gamma=st.sampled_from([0.0, 0.5, 1.0, 2.0]),
    A=log_uniform(1e-3, 30.0),  # half-amplitude in units Fc / sigma
    sigma=log_uniform(1e-2, 1e10),
    Fc=log_uniform(1e-3, 1e3),
)
def test_clockwise_dahl_loop_area(gamma, A, sigma, Fc):
    # symmetric closed cycle -A..A: the ascending branch from (-A, -a) must reach (A, a)
    def mismatch(a):
        return 1.0 - _gap_after(1.0 + a, np.array(2 * A), gamma) - a

    a = 1.0 if mismatch(1.0) >= 0.0 else brentq(mismatch, 0.0, 1.0, xtol=1e-15, rtol=4 * EPS)
    xi = 2 * A * np.linspace(0.0, 1.0, 4001) ** 2  # dense where the branch bends most
    up = 1.0 - _gap_after(1.0 + a, xi, gamma)
    x = np.concatenate((xi - A, (A - xi)[1:])) * Fc / sigma
    F = np.concatenate((up, -up[1:])) * Fc
    E = energy.loop_integral(x, F, closure_tol=1e-9)
    # loop = 2 int_{-A}^{A} f_+ dx (2.5) by symmetry, here by adaptive quadrature
    branch = quad(lambda q: 1.0 - float(_gap_after(1.0 + a, np.array(q), gamma)), 0.0, 2 * A, limit=200)[0]
    ref = 2 * branch * Fc**2 / sigma
    if gamma == 0.0 and A <= 1.0:
        assert abs(E) <= 1e-12 * Fc**2 / sigma * A  # elastic: the linear spring of (2.6)
    else:
        assert E > 0.0  # clockwise hysteresis (2.7)
        assert E == pytest.approx(ref, rel=1e-6)


# --------------------------------------------------------------------------- (2.12) for any state


@FAST
@given(
    gamma=st.floats(0.0, 5.0),
    a=st.floats(0.0, 1.0),
    sigma=log_uniform(1e-2, 1e10),
    Fc=log_uniform(1e-3, 1e3),
)
def test_reversal_potential_never_exceeds_bound_2_12(gamma, a, sigma, Fc):
    d = Dahl(sigma, Fc, gamma)
    # a reversal ends a loading branch: the new branch starts on its unloading side
    E = energy.branch_energy(a * Fc, -1, friction=d)
    bc = energy.bound_check(E, friction=d)
    assert bc.holds and bc.holds_sharp
    assert bc.ratio <= 1.0 + 1e-15
    assert (bc.ratio < 1.0) or (gamma == 0.0 and a == 1.0)
    # the sharp bound H_gamma(-1) = int_0^1 u (1 + u)^-gamma du, by quadrature
    H1 = quad(lambda u: u * (1 + u) ** -gamma, 0.0, 1.0, epsabs=0, epsrel=1e-13)[0]
    assert bc.bound_sharp == pytest.approx(H1 * Fc**2 / sigma, rel=1e-12)
