"""No silent NaN or inf: closed forms stay finite at extreme arguments, energies that overflow are refused.

References: mpmath for the describing function; the overflow cases have no finite answer in
double precision, so they must raise with the argument named.
"""

from __future__ import annotations

import warnings

import mpmath as mp
import numpy as np
import pytest

from prefriction import energy
from prefriction.describing import dahl_describing_function


def _reference(A: float, sigma: float, Fc: float) -> complex:
    with mp.workdps(60):
        k = mp.mpf(sigma) * mp.mpf(A) / Fc
        N = (2 * Fc / mp.mpf(A)) * (mp.besseli(1, k) / mp.cosh(k) + 2j / mp.pi * (1 - mp.tanh(k) / k))
        return complex(N)


@pytest.mark.parametrize("A", [1e6, 1e-200, 1e-12, 2e-4, 1.0, 1e3])
def test_dahl_describing_function_at_extreme_amplitudes(A: float) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = complex(dahl_describing_function(A, 1e4, 2.0))
    ref = _reference(A, 1e4, 2.0)
    assert abs(got.real - ref.real) <= 1e-13 * abs(ref) and abs(got.imag - ref.imag) <= 1e-13 * abs(ref)


@pytest.mark.parametrize("call, match", [
    (lambda: energy.kinetic_energy([1e200], mass=1.0), "kinetic_energy overflows"),
    (lambda: energy.work_integral([0.0, 1e300, -1e300], [1.0, 1e200, 1e200]), "work_integral overflows"),
    (lambda: energy.integrated_power([0.0, 1.0, 2.0], [1e200, 1e200, 1e200], [1e200, 1e200, 1e200]),
     "integrated_power overflows"),
])
def test_energies_that_overflow_are_refused(call, match) -> None:
    with pytest.raises(ValueError, match=match):
        call()


def test_total_energy_through_gross_sliding_with_positions() -> None:
    """Unforced, E_k + E_branch is constant along a branch (E_0 = m v0^2 / 2 from F = 0) even where
    the force has rounded to Fc; without the positions the saturated samples are refused."""
    import prefriction as pf

    system = pf.Oscillator(pf.Dahl(1e4, 1.0), mass=1.0)
    v0 = 300 * pf.Scales.of(system).v
    res = pf.simulate(system, v0, reversals=2, rtol=1e-10, dense=True)
    with pytest.raises(ValueError, match="branch energy is infinite"):
        energy.total_energy(res.t, res.v, res.F, system=system)
    E = energy.total_energy(res.t, res.v, res.F, system=system, x=res.x)
    first = res.t < res.reversals.t[0]
    assert np.any(np.abs(res.F[first]) == 1.0)  # the force did round to Fc
    assert np.max(np.abs(E[first] - 0.5 * v0 * v0)) < 1e-3 * 0.5 * v0 * v0
