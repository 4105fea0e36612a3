"""The slip events and the reversal map of :class:`prefriction.GMS` (the mixin :class:`GMSSlips`).

A sticking element ``j`` slips when ``s (z_j + kappa_j r)`` reaches ``alpha_j S~(v~)``, its
share of the Stribeck curve at the current velocity; a sticking element at the same normalised
force (within :data:`~prefriction.models.elements.TIE`) slips with it. A reversal keeps every
``z_j`` and clears the flags, putting a sticking element within ``snap`` of its limit
``alpha_j S~(0)`` on it. The protocol and the run-time numbers ``q``: the notes of
:mod:`prefriction.models.gms`.
"""

from __future__ import annotations

from typing import Any, Sequence

import casadi as ca

from prefriction.models.elements import TIE, symbolic

__all__ = ["GMSSlips"]


class GMSSlips:
    """Slip indicators, slip events and reversals of a GMS (module notes); mixin of
    :class:`prefriction.GMS`, which supplies ``n_elements``, the Stribeck curve ``_S`` and the
    element helpers ``_selected`` and ``_put_on_limits`` of
    :class:`~prefriction.models.elements.ParallelElements`."""

    def _indicator(self, j: int, z: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        """Slip indicator of element ``j``: ``1 - s (z_j + kappa_j r) / (alpha_j S~(v))``."""
        n = self.n_elements
        return 1.0 - s * (z[j] + q[j] * z[n]) / (q[n + j] * self._S(v, q, 3 * n))

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        n = self.n_elements
        sym = symbolic(z, m, s, q)
        mn = list(m)
        mn[k] = 1.0 + 0.0 * q[n + k]
        # the firing element is at its limit: s (z_k + kappa_k r) / alpha_k = S~(v). A sticking
        # element j at the same normalised force (within TIE) reaches its limit at this instant
        gk = s * (z[k] + q[k] * z[n]) * (1.0 - TIE)
        for j in range(n):
            if j == k:
                continue
            hit = s * (z[j] + q[j] * z[n]) * q[n + k] >= gk * q[n + j]
            if sym:
                mn[j] = ca.if_else(ca.logic_and(m[j] < 0.5, hit), 1.0, m[j])
            elif m[j] < 0.5 and hit:
                mn[j] = 1.0
        return list(z), mn

    def _event_at(self, is_k: list, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """:meth:`on_event` for the symbolic index of :meth:`on_event_at`: the element that fired
        starts to slip, and every sticking one at its normalised force (within ``TIE``)."""
        n = self.n_elements
        loads = [z[j] + q[j] * z[n] for j in range(n)]
        alpha_k = self._selected(is_k, [q[n + j] for j in range(n)])
        gk = s * self._selected(is_k, loads) * (1.0 - TIE)
        mn = list(m)
        for j in range(n):
            hit = s * loads[j] * alpha_k >= gk * q[n + j]
            mn[j] = ca.if_else(ca.logic_or(is_k[j], ca.logic_and(m[j] < 0.5, hit)), 1.0, m[j])
        return list(z), mn

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        """A sticking element within ``snap`` of its limit ``alpha_j S~(0)`` is put on it."""
        n = self.n_elements
        S0 = 1.0 + q[3 * n]  # S~ at v = 0: Fs / Fc
        return self._put_on_limits(z, m, s_new, q, snap, [q[n + j] * S0 for j in range(n)], sticking_only=True)
