"""friction_along's one C pass (``prefriction/along/native.c``): the motion's intervals computed
in C from ``t`` and ``x`` as ``docs/along.md#motion`` defines them, checked against that
definition written here, and the force against the Maxwell-slip stop operator (closed form)
on both paths (the C pass and the CasADi block Function without a compiler)."""

from __future__ import annotations

import numpy as np
import pytest

import prefriction as pf
import prefriction.along.run as along_run
from prefriction.simulation.compiled import jit_available

from _stop_operator import K, W, element_forces, two_tone

pytestmark = pytest.mark.skipif(not jit_available(), reason="the C pass needs a C compiler")


def _motion() -> tuple[np.ndarray, np.ndarray]:
    """Flat at the start and in between, reversals, uneven sample times: 400 samples."""
    t, x = two_tone(3, 400, (2e-5, 4e-6), (3.1, 17.0))
    x[:5] = x[5]  # no displacement before the first moving interval
    x[120:150] = x[120]  # at rest
    return t, x


def _stop_operator(x: np.ndarray) -> np.ndarray:
    """Maxwell-slip force [N] from the relaxed state: the elements' forces summed."""
    return element_forces(x).sum(axis=1)


def _definition(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocities at the samples and reversal samples as docs/along.md#motion defines them."""
    v = np.diff(x) / np.diff(t)
    dirs, s = [], None
    first = next(np.sign(d) for d in np.diff(x) if d != 0.0)
    for d in np.diff(x):
        s = np.sign(d) if d != 0.0 else (first if s is None else s)
        dirs.append(s)
    rev = [k for k in range(1, len(dirs)) if dirs[k] != dirs[k - 1]]
    return np.concatenate(([v[0]], v)), np.array(rev, dtype=int)


@pytest.mark.parametrize("native", [True, False])
def test_motion_and_force_as_defined(native: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    if not native:
        monkeypatch.setattr(along_run, "along_driver", lambda model, substeps: None)
    t, x = _motion()
    res = pf.friction_along(pf.MaxwellSlip(K, W), t, x)
    v, rev = _definition(t, x)
    np.testing.assert_array_equal(res.v, v)
    np.testing.assert_array_equal(res.reversals, rev)
    assert rev.size >= 4
    assert np.max(np.abs(res.F - _stop_operator(x))) <= 1e-12 * W.sum()
    assert res.states.shape[0] == res.flags.shape[0] == t.size


def test_given_velocities_and_own_arrays() -> None:
    """The user's velocities are used at the samples; the result keeps its own t and x."""
    t, x = _motion()
    v = np.cos(t)
    res = pf.friction_along(pf.MaxwellSlip(K, W) + pf.Viscous(2.0), t, x, v=v)
    np.testing.assert_array_equal(res.v, v)
    F_ref = _stop_operator(x) + 2.0 * v
    assert np.max(np.abs(res.F - F_ref)) <= 1e-12 * np.ptp(F_ref)
    x0 = x.copy()
    x *= 2.0
    t += 1.0
    np.testing.assert_array_equal(res.x, x0)
    assert res.t[0] == pytest.approx(t[0] - 1.0)


def test_bad_samples_in_float_arrays_are_named() -> None:
    t, x = _motion()
    bad = x.copy()
    bad[7] = np.inf
    with pytest.raises(ValueError, match=r"x\[7\] must be finite"):
        pf.friction_along(pf.MaxwellSlip(K, W), t, bad)
    tt = t.copy()
    tt[9] = tt[8]
    with pytest.raises(ValueError, match=r"t must be strictly increasing, got t\[8\]"):
        pf.friction_along(pf.MaxwellSlip(K, W), tt, x)
    with pytest.raises(ValueError, match=r"v\[3\] must be finite"):
        pf.friction_along(pf.MaxwellSlip(K, W), t, x, v=np.r_[0.0, 0.0, 0.0, np.nan, np.zeros(t.size - 4)])
