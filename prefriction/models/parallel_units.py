"""The units and run-time numbers of a sum of friction models (:class:`prefriction.Parallel`).

:class:`ParallelUnits` is the mixin of :class:`~prefriction.models.parallel.Parallel` that holds
its reference stiffness and force, its summed bounds and the composition of the models'
run-time numbers ``q = (phi_i, tau_i, q_i)`` (the class notes of ``Parallel``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

if TYPE_CHECKING:
    from prefriction.models.base import FrictionModel
    from prefriction.units import Scales

__all__ = ["ParallelUnits"]


@dataclass(frozen=True)
class _Units:
    """The normalised units of one model of a sum for a system of mass ``mass`` (floats or CasADi
    symbols): what :meth:`FrictionModel.runtime_params_for` reads."""

    x: Any
    F: Any
    t: Any
    v: Any
    E: Any

    @classmethod
    def of(cls, sigma: Any, Fc: Any, mass: Any) -> "_Units":
        return cls(Fc / sigma, Fc, (mass / sigma) ** 0.5, Fc / (mass * sigma) ** 0.5, Fc * Fc / sigma)


class ParallelUnits:
    """Units of a sum (mixin of :class:`~prefriction.models.parallel.Parallel`, which holds the
    tuple ``models``): reference stiffness and force, summed bounds, run-time numbers."""

    models: tuple

    @property
    def _stateful(self) -> list[FrictionModel]:
        return [m for m in self.models if m.n_states > 0]

    @property
    def sigma(self) -> float:  # type: ignore[override]
        """Reference stiffness [N/m]: the sum over the models with a state (class notes)."""
        return math.fsum(m.sigma for m in self._stateful) if self._stateful else 1.0

    @property
    def Fc(self) -> float:  # type: ignore[override]
        """Reference force [N]: the sum over the models with a state (class notes)."""
        return math.fsum(m.Fc for m in self._stateful) if self._stateful else 1.0

    @property
    def max_hysteretic_force(self) -> float:  # type: ignore[override]
        """The sum of the models' largest forces at rest [N]."""
        return math.fsum(m.max_hysteretic_force for m in self.models)

    @property
    def k_min(self) -> float:
        """The sum of the models' least unloading stiffnesses [N/m]."""
        return math.fsum(m.k_min for m in self.models)

    def compose(self, units: Sequence[tuple[Any, Any, Any]]) -> tuple[Any, Any, list[Any]]:
        """``(sigma, Fc, q)`` of the sum from each model's ``(sigma_i, Fc_i, q_i)`` (floats or
        CasADi symbols; the fit passes symbols): the units and run-time numbers of the class notes."""
        live = [(s, f) for m, (s, f, _q) in zip(self.models, units) if m.n_states > 0]
        sigma = sum(s for s, _f in live) if live else 1.0
        Fc = sum(f for _s, f in live) if live else 1.0
        q: list[Any] = []
        for s_i, f_i, q_i in units:
            q += [f_i / Fc, (s_i / sigma) ** 0.5] + [q_i[j] for j in range(_len(q_i))]
        return sigma, Fc, q

    def runtime_params_for(self, scales: "Scales") -> np.ndarray:
        """``q = (phi_i, tau_i, q_i)`` with each model's numbers for the system's mass."""
        mass = self.sigma * scales.t ** 2
        units = [(m.sigma, m.Fc, m.runtime_params_for(_Units.of(m.sigma, m.Fc, mass))) for m in self.models]
        return np.array(self.compose(units)[2], dtype=float)

    def runtime_params(self) -> np.ndarray:
        """``q`` for a unit mass."""
        return self.runtime_params_for(_Units.of(self.sigma, self.Fc, 1.0))


def _len(q: Any) -> int:
    """Length of a run-time vector (numpy array, list or CasADi column)."""
    return int(q.shape[0]) if hasattr(q, "shape") and len(q.shape) > 0 else len(q)
