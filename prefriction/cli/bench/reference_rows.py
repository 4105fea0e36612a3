"""Rows of ``prefriction bench`` checked against independent references (``docs/bench.md#reference-rows``).

Each row runs :func:`prefriction.simulate` over the tolerances 1e-6 ... 1e-10 on a Dahl
oscillator with ``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg (small-oscillation frequency
``w0 = sqrt(sigma / m) = 100`` rad/s) and prints the largest ``error / rtol``; a row passes
within 10x rtol. The references are independent of the simulator:

- scipy ``solve_ivp(method="DOP853")`` at ``rtol = 1e-13`` (``atol = 1e-15``) in normalised units
  (``docs/mathematics.md#normalised-units``), restarted at every reversal and every saturation
  (:func:`prefriction.cli.bench.restarts.scipy_reversals`);
- for gamma = 0 below saturation (the Prandtl stop stays elastic, ``docs/mathematics.md#prandtl-stop``)
  the conservation of energy: every reversal has ``F^2 / (2 sigma) = m v0^2 / 2``.

Rows: unforced gamma = 0.3 and 0.2 with saturation (``v0 = 0.02`` m/s; error of the reversal
positions relative to ``max(|x|, Fc / sigma)``); forced gamma = 0.3 at resonance
(``u = 0.5 sin(w0 t)`` N); forced gamma = 0.5, ``u = 0.5 sin(5 t)`` N from rest to
``t_end = 2.5133`` s (30 reversals; the count must match); gamma = 0 below saturation (energy
drift over 1e4 reversals); a forced response 1/100 of the forcing (``w = 10 w0``; error of the
reversal forces relative to the largest reversal force).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Optional

import numpy as np

from prefriction.cli.bench.restarts import scipy_reversals
from prefriction.cli.bench.timing import progress
from prefriction.models import Dahl, Oscillator
from prefriction.signals import Sine
from prefriction.simulation.simulate import simulate
from prefriction.units import Scales

__all__ = ["LADDER", "QUICK_LADDER", "RowCase", "RowResult", "format_rows", "measure", "row_cases", "run"]

SIGMA, FC, MASS = 1e4, 1.0, 1.0  # N/m, N, kg
W0 = math.sqrt(SIGMA / MASS)  # small-oscillation angular frequency [rad/s]
LADDER = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
QUICK_LADDER = (1e-6, 1e-9)
REF_RTOL = 1e-13
LIMIT = 10.0  # a row passes if every error / rtol <= LIMIT


@dataclass(frozen=True)
class RowCase:
    """One stability row: a Dahl oscillator, its start and what is compared.

    Attributes
    ----------
    name : str
        Row label.
    gamma : float
        Dahl shape factor.
    v0 : float
        Initial velocity [m/s] (``x0 = F0 = 0``).
    n : int or None
        Reversals of an unforced run.
    t_end : float or None
        End time of a forced run [s].
    amplitude, omega : float
        Input ``u = amplitude sin(omega t)`` [N, rad/s]; 0 for an unforced row.
    metric : str
        ``"positions"`` (reversal positions relative to ``max(|x|, Fc / sigma)``), ``"forces"``
        (reversal forces relative to the largest one) or ``"energy"`` (drift of
        ``F^2 / (2 sigma)`` at the reversals from ``m v0^2 / 2``).
    expected : int or None
        Number of reversals the reference must have (a check of the row itself).
    """

    name: str
    gamma: float
    v0: float
    n: Optional[int] = None
    t_end: Optional[float] = None
    amplitude: float = 0.0
    omega: float = 0.0
    metric: str = "positions"
    expected: Optional[int] = None

    @property
    def system(self) -> Oscillator:
        """The oscillator (``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg) and its input."""
        u = Sine(self.amplitude, self.omega / (2.0 * math.pi)) if self.amplitude else None
        return Oscillator(Dahl(SIGMA, FC, self.gamma), mass=MASS, u=u)


@dataclass(frozen=True)
class RowResult:
    """Measured row: ``error / rtol`` per tolerance, reversal counts and the verdict."""

    case: str
    metric: str
    ratios: tuple[float, ...]
    tols: tuple[float, ...]
    n_ref: int
    n_sim: tuple[int, ...]

    @property
    def worst(self) -> float:
        """Largest ``error / rtol`` over the tolerances (inf for a wrong reversal count)."""
        return max(self.ratios)

    @property
    def passed(self) -> bool:
        """True if every ``error / rtol`` is at most :data:`LIMIT`."""
        return self.worst <= LIMIT


def row_cases(quick: bool = False) -> list[RowCase]:
    """The rows; ``quick`` shortens the gamma = 0 run from 1e4 to 500 reversals."""
    return [
        RowCase("gamma=0.3 saturating, v0=0.02", 0.3, 0.02, n=50),
        RowCase("gamma=0.2 saturating, v0=0.02", 0.2, 0.02, n=50),
        RowCase("gamma=0.3 forced at resonance", 0.3, 0.0, t_end=0.5, amplitude=0.5, omega=W0),
        RowCase("gamma=0.5 forced 0.5 sin(5 t)", 0.5, 0.0, t_end=2.5133, amplitude=0.5, omega=5.0, expected=30),
        RowCase(f"gamma=0 elastic, {500 if quick else 10_000} reversals", 0.0, 0.005,
                n=500 if quick else 10_000, metric="energy"),
        RowCase("gamma=1 forced at w=10 w0", 1.0, 0.0, t_end=0.1, amplitude=0.5, omega=10.0 * W0, metric="forces"),
    ]


def reference(case: RowCase) -> np.ndarray:
    """Reference reversals ``(t~, x~, F~)`` (normalised) by scipy DOP853 at :data:`REF_RTOL` with
    restarts; for the energy row the count only matters (energy is conserved exactly)."""
    sc = Scales.of(case.system)
    if case.metric == "energy":
        return np.zeros((case.n, 3))
    amp, w = case.amplitude / sc.F, case.omega * sc.t

    def sine(t: float) -> float:
        return amp * math.sin(w * t)

    u = sine if case.amplitude else None
    t_end = None if case.t_end is None else case.t_end / sc.t
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        R = scipy_reversals(case.gamma, case.v0 / sc.v, REF_RTOL, n=case.n, t_end=t_end, u=u)
    if case.expected is not None and len(R) != case.expected:
        raise RuntimeError(f"{case.name}: the scipy reference has {len(R)} reversals, expected {case.expected}")
    return R


def row_error(case: RowCase, got: np.ndarray, ref: np.ndarray) -> float:
    """The row's error of the simulated reversals ``got`` (normalised ``(t~, x~, F~)``)."""
    if len(got) != len(ref):
        return math.inf  # a missed or extra reversal
    if case.metric == "energy":  # (F~^2 / 2) / (v0~^2 / 2): stored energy at v = 0 over E_0
        v0 = case.v0 / Scales.of(case.system).v
        err = float(np.max(np.abs(got[:, 2] ** 2 / v0 ** 2 - 1.0)))
    elif case.metric == "forces":
        err = float(np.max(np.abs(got[:, 2] - ref[:, 2])) / np.max(np.abs(ref[:, 2])))
    else:
        err = float(np.max(np.abs(got[:, 1] - ref[:, 1]) / np.maximum(np.abs(ref[:, 1]), 1.0)))
    return err if math.isfinite(err) else math.inf


def measure(case: RowCase, ladder: tuple[float, ...] = LADDER) -> RowResult:
    """Run ``case`` over ``ladder`` against its reference."""
    system = case.system
    sc = Scales.of(system)
    ref = reference(case)
    ratios, counts = [], []
    for tol in ladder:
        res = simulate(system, case.v0, reversals=case.n, t_end=case.t_end, rtol=tol)
        tab = res.reversals
        got = np.column_stack([tab.t / sc.t, tab.x / sc.x, tab.F / sc.F])
        ratios.append(row_error(case, got, ref) / tol)
        counts.append(len(tab))
    return RowResult(case.name, case.metric, tuple(ratios), tuple(ladder), len(ref), tuple(counts))


def run(quick: bool = False) -> list[RowResult]:
    """Every row (progress on stderr)."""
    cases = row_cases(quick)
    out = []
    for k, case in enumerate(cases, 1):
        progress(f"stability rows [{k}/{len(cases)}]: {case.name}")
        out.append(measure(case, QUICK_LADDER if quick else LADDER))
    return out


def format_rows(rows: list[RowResult]) -> str:
    """The rows as a table: ``err/rtol`` per tolerance, reversal counts and PASS/FAIL."""
    tols = rows[0].tols if rows else ()
    head = f"{'row':<34} {'error':<9} {'n ref':>6} {'n sim':>6} " + " ".join(
        f"{'rtol ' + format(t, '.0e'):>10}" for t in tols) + "  result"
    lines = [head, "-" * len(head)]
    for r in rows:
        n_sim = str(r.n_sim[0]) if len(set(r.n_sim)) == 1 else "/".join(map(str, r.n_sim))
        lines.append(f"{r.case:<34} {r.metric:<9} {r.n_ref:>6} {n_sim:>6} "
                     + " ".join(f"{x:10.2f}" for x in r.ratios) + f"  {'PASS' if r.passed else 'FAIL'}")
    return "\n".join(lines)
