"""A friction model in one file: a Bouc-Wen hysteretic element with a viscous damper.

Bouc-Wen (Wen 1976) with exponent n = 3 and gamma = 0, beta = 1 / Fy^3::

    F = Fy w + c v,      w' = (k / Fy) (v - |v| w^3)      (w = 1: the element slides at Fy)

On a branch of direction s (|v| = s v) in normalised units (docs/models.md#protocol):
``w' = v (1 - s w^3)``, ``F~ = w + c~ v``. The model gives only its mathematics; the base class
derives the units (sigma = k, Fc = Fy: the parameters in N/m and N), the run-time numbers
``q = [k~, Fy~, c~] = [1, 1, c V / Fy]`` (declared order, normalised by their units), the reset at
a reversal (w carries over), the initial state and the structure key. Run it:
``python examples/bouc_wen_model.py`` (a few seconds: one compile per structure).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import prefriction as pf
from prefriction.testing import check_model


@dataclass(frozen=True)
class BoucWen(pf.FrictionModel):
    """Bouc-Wen element: stiffness ``k`` [N/m], slide force ``Fy`` [N], damping ``c`` [N s/m]."""

    k: float
    Fy: float
    c: float = 0.0

    parameters = (pf.Parameter("k", "N/m", 0.0, math.inf, low_open=True),
                  pf.Parameter("Fy", "N", 0.0, math.inf, low_open=True),
                  pf.Parameter("c", "N s/m", 0.0, math.inf))
    n_states = 1

    def rate(self, z, m, v, s, q):
        return [v * (1.0 - s * z[0] ** 3)]

    def force(self, z, m, v, s, q):
        return z[0] + q[2] * v


def main() -> None:
    model = BoucWen(k=2e5, Fy=0.5, c=2.0)
    system = pf.Oscillator(model, mass=0.3, u=pf.signals.Sine(amplitude=0.8, frequency=40.0))
    res = pf.simulate(system, 0.0, t_end=0.1)  # forced: every reversal located
    t = np.linspace(0.0, 0.05, 501)
    along = pf.friction_along(model, t, 4e-6 * np.sin(2 * np.pi * 40.0 * t))
    check = check_model(model, reversals=6, t_end=60.0)  # against an independent scipy run
    print(f"{len(res.reversals)} reversals; F along x(t) in [{along.F.min():.4f}, {along.F.max():.4f}] N; "
          f"check_model: {check.n_reversals} reversals, error {check.max_error:.1e}")


if __name__ == "__main__":
    main()
