"""The energy report of a LuGre oscillator: viscous and hysteretic dissipation apart
(:class:`LuGreEnergyReport`, :func:`analyze_lugre_samples`, :func:`lugre_table_energy`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction.analysis.energy.balance import BoundCheck
from prefriction.analysis.energy.lugre import half_cycle_split, lugre_bound
from prefriction.analysis.energy.sampled_reversals import SampledReversals
from prefriction.models import LuGre, Oscillator


@dataclass(frozen=True, eq=False)
class LuGreEnergyReport:
    """Energy balance of a sampled LuGre oscillator, split per half-cycle (docs/mathematics.md#lugre-energy).

    Entry ``k`` of each per-half-cycle array is the half-cycle that *ends* at reversal ``k``
    (length n, as in :class:`prefriction.ReversalTable`); entry 0 is the first excursion, from
    the first sample to reversal 1.

    Attributes
    ----------
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and friction forces ``F = sigma0 z`` [N] (``z`` by
        cubic Hermite interpolation of the deflection and its rate in time), length n.
    direction : numpy.ndarray
        Sign of the velocity after each reversal.
    E_p : numpy.ndarray
        Stored bristle energy ``sigma0 z^2 / 2 = F^2 / (2 sigma0)`` at each reversal [J].
    E_0 : float
        Energy of the first sample, ``m v^2 / 2 + sigma0 z^2 / 2`` [J].
    W_u : numpy.ndarray
        Work of the input force ``int u v dt`` per half-cycle [J] (zeros unforced).
    E_d : numpy.ndarray
        Energy lost per half-cycle from the reversal states, ``E_p[k-1] + W_u[k] - E_p[k]`` [J]
        (``E_0 + W_u[0] - E_p[0]`` for the first excursion).
    D_sigma2, D_sigma1 : numpy.ndarray
        ``int sigma2 v^2 dt`` (>= 0) and ``int sigma1 z' v dt`` (either sign) per half-cycle [J].
    D_viscous : numpy.ndarray
        Viscous dissipation ``D_sigma2 + D_sigma1``, the work of the rate terms ``sigma1 z' + sigma2 v`` [J].
    D_hysteretic : numpy.ndarray
        Hysteretic dissipation ``int sigma0^2 |v| z^2 / g(v) dt >= 0`` per half-cycle [J].
    residual : float
        ``max |E_d - D_viscous - D_hysteretic|`` over every half-cycle,
        relative to ``max(E_0, max E_p)``: how well the quadrature of the powers closes the
        balance (an estimate of the split's error).
    interpolated : int
        Samples whose deflection was interpolated (ill-conditioned, see ``bristle_deflection``).
    method : str
        Quadrature of the powers.
    bound : BoundCheck
        ``E_p <= Fs^2 / (2 sigma0)`` (``|z| <= Fs / sigma0``, 1995 property 1).
    """

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    direction: np.ndarray
    E_p: np.ndarray
    E_0: float
    W_u: np.ndarray
    E_d: np.ndarray
    D_sigma2: np.ndarray
    D_sigma1: np.ndarray
    D_viscous: np.ndarray
    D_hysteretic: np.ndarray
    residual: float
    interpolated: int
    method: str
    bound: BoundCheck

    def __len__(self) -> int:
        return len(self.t)

    @property
    def total_viscous(self) -> float:
        """Viscous dissipation from the first sample to the last reversal [J]."""
        return float(np.sum(self.D_viscous))

    @property
    def total_hysteretic(self) -> float:
        """Hysteretic dissipation from the first sample to the last reversal [J]."""
        return float(np.sum(self.D_hysteretic))

    def __repr__(self) -> str:
        return (
            f"LuGreEnergyReport({len(self)} reversals, E_0={self.E_0:.4g} J, E_p[-1]={self.E_p[-1]:.4g} J, "
            f"viscous={self.total_viscous:.4g} J, hysteretic={self.total_hysteretic:.4g} J, residual={self.residual:.2g})"
        )

    def summary(self) -> str:
        """Totals, balance and bound in a few lines."""
        lost = self.total_viscous + self.total_hysteretic
        share = self.total_hysteretic / lost if lost > 0 else 0.0
        return "\n".join([
            f"LuGre energy balance: {len(self)} reversals in samples (quadrature {self.method}); "
            f"{self.interpolated} samples with an interpolated bristle deflection",
            f"E_0 = {self.E_0:.6e} J, E_p from {self.E_p[0]:.6e} J (reversal 1) to {self.E_p[-1]:.6e} J (reversal {len(self)}), "
            f"input work {float(np.sum(self.W_u)):.6e} J",
            f"dissipated up to the last reversal: viscous {self.total_viscous:.6e} J, "
            f"hysteretic {self.total_hysteretic:.6e} J ({100 * share:.2f} % of the loss)",
            f"balance E_p(i-1) + W_u(i) - E_p(i) = D_viscous(i) + D_hysteretic(i): max relative residual {self.residual:.3e}",
            self.bound.format().splitlines()[0],
        ])

    def format(self, max_rows: int = 20) -> str:
        """Per-half-cycle table (at most ``max_rows`` rows) followed by :meth:`summary`."""
        head = (f"{'i':>5} {'t [s]':>12} {'F [N]':>12} {'E_p [J]':>11} {'E_d [J]':>11} "
                f"{'viscous [J]':>11} {'hyster. [J]':>11} {'W_u [J]':>11}")
        n = len(self)
        first, last = (max_rows + 1) // 2, max_rows // 2  # max_rows rows: the first and last halves
        idx = list(range(n)) if n <= max_rows else list(range(first)) + list(range(n - last, n))
        lines = ["LuGre energy per half-cycle i (ending at reversal i; i = 1 the first excursion)", head, "-" * len(head)]
        prev = -1
        for i in idx:
            if i != prev + 1:
                lines.append(f"{'...':>5}")
            cells = f"{self.E_d[i]:>11.4e} {self.D_viscous[i]:>11.4e} {self.D_hysteretic[i]:>11.4e} {self.W_u[i]:>11.4e}"
            lines.append(f"{i + 1:>5} {self.t[i]:>12.6g} {self.F[i]:>12.5g} {self.E_p[i]:>11.4e} {cells}")
            prev = i
        return "\n".join(lines + ["", self.summary()])


def analyze_lugre_samples(
    t: np.ndarray, v: np.ndarray, F: np.ndarray, rev: SampledReversals, W: np.ndarray, *, system: Oscillator, method: str
) -> LuGreEnergyReport:
    """The report of validated samples of a LuGre oscillator (called by ``analyze_samples``):
    ``rev`` the reversals in the samples, ``W`` the input's work over the first excursion and
    each half-cycle [J] (length ``len(rev)``)."""
    friction: LuGre = system.friction
    split = half_cycle_split(t, v, F, rev, friction, method)
    F_rev = friction.sigma0 * split["z_rev"]  # v = 0 and z' = 0 at a reversal: F = sigma0 z
    E_p = F_rev**2 / (2.0 * friction.sigma0)
    z0 = float(split["z"][0])
    E_0 = 0.5 * system.mass * float(v[0]) ** 2 + 0.5 * friction.sigma0 * z0 * z0
    s2, s1, h = (np.concatenate(([first], half)) for first, half in zip(split["first"], split["half"]))
    E_d = np.concatenate(([E_0], E_p[:-1])) + W - E_p
    lost = E_d - s2 - s1 - h
    scale = max(E_0, float(np.max(E_p)))
    return LuGreEnergyReport(
        t=rev.t, x=rev.x, F=F_rev, direction=rev.direction, E_p=E_p, E_0=E_0, W_u=W, E_d=E_d,
        D_sigma2=s2, D_sigma1=s1, D_viscous=s2 + s1, D_hysteretic=h,
        residual=float(np.max(np.abs(lost)) / scale) if scale > 0 else float(np.max(np.abs(lost))),
        interpolated=split["interpolated"], method=method, bound=lugre_bound(E_p, friction, E_0),
    )


def lugre_table_energy(F: Any, friction: LuGre) -> np.ndarray:
    """Stored bristle energy ``F^2 / (2 sigma0)`` [J] at reversals with friction forces ``F`` [N]."""
    F = np.asarray(F, dtype=float)
    return F * F / (2.0 * friction.sigma0)
