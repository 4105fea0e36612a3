"""The stored energy of :class:`prefriction.MaxwellSlip` on a branch, and its least unloading
stiffness ``k_min`` (the bound (2.12)).

:class:`MaxwellSlipEnergy` is the mixin of :class:`~prefriction.models.maxwell_slip.MaxwellSlip`
that holds them; the virgin curve ``phi``, its integral ``Phi``, the complementary energy
``Phi*`` and the walk along an unloading branch are in
:mod:`prefriction.models.element_curves`.

**Energy.** The energy analysis needs the potential energy ``E_p`` at a reversal: the work
``-int F dx`` that the new branch returns until its force crosses zero.
:meth:`MaxwellSlip.branch_energy` gives it from the state for any state on an unloading branch
(``s F <= 0``), elements that slip before the zero crossing included.
:meth:`MaxwellSlip.branch_energy_of_force` gives ``4 Phi*(|F~| / 2)`` for ``s F <= 0`` (the
Masing branch). The two agree (to 1e-14, checked on 14 000 random displacement histories from
the virgin state) at every unloading reversal whose preceding reversal force has the other sign
or is zero: the Masing branch then crosses zero before it reaches the preceding reversal point.
That covers **every reversal of unforced motion** from an initial state on the virgin curve (an
unforced mass reverses only with ``s F > 0``, so reversal forces alternate in sign). Under
forcing, a reversal before the force zero crossing makes two consecutive reversal forces of one
sign; the next branch then meets the earlier reversal point before its zero crossing and
continues along an older branch (Masing's memory rule), and the force-only value is wrong (by up
to 80 % in those tests): use ``branch_energy``. For ``s F > 0`` (loading) the stored energy is
not a function of the state at all (a full slip reached from reversals at different forces has
one state and different branches): both methods return the energy stored on the virgin curve,
``Phi(phi^-1(|F~|))``, right for the virgin-curve initial states.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from prefriction.models.element_curves import unloading_energy

__all__ = ["MaxwellSlipEnergy"]


class MaxwellSlipEnergy:
    """Energy of a Maxwell-slip model (mixin of :class:`~prefriction.models.maxwell_slip.MaxwellSlip`,
    which supplies ``sigma``, ``n_elements`` and the virgin curve ``_virgin``): ``k_min`` and the
    branch energies (module notes)."""

    @property
    def k_min(self) -> float:
        """Least tangent stiffness [N/m] on an unloading branch from a reversal at ``|F| <= Fc``:
        ``sigma`` times the slope of the virgin curve just below ``F = Fc / 2``."""
        v = self._virgin
        j = int(np.searchsorted(v.F, 0.5, side="left")) - 1  # F_j < 1/2 <= F_{j+1}
        return self.sigma * float(v.k[max(j, 0)])

    def branch_energy_of_force(self, F: np.ndarray, s: Any) -> np.ndarray:
        """Normalised stored energy on a branch of direction ``s`` at the normalised forces ``F``.

        ``s F <= 0`` (unloading, e.g. just after a reversal): ``4 Phi*(|F| / 2)``, the energy the
        Masing branch from a reversal at ``F`` returns until its force crosses zero; exact at a
        reversal whose preceding reversal force has the other sign, so at every reversal of
        unforced motion from an :meth:`initial_state` (module notes).
        ``s F > 0`` (loading): ``Phi(phi^-1(|F|))``, the energy stored on the virgin curve (exact
        for the virgin-curve initial states; the loading part of a later branch depends on its
        reversal, not on ``F`` alone).
        """
        F = np.asarray(F, dtype=float)
        sF = np.asarray(s, dtype=float) * F
        a = np.clip(np.abs(sF), 0.0, 1.0)
        v = self._virgin
        return np.where(sF <= 0.0, 4.0 * v.complementary(a / 2.0), v.stored(a))

    def branch_energy(self, z: Sequence[float], m: Sequence[float], s: float, q: Any) -> float:
        """Normalised energy stored on the current branch in state ``(z, m)``, direction ``s``.

        Unloading (``s F~ <= 0``): the work ``-int F~ dx~`` from the state to the force zero
        crossing, following every element exactly (sticking ones at slope ``kappa_i`` until
        they reach ``s w_i``), for any state. Loading (``s F~ > 0``): not a function of the
        state; :meth:`branch_energy_of_force` (the virgin curve).
        """
        n = self.n_elements
        qq = np.asarray(q, dtype=float)
        g = s * np.asarray(z[:n], dtype=float)
        f0 = math.fsum(g.tolist())
        if f0 > 0.0:
            return float(self.branch_energy_of_force(np.array([s * f0]), s)[0])
        return unloading_energy(g, np.asarray(m, dtype=float) > 0.5, qq[:n], qq[n:])
