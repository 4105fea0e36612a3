"""Maxwell-slip friction: N elastic-plastic (Jenkin) elements in parallel, through the protocol::

    F = sum_i F_i,   F_i' = k_i x' while |F_i| < W_i (sticking),   F_i = s W_i while slipping

Iwan's parallel model of elastic-plastic elements (W. D. Iwan, "A distributed-element model for
hysteresis and its steady-state dynamic response", J. Appl. Mech. 33 (1966) 893-900) in the
form of V. Lampaert, F. Al-Bender, J. Swevers, "A generalized Maxwell-slip friction model
appropriate for control purposes", Proc. 2003 IEEE Int. Conf. Physics and Control (PhysCon),
1170-1177, with constant slip forces (rate-independent). See :class:`MaxwellSlip` and
``docs/models.md#other-models``.

The virgin curve ``phi``, its integral ``Phi`` and complementary energy ``Phi*``, and the walk
along an unloading branch element by element, are in :mod:`prefriction.models.element_curves`;
the element machinery shared with :class:`prefriction.GMS` is in
:mod:`prefriction.models.elements`.

**Energy.** :meth:`MaxwellSlip.branch_energy` and :meth:`MaxwellSlip.branch_energy_of_force`
(the stored energy ``E_p`` at a reversal, and where the force-only form is exact) and
``k_min``: :mod:`prefriction.models.maxwell_slip_energy`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import Parameter
from prefriction.models.closed_form import pick
from prefriction.models.elements import MAX_ELEMENTS, TIE, ParallelElements, symbolic
from prefriction.models.maxwell_slip_energy import MaxwellSlipEnergy

__all__ = ["MaxwellSlip", "MAX_ELEMENTS"]


@dataclass(frozen=True, eq=False)
class MaxwellSlip(MaxwellSlipEnergy, ParallelElements):
    """Maxwell-slip friction: N elastic-plastic (Jenkin) elements in parallel (Iwan 1966; Lampaert,
    Al-Bender and Swevers 2003, "A generalized Maxwell-slip friction model appropriate for
    control purposes", with constant slip forces).

    Element ``i`` is a spring ``k_i`` in series with a Coulomb slider of slip force ``W_i``:
    with deflection ``d_i`` it carries ``k_i d_i``; it sticks (``d_i' = x'``) while
    ``|k_i d_i| < W_i`` and slips at ``k_i d_i = s W_i`` (``d_i' = 0``, ``s = sign(x')``) until
    the velocity reverses, when every element sticks again. The friction force is
    ``F = sum_i k_i d_i``. Rate-independent.

    Parameters
    ----------
    stiffness : array_like
        Element stiffnesses ``k_i`` [N/m]: 1-D, 1 to 100 entries, each finite and > 0.
    slip_force : array_like
        Element slip forces ``W_i`` [N]: 1-D, as many entries as ``stiffness``, each finite
        and > 0.

    Raises
    ------
    TypeError
        If an argument is not an array of real numbers.
    ValueError
        If an argument is not 1-D, has fewer than 1 or more than 100 entries, an entry that is
        not finite and > 0, or the lengths differ. The message names the argument, the value
        and the allowed range.

    Notes
    -----
    Normalised units (``docs/models.md``): ``sigma = sum k_i`` (the rest stiffness: every
    element sticks after a reversal) and ``Fc = sum W_i`` (the force in gross sliding). With
    ``kappa_i = k_i / sigma`` and ``w_i = W_i / Fc`` the run-time numbers are ``q = (kappa_1..N,
    w_1..N)``; the structure is ``N`` alone, so one compiled plant serves every model with the
    same number of elements.

    Protocol: states ``z_i = k_i d_i / Fc`` (the normalised element forces; ``F~ = sum z_i``),
    rates ``z_i' = kappa_i v~ (1 - m_i)``, flags ``m_i`` (element ``i`` slips), one event per
    element, indicator ``1 - s z_i / w_i`` while it sticks (``+1`` while it slips); the event
    sets ``z_i = s w_i`` exactly, ``m_i = 1`` (and slips with it any sticking element within
    :data:`~prefriction.models.elements.TIE` of its limit: equal slip deflections). A reversal
    keeps every ``z_i`` and clears every flag; a sticking element within ``snap`` of its limit
    there is put on it (a reversal at the onset of slip). ``initial_state(f0, s)`` is the state
    on the virgin curve (loading from ``z = 0``) with the force ``f0``.

    One more state, the *retrace guard* ``r`` of :mod:`prefriction.models.elements` (zero on
    every branch, reset by ``reverse``): the indicators are ``1 - s (z_i + kappa_i r) / w_i``.

    **Masing rule** (derived in ``maxwell_slip_exact``): whatever the state, the branch that
    starts at a reversal ``(x_r, F_r)`` in direction ``s`` is ``F = F_r + 2 s phi_SI(s (x - x_r)
    / 2)`` (the virgin curve :meth:`virgin_curve` stretched by 2 in both axes) over at least the
    span of the preceding half-cycle: the elements at their limit at the reversal reach the
    opposite limit after ``2 W_i / k_i``, the others come back to where the preceding
    half-cycle started them first.

    **Energy.** :meth:`branch_energy` (from the state) and :meth:`branch_energy_of_force` (the
    Masing branch, ``4 Phi*(|F~| / 2)``) give the potential energy ``E_p`` at a reversal; they
    agree at every reversal of unforced motion (notes of
    :mod:`prefriction.models.maxwell_slip_energy`).

    ``k_min`` is the least tangent stiffness on an unloading branch from ``|F| <= Fc`` (the Masing
    branch of a reversal at ``-Fc`` crosses zero where the virgin curve reaches ``Fc / 2``): the
    slope of the virgin curve just below ``F = Fc / 2``. It is ``sigma`` if every slip
    deflection ``W_i / k_i`` is at least the virgin deflection at ``Fc / 2``, less otherwise
    (elements with small slip deflections slip before the zero crossing); then ``E_p`` after a
    reversal at ``|F| = Fc`` exceeds ``Fc^2 / (2 sigma)`` and the bound (2.12) needs this
    ``k_min``.

    Examples
    --------
    >>> import prefriction as pf
    >>> model = pf.MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.3])
    >>> model.sigma, model.Fc
    (100000.0, 1.0)
    >>> [round(float(d) * 1e6, 3) for d in model.slip_deflections]  # W_i / k_i [um]
    [5.0, 13.333, 30.0]
    """

    stiffness: Any
    slip_force: Any

    parameters: ClassVar[tuple[Parameter, ...]] = (
        Parameter("stiffness", "N/m", 0.0, math.inf, low_open=True),
        Parameter("slip_force", "N", 0.0, math.inf, low_open=True),
    )

    _stiffness_field: ClassVar[str] = "stiffness"
    rate_independent = True

    def _validate(self) -> None:
        """Check both arrays elementwise (each entry in the declared range) and their lengths."""
        self._element_arrays(("stiffness", "N/m"), ("slip_force", "N"))

    # --- normalisation ---------------------------------------------------------------------
    @property
    def Fc(self) -> float:  # type: ignore[override]
        """Gross-sliding force ``sum W_i`` [N]."""
        return math.fsum(self.slip_force.tolist())

    @property
    def slip_deflections(self) -> np.ndarray:
        """Element slip deflections ``W_i / k_i`` [m]."""
        return self.slip_force / self.stiffness

    def _element_fractions(self) -> tuple[np.ndarray, np.ndarray]:
        """``(kappa, w)``: the two halves of :meth:`runtime_params`."""
        q = self.runtime_params()
        n = self.n_elements
        return q[:n], q[n:]

    def virgin_curve(self, x: Any) -> np.ndarray:
        """Force [N] on the virgin curve at displacement ``x`` [m] from the unloaded state
        (odd in ``x``): ``sign(x) sum_i min(k_i |x|, W_i)``."""
        x = np.asarray(x, dtype=float)
        return np.sign(x) * np.minimum(np.abs(x)[..., None] * self.stiffness, self.slip_force).sum(axis=-1)

    def runtime_params(self) -> np.ndarray:
        """``(kappa_1..N, w_1..N)``: ``k_i / sigma`` and ``W_i / Fc``."""
        return np.concatenate((self.stiffness / self.sigma, self.slip_force / self.Fc))

    # --- dynamics -------------------------------------------------------------------------
    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        n = self.n_elements
        return [q[i] * v * (1.0 - m[i]) for i in range(n)] + [self._guard_rate(v, s)]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        total = z[0]
        for i in range(1, self.n_elements):
            total = total + z[i]
        return total

    def _indicator(self, j: int, z: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        """Slip indicator of element ``j``: ``1 - s (z_j + kappa_j r) / w_j`` (``r = 0`` on a
        branch; independent of the velocity ``v``)."""
        n = self.n_elements
        return 1.0 - s * (z[j] + q[j] * z[n]) / q[n + j]

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        n = self.n_elements
        sym = symbolic(z, m, s, q)
        zn, mn = list(z), list(m)
        for j in range(n):
            w = q[n + j]
            if j == k:
                zn[j], mn[j] = s * w, 1.0 + 0.0 * w
                continue
            ind = self._indicator(j, z, None, s, q)
            if sym:
                hit = ca.logic_and(m[j] < 0.5, ind <= TIE)
                zn[j] = ca.if_else(hit, s * w, z[j])
                mn[j] = ca.if_else(hit, 1.0, m[j])
            elif m[j] < 0.5 and ind <= TIE:
                zn[j], mn[j] = s * w, 1.0
        return zn, mn

    def _event_at(self, is_k: list, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """:meth:`on_event` for the symbolic index of :meth:`on_event_at`: the element that fired,
        and every sticking one within ``TIE`` of its limit, put on its limit."""
        n = self.n_elements
        zn, mn = list(z), list(m)
        for j in range(n):
            ind = self._indicator(j, z, None, s, q)
            hit = ca.logic_or(is_k[j], ca.logic_and(m[j] < 0.5, ind <= TIE))
            zn[j] = ca.if_else(hit, s * q[n + j], z[j])
            mn[j] = ca.if_else(hit, 1.0, m[j])
        return zn, mn

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        """Every element within ``snap`` of its slip force ``w_j`` (or slipping) is put on it."""
        n = self.n_elements
        return self._put_on_limits(z, m, s_new, q, snap, [q[n + j] for j in range(n)], sticking_only=False)

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """Exact step over ``dt`` at the constant velocity ``v``: the stop operator per element
        (``docs/along.md#exact-steps``). A sticking element moves by ``kappa_i v dt`` up to its
        limit ``s w_i`` (within :data:`~prefriction.models.elements.TIE`), where it slips."""
        n = self.n_elements
        zn, mn = list(z), list(m)
        for i in range(n):
            w = q[n + i]
            z1 = z[i] + q[i] * (v * dt) * (1.0 - m[i])  # v dt: the displacement (exact where v = dx / dt)
            hit = s * z1 >= w * (1.0 - TIE)
            zn[i], mn[i] = pick(hit, s * w, z1), pick(hit, 1.0, m[i])
        return zn, mn

