"""How close a closed loop came to its reference: the residual error, its PD bound and the
settling time of a :class:`controllers.LoopResult` (the mixin :class:`LoopSettling`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional

import numpy as np

from prefriction._validation import check_positive

if TYPE_CHECKING:
    from prefriction.models import Oscillator

__all__ = ["LoopSettling"]


class LoopSettling:
    """Residual error, PD bound and settling time of a loop (mixin of
    :class:`controllers.LoopResult`, which holds ``t``, ``reference``, ``x``, ``error``,
    ``kp`` and ``system``)."""

    t: np.ndarray
    reference: np.ndarray
    x: np.ndarray
    error: np.ndarray
    kp: Optional[float]
    system: "Oscillator"

    @property
    def residual_error(self) -> float:
        """Error ``r - x`` at the last output time [m]."""
        return float(self.error[-1])

    @property
    def error_bound(self) -> Optional[float]:
        """``F_max / kp`` [m], the bound of the residual error of a PD loop at rest; ``None`` otherwise.

        At rest the control force ``kp e`` balances the friction force, at most the model's
        largest force at rest ``F_max`` (``max_hysteretic_force``: ``Fc`` for Dahl and
        Maxwell-slip, the static force ``Fs`` for LuGre)."""
        return None if self.kp is None else self.system.friction.max_hysteretic_force / self.kp

    @property
    def settling_time(self) -> float:
        """Settling time [s] into a 2 % band of the reference's travel (:meth:`settling_time_within`
        with ``band = 0.02``)."""
        return self.settling_time_within(0.02)

    def settling_time_within(self, band: float) -> float:
        """First time [s] after which the error ``|r - x|`` stays within ``band`` of the reference's travel.

        Measured against the reference, not the final position: the travel is
        ``max |r(t) - x(0)|`` over the run (a step's height, a move's distance, a sine's peak
        excursion from the start), and the loop has settled once ``|r - x| <= band * travel`` at
        every later output sample. A PD loop that stops short of the target by more than the
        band never settles; a tracking loop settles once its error stays small.

        Parameters
        ----------
        band : float
            Relative band [-], ``0 < band < inf`` (0.02 for the usual 2 % settling time).

        Returns
        -------
        float
            The time [s]; ``inf`` if the error is outside the band at the last output sample
            (not settled within the run), ``nan`` if the reference never leaves ``x(0)``.
        """
        band = check_positive("band", band)
        travel = float(np.max(np.abs(self.reference - self.x[0])))
        if travel == 0.0:
            return math.nan
        outside = np.nonzero(np.abs(self.error) > band * travel)[0]
        if outside.size == 0:
            return float(self.t[0])
        if outside[-1] == len(self.t) - 1:
            return math.inf
        return float(self.t[outside[-1] + 1])
