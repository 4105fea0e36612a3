"""The elasto-plastic friction law for the scipy reference of :mod:`prefriction.identify.synthetic_events`.

Written in SI units from the equations of P. Dupont, V. Hayward, B. Armstrong, F. Altpeter,
"Single state elastoplastic friction models", IEEE Trans. Automatic Control 47(5), 787-792,
2002, eqs. (7)-(9) (``docs/models.md#elasto-plastic``), not from
:mod:`prefriction.models.elasto_plastic` (only the model's numbers are read)::

    z' = v - alpha(z, v) sigma0 |v| z / f_ss(v),   f_ss(v) = Fc + (Fs - Fc) exp(-(v / vs)^2),   (7)
    F  = sigma0 z + sigma1 z' + sigma2 v,                                                       (8)
    alpha = 0                                     |z| <= z_ba or sign(z) != sign(v)             (9)
          = (1 + sin(pi (|z| - (z_ss + z_ba) / 2) / (z_ss - z_ba))) / 2    z_ba < |z| < z_ss(v)
          = 1                                     |z| >= z_ss(v) = f_ss(v) / sigma0.

``alpha`` is evaluated from (9) everywhere; it is C1 but not C2 at ``|z| = z_ba`` and
``|z| = z_ss``, so on each branch (``s = sign(v)`` fixed) the breakaway ``s z = z_ba`` and the
first saturation ``s z = z_ss(v)`` are terminal events of ``solve_ivp`` (flags ``broke``,
``sat``) and the integration restarts there. A velocity reversal keeps ``z``; the new branch
starts broken if ``s z > z_ba`` and saturated if ``s z >= z_ss(0)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["ElastoPlasticLaw"]


class ElastoPlasticLaw:
    """The law of one :class:`prefriction.ElastoPlastic` for
    :func:`~prefriction.identify.synthetic_events.event_motion`: state ``[z]`` (bristle deflection
    [m]), two events per branch (0 breakaway, 1 saturation)."""

    kind = "ElastoPlastic"
    n = 1
    n_events = 2

    def __init__(self, model: Any) -> None:
        self.sigma0, self.sigma1, self.sigma2 = float(model.sigma0), float(model.sigma1), float(model.sigma2)
        self.Fc, self.Fs, self.vs, self.z_ba = float(model.Fc), float(model.Fs), float(model.vs), float(model.z_ba)
        self.stiffness = self.sigma0
        self.state_scale = self.Fc / self.sigma0

    def f_ss(self, v: float) -> float:
        """Steady-state force ``f_ss(v)`` [N] of (7)."""
        return self.Fc + (self.Fs - self.Fc) * math.exp(-((v / self.vs) ** 2))

    def alpha(self, z: float, v: float) -> float:
        """``alpha(z, v)`` of (9)."""
        zss = self.f_ss(v) / self.sigma0
        if math.copysign(1.0, z) != math.copysign(1.0, v) or abs(z) <= self.z_ba:
            return 0.0
        if abs(z) >= zss:
            return 1.0
        return 0.5 + 0.5 * math.sin(math.pi * (abs(z) - 0.5 * (zss + self.z_ba)) / (zss - self.z_ba))

    def to_state(self, F: np.ndarray, s: float) -> np.ndarray:
        """The virgin state: ``z = 0``."""
        return np.zeros(1)

    def rates(self, z: np.ndarray, v: float, s: float, sat: np.ndarray) -> np.ndarray:
        """``z'`` of (7) [m/s]."""
        return np.array([v - self.alpha(z[0], v) * self.sigma0 * abs(v) * z[0] / self.f_ss(v)])

    def friction(self, z: np.ndarray, v: float, s: float, sat: np.ndarray) -> float:
        """``F`` of (8) [N]."""
        return self.sigma0 * z[0] + self.sigma1 * self.rates(z, v, s, sat)[0] + self.sigma2 * v

    def watched(self, i: int, sat: np.ndarray) -> bool:
        """Breakaway until it happens; the saturation after the breakaway until it happens."""
        return not sat[0] if i == 0 else bool(sat[0] and not sat[1])

    def indicators(self, z: np.ndarray, v: float, s: float) -> np.ndarray:
        """``[z_ba - s z, z_ss(v) - s z]`` [m], positive before each event."""
        return np.array([self.z_ba - s * z[0], self.f_ss(v) / self.sigma0 - s * z[0]])

    def on_event(self, z: np.ndarray, i: int, s: float) -> np.ndarray:
        """``z`` on the breakaway limit ``s z_ba`` (its root, to round-off), unchanged at saturation."""
        return np.array([s * self.z_ba]) if i == 0 else np.array(z, dtype=float)

    def reverse(self, z: np.ndarray, s: float, sat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``z`` kept at a reversal to ``-s``; the flags of the new branch from ``z``."""
        w = -s * z[0]
        return np.array(z, dtype=float), np.array([w > self.z_ba, w >= self.f_ss(0.0) / self.sigma0])
