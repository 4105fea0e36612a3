"""Force-displacement curves of N elastic-plastic (Jenkin) elements in parallel, and their energies.

Elements ``i`` with normalised stiffnesses ``kappa_i`` and slip forces ``w_i`` (normalised
units, ``docs/mathematics.md``; :class:`prefriction.MaxwellSlip`, and the elements of
:class:`prefriction.GMS` at rest): with the slip deflections ``Delta_i = w_i / kappa_i``, the
virgin curve is ``phi(y) = sum_i min(kappa_i y, w_i)`` (piecewise linear, concave,
``phi(0) = 0``). Its integral ``Phi(y) = int_0^y phi`` is the energy stored on it, and the
complementary energy ``Phi*(f) = int_0^f phi^-1`` gives the energy a Masing branch returns
after a reversal at ``|F| = a``: ``E_p = 4 Phi*(a / 2)`` (Masing's rule; W. D. Iwan, "A
distributed-element model for hysteresis and its steady-state dynamic response", J. Appl.
Mech. 33 (1966) 893-900).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["VirginCurve", "unloading_energy"]


class VirginCurve:
    """The normalised virgin curve ``phi`` of elements ``(kappa, w)``, with its integrals.

    Elements sorted by slip deflection ``Delta``: breakpoints ``y_j`` (``y_0 = 0``, then the
    sorted ``Delta``), forces ``F_j = phi(y_j)``, slopes ``k_j`` on ``[y_j, y_{j+1}]`` (``k_N =
    0``), stored energies ``P_j = Phi(y_j)`` and complementary energies ``C_j = Phi*(F_j)``.

    Parameters
    ----------
    kappa : numpy.ndarray
        Normalised element stiffnesses ``k_i / sigma`` [-], each > 0.
    w : numpy.ndarray
        Normalised element slip forces ``W_i / Fc`` [-], each > 0, as many as ``kappa``.
    """

    def __init__(self, kappa: np.ndarray, w: np.ndarray) -> None:
        self._kappa, self._w = kappa, w
        delta = w / kappa
        order = np.argsort(delta, kind="stable")
        d, kap, ww = delta[order], kappa[order], w[order]
        n = d.size
        self.y = np.concatenate(([0.0], d))
        # slope after breakpoint j: sticking elements (those with larger Delta)
        tail = np.concatenate((np.cumsum(kap[::-1])[::-1], [0.0]))  # tail[j] = sum_{i >= j} kap[i]
        self.k = tail  # k[j] = slope on [y_j, y_{j+1}] (sorted elements j.. still stick), k[n] = 0
        head = np.concatenate(([0.0], np.cumsum(ww)))  # sum of w of the first j elements
        self.F = head + self.y * tail  # phi(y_j) = sum_{i<j} w_i + y_j sum_{i>=j} kappa_i
        self.F[0] = 0.0
        dy = np.diff(self.y)
        self.P = np.concatenate(([0.0], np.cumsum(dy * (self.F[:-1] + self.F[1:]) / 2.0)))
        dF = np.diff(self.F)
        self.C = np.concatenate(([0.0], np.cumsum(dF * (self.y[:-1] + self.y[1:]) / 2.0)))
        self.n = n

    def segment_of_force(self, f: np.ndarray) -> np.ndarray:
        """Index ``j`` of the segment ``F_j <= f < F_{j+1}`` (``n`` at and beyond ``F_n``)."""
        j = np.searchsorted(self.F, f, side="right") - 1
        return np.clip(j, 0, self.n)

    def inverse(self, f: np.ndarray) -> np.ndarray:
        """``phi^-1(f)`` for ``0 <= f`` (``max Delta`` at and beyond ``phi = 1``)."""
        f = np.asarray(f, dtype=float)
        j = self.segment_of_force(f)
        k = self.k[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            y = self.y[j] + np.where(k > 0.0, (f - self.F[j]) / np.where(k > 0.0, k, 1.0), 0.0)
        return y

    def stored(self, f: np.ndarray) -> np.ndarray:
        """``Phi(phi^-1(f))``: energy stored on the virgin curve from 0 up to the force ``f``."""
        f = np.minimum(np.asarray(f, dtype=float), self.F[-1])
        j = self.segment_of_force(f)
        y = self.inverse(f)
        return self.P[j] + (y - self.y[j]) * (self.F[j] + f) / 2.0

    def complementary(self, f: np.ndarray) -> np.ndarray:
        """``Phi*(f) = int_0^f phi^-1``, ``0 <= f <= phi(max Delta)`` (clipped)."""
        f = np.minimum(np.asarray(f, dtype=float), self.F[-1])
        j = self.segment_of_force(f)
        y = self.inverse(f)
        return self.C[j] + (f - self.F[j]) * (self.y[j] + y) / 2.0

    def loaded(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """Element forces and slip flags ``(z, m)`` on the virgin curve at the force ``f0``.

        Loading from ``z = 0`` to the normalised force ``f0`` (``|f0| <= 1``): the elements with
        the smallest slip deflections are at their limit ``sign(f0) w_i``, the others at
        ``sign(f0) kappa_i phi^-1(|f0|)``; those at their limit slip (``m_i = 1``) if ``s`` is
        the direction of ``f0``. Beyond the end of the curve every element is at its limit.
        """
        n = self.n
        if f0 == 0.0:
            return [0.0] * n, [0.0] * n
        kappa, w = self._kappa, self._w
        a = abs(f0)
        j = int(self.segment_of_force(np.array(a)))
        y = float(self.inverse(np.array(a)))
        order = np.argsort(w / kappa, kind="stable")
        at_limit = np.zeros(n, dtype=bool)
        at_limit[order[:j]] = True  # segment j: the j smallest slip deflections are at their limit
        sg = 1.0 if f0 > 0 else -1.0
        z = [sg * float(w[i]) if at_limit[i] else sg * float(kappa[i]) * y for i in range(n)]
        m = [1.0 if (at_limit[i] and s * sg > 0) else 0.0 for i in range(n)]
        return z, m


def unloading_energy(g: np.ndarray, slipping: np.ndarray, kappa: np.ndarray, w: np.ndarray) -> float:
    """Normalised work ``-int F~ dx~`` an unloading branch returns until its force crosses zero.

    Every element followed exactly: a sticking one at slope ``kappa_i`` until it reaches its
    slip force ``w_i``, then at its limit.

    Parameters
    ----------
    g : numpy.ndarray
        Element forces in the direction of motion, ``s z_i`` [-], with ``sum g < 0`` (unloading).
    slipping : numpy.ndarray
        True for the elements that slip (they stay at their limit).
    kappa, w : numpy.ndarray
        Normalised element stiffnesses and slip forces [-].

    Returns
    -------
    float
        The energy [``Fc^2 / sigma``].

    Raises
    ------
    ValueError
        If the branch never reaches zero force (the elements' slip forces sum to less than the
        unloading force; impossible for ``|F~| <= 1``).
    """
    room = np.where(slipping, 0.0, np.maximum(w - g, 0.0))
    brk = room / kappa  # distance to each element's slip
    order = np.argsort(brk, kind="stable")
    f, K, d, E = math.fsum(g.tolist()), math.fsum(kappa[room > 0.0].tolist()), 0.0, 0.0
    for i in order:
        if f >= 0.0:
            break
        if room[i] <= 0.0:
            continue
        step = brk[i] - d
        if K > 0.0 and f + K * step >= 0.0:  # zero crossing on this segment
            L = -f / K
            return E + 0.5 * (-f) * L
        E -= step * (f + 0.5 * K * step)
        f += K * step
        d = brk[i]
        K -= kappa[i]
        K = max(K, 0.0)
    if f < 0.0:  # cannot happen for |F~| <= 1: all slipping gives f = 1
        if K > 0.0:
            return E + 0.5 * f * f / K
        raise ValueError("branch_energy: the branch never reaches zero force from this state")
    return E
