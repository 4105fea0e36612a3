"""The cases of ``prefriction bench``, its error metric and its reference.

The headline case and the stiff and extreme cases are unforced Dahl oscillators (SI units);
the reference of every case is :func:`prefriction.exact_reversals`. The error of a run is the
largest relative error of its first 50 reversal times, positions (relative to
``max(|x|, Fc / sigma)``) and forces (``docs/bench.md#error``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from prefriction.models import Dahl, Oscillator
from prefriction.reversals import ReversalTable

N_REV = 50
LADDER = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
QUICK_LADDER = [1e-6, 1e-9]
DEFAULT_METHOD = "native"


@dataclass(frozen=True)
class Case:
    """One benchmark case: an unforced Dahl oscillator and its initial state (SI)."""

    name: str
    sigma: float
    Fc: float
    mass: float
    v0: float
    F0: float = 0.0
    gamma: float = 1.0

    @property
    def system(self) -> Oscillator:
        """The oscillator of the case."""
        return Oscillator(Dahl(self.sigma, self.Fc, self.gamma), mass=self.mass)


HEADLINE = Case("headline sigma/Fc=1e4 m=1 v0=1", 1e4, 1.0, 1.0, 1.0)


def stability_cases() -> list[Case]:
    """The stiff and extreme cases of ``docs/bench.md#stability`` (SI units), headline first."""
    cases = [HEADLINE]
    for r in (1e-2, 1e10):
        cases.append(Case(f"sigma/Fc={r:g}", r, 1.0, 1.0, 1.0))
    for m in (1e-6, 1e3):
        cases.append(Case(f"mass={m:g} kg", 1e4, 1.0, m, 1.0))
    for ratio in (1e-20, 1e6):  # sigma m v0^2 / (2 Fc^2)
        cases.append(Case(f"energy ratio={ratio:g}", 1e4, 1.0, 1.0, math.sqrt(2.0 * ratio / 1e4)))
    for F0 in (0.999999, -0.999999):
        cases.append(Case(f"F0={F0:+g} Fc", 1e4, 1.0, 1.0, 1.0, F0))
    cases.append(Case("F0=+0.999999 Fc, v0=0", 1e4, 1.0, 1.0, 0.0, 0.999999))
    for g in (0.0, 0.5, 2.0, 5.0):
        cases.append(Case(f"gamma={g:g}", 1e4, 1.0, 1.0, 1.0, 0.0, g))
    return cases


def exact(case: Case, n: int) -> ReversalTable:
    """The first ``n`` reversals of ``case`` by :func:`prefriction.exact_reversals` (from ``x0 = 0``)."""
    from prefriction.analysis.exact import exact_reversals

    return exact_reversals(case.system, case.v0, n, x0=0.0, F0=case.F0)


def table_error(t: np.ndarray, x: np.ndarray, F: np.ndarray, ref_t: np.ndarray, ref_x: np.ndarray,
                ref_F: np.ndarray, x_scale: float) -> float:
    """Max relative error of reversal times, positions and forces against a reference.

    Times and forces relative to the reference, positions relative to ``max(|x_ref|, x_scale)``;
    a missing or extra reversal gives ``inf`` (``docs/bench.md#error``).

    Parameters
    ----------
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N] to check.
    ref_t, ref_x, ref_F : numpy.ndarray
        The reference reversals, same units.
    x_scale : float
        Least position scale [m], ``Fc / sigma``.

    Returns
    -------
    float
        The largest relative error; ``inf`` if the numbers of reversals differ or a value is not
        finite.
    """
    t, x, F = (np.asarray(a, dtype=float) for a in (t, x, F))
    ref_t, ref_x, ref_F = (np.asarray(a, dtype=float) for a in (ref_t, ref_x, ref_F))
    if len(t) != len(ref_t) or len(t) == 0:
        return math.inf
    et = np.abs(t - ref_t) / np.abs(ref_t)
    ex = np.abs(x - ref_x) / np.maximum(np.abs(ref_x), x_scale)
    eF = np.abs(F - ref_F) / np.abs(ref_F)
    err = float(np.max([et.max(), ex.max(), eF.max()]))  # np.max: a NaN stays NaN (max() would drop it)
    return err if math.isfinite(err) else math.inf


def reversal_error(case: Case, t: np.ndarray, x: np.ndarray, F: np.ndarray, ref: ReversalTable,
                   n: int = N_REV) -> float:
    """Max relative error of the first ``n`` reversal times, positions and forces (inf if missing).

    Parameters
    ----------
    case : Case
        The case (its ``Fc / sigma`` [m] is the least position scale).
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N] of a run.
    ref : ReversalTable
        The reference, at least ``n`` reversals.
    n : int, optional
        Reversals compared, default 50.

    Returns
    -------
    float
        The error of :func:`table_error` over the first ``n``; ``inf`` if the run or the
        reference has fewer than ``n`` reversals.
    """
    if len(t) < n or len(ref.t) < n:
        return math.inf
    return table_error(t[:n], x[:n], F[:n], ref.t[:n], ref.x[:n], ref.F[:n], case.Fc / case.sigma)
