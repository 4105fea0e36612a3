"""Maxwell-slip friction: N elasto-plastic (Jenkin) elements in parallel, through the protocol.

Iwan's parallel model of elasto-plastic elements (W. D. Iwan, "A distributed-element model for
hysteresis and its steady-state dynamic response", J. Appl. Mech. 33 (1966) 893-900) in the
form of V. Lampaert, F. Al-Bender, J. Swevers, "A generalized Maxwell-slip friction model
appropriate for control purposes", Proc. 2003 IEEE Int. Conf. Physics and Control (PhysCon), 1170-1177, with constant slip
forces (rate-independent). See :class:`MaxwellSlip` and ``docs/models.md#other-models``.

The virgin curve and its Masing branches (all normalised, ``docs/mathematics.md``): with
``kappa_i = k_i / sigma``, ``w_i = W_i / Fc`` and the slip deflections ``Delta_i = w_i /
kappa_i``, the virgin curve is ``phi(y) = sum_i min(kappa_i y, w_i)`` (piecewise linear,
concave, ``phi(0) = 0``, ``phi' (0) = 1``, ``phi = 1`` beyond ``max Delta_i``). Its integral
``Phi(y) = int_0^y phi`` is the energy stored on it, and the complementary energy
``Phi*(f) = int_0^f phi^-1`` gives the energy a Masing branch returns after a reversal at
``|F| = a``: ``E_p = 4 Phi*(a / 2)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar, Hashable, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel, Parameter

__all__ = ["MaxwellSlip", "MAX_ELEMENTS"]

MAX_ELEMENTS = 64
"""Largest number of elements of a :class:`MaxwellSlip` model."""

TIE = 1e-12
"""Slip indicator (relative to the slip force) below which a sticking element slips together
with the element whose event fired: elements with equal slip deflections reach their limits at
the same instant to round-off, and an indicator that is already at or below zero after a
transition would never see the positive-to-negative crossing the integrator detects."""


def _symbolic(*groups: Any) -> bool:
    """True if any argument, or any entry of a list/tuple argument, is a CasADi symbol."""
    for g in groups:
        if isinstance(g, (ca.SX, ca.MX)):
            return True
        if isinstance(g, (list, tuple)):
            for x in g:
                if isinstance(x, (ca.SX, ca.MX)):
                    return True
    return False


def _positive_array(name: str, value: Any, unit: str) -> np.ndarray:
    """``value`` as a read-only 1-D float array of 1..MAX_ELEMENTS finite entries > 0, or raise
    ``TypeError``/``ValueError`` naming ``name``, the offending value and the allowed range."""
    allowed = f"a 1-D array of 1 to {MAX_ELEMENTS} finite numbers > 0 [{unit}]"
    if isinstance(value, (str, bytes, dict)) or value is None:
        raise TypeError(f"{name} must be {allowed}, got {value!r} of type {type(value).__name__}")
    try:
        raw = np.asarray(value)
    except Exception as exc:  # ragged nested sequences and the like
        raise TypeError(f"{name} must be {allowed}, got {value!r}") from exc
    if raw.dtype == bool or not (np.issubdtype(raw.dtype, np.integer) or np.issubdtype(raw.dtype, np.floating)):
        raise TypeError(f"{name} must be {allowed}, got {value!r} (dtype {raw.dtype})")
    arr = np.array(raw, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be {allowed}, got an array of shape {arr.shape}")
    if not 1 <= arr.size <= MAX_ELEMENTS:
        raise ValueError(f"{name} must hold 1 to {MAX_ELEMENTS} elements, got {arr.size} "
                         f"(allowed: 1 <= len({name}) <= {MAX_ELEMENTS})")
    bad = ~(np.isfinite(arr) & (arr > 0.0))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{i}] must be finite and > 0, got {float(arr[i])!r} "
                         f"(allowed range: 0 < {name}[i] < inf [{unit}])")
    arr.flags.writeable = False
    return arr


class _Virgin:
    """The normalised virgin curve ``phi`` of a Maxwell-slip model, with its integrals.

    Elements sorted by slip deflection ``Delta``: breakpoints ``y_j`` (``y_0 = 0``, then the
    sorted ``Delta``), forces ``F_j = phi(y_j)``, slopes ``k_j`` on ``[y_j, y_{j+1}]`` (``k_N =
    0``), stored energies ``P_j = Phi(y_j)`` and complementary energies ``C_j = Phi*(F_j)``.
    """

    def __init__(self, kappa: np.ndarray, w: np.ndarray) -> None:
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


@dataclass(frozen=True, eq=False)
class MaxwellSlip(FrictionModel):
    """Maxwell-slip friction: N elasto-plastic elements in parallel (Iwan 1966; Lampaert,
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
        Element stiffnesses ``k_i`` [N/m]: 1-D, 1 to 64 entries, each finite and > 0.
    slip_force : array_like
        Element slip forces ``W_i`` [N]: 1-D, as many entries as ``stiffness``, each finite
        and > 0.

    Raises
    ------
    TypeError
        If an argument is not an array of real numbers.
    ValueError
        If an argument is not 1-D, has fewer than 1 or more than 64 entries, an entry that is
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
    :data:`TIE` of its limit: equal slip deflections). A reversal keeps every ``z_i`` and clears
    every flag; a sticking element within ``snap`` of its limit there is put on it (a reversal
    at the onset of slip). ``initial_state(f0, s)`` is the state on the virgin curve (loading
    from ``z = 0``) with the force ``f0``.

    One more state, the *retrace guard* ``r`` (``r' = 2 max(-s v~, 0)``): zero on every branch,
    it grows only past a reversal inside a trial step of the integrator, where ``s (z_i + kappa_i
    r)`` keeps growing like the arc length travelled; the indicators are ``1 - s (z_i + kappa_i
    r) / w_i``. CasADi's integrator looks at the indicators at the ends of a step (and projects
    their zero crossings linearly): without the guard, an element that starts to slip shortly
    before a reversal has an indicator that dips below zero and comes back within one step, and
    the slip was missed (the element stuck on past its slip force). With the guard the indicator
    stays negative and keeps falling past the reversal. The guard enters no rate of ``x``, ``v``
    or ``z``, which stay smooth (a kink in the element rates themselves cost 30-100 ``rtol`` of
    accuracy). ``reverse`` resets it to zero. A slip within a few ten ``rtol`` (relative
    distance) of a reversal can still be missed; ``reverse`` then puts the element on its limit,
    which dissipates what the slip would have (only the force recorded at that reversal is off,
    by the overshoot).

    **Masing rule** (derived in ``maxwell_slip_exact``): whatever the state, the branch that
    starts at a reversal ``(x_r, F_r)`` in direction ``s`` is ``F = F_r + 2 s phi_SI(s (x - x_r)
    / 2)`` (the virgin curve :meth:`virgin_curve` stretched by 2 in both axes) over at least the
    span of the preceding half-cycle: the elements at their limit at the reversal reach the
    opposite limit after ``2 W_i / k_i``, the others come back to where the preceding
    half-cycle started them first.

    **Energy.** The energy analysis needs the potential energy ``E_p`` at a reversal: the work
    ``-int F dx`` that the new branch returns until its force crosses zero.
    :meth:`branch_energy` gives it from the state for any state on an unloading branch
    (``s F <= 0``), elements that slip before the zero crossing included.
    :meth:`branch_energy_of_force` gives ``4 Phi*(|F~| / 2)`` for ``s F <= 0`` (the Masing
    branch). The two agree (to 1e-14, checked on 14 000 random displacement histories from the
    virgin state) at every unloading reversal whose preceding reversal force has the other sign
    or is zero: the Masing branch then crosses zero before it reaches the preceding reversal
    point. That covers **every reversal of unforced motion** from an :meth:`initial_state` (an
    unforced mass reverses only with ``s F > 0``, so reversal forces alternate in sign). Under
    forcing, a reversal before the force zero crossing makes two consecutive reversal forces of
    one sign; the next branch then meets the earlier reversal point before its zero crossing
    and continues along an older branch (Masing's memory rule), and the force-only value is
    wrong (by up to 80 % in those tests): use :meth:`branch_energy`. For ``s F > 0`` (loading)
    the stored energy is not a function of the state at all (a full slip reached from reversals
    at different forces has one state and different branches): both methods return the energy
    stored on the virgin curve, ``Phi(phi^-1(|F~|))``, right for the virgin-curve initial
    states.

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

    def __post_init__(self) -> None:
        self._validate()

    def _validate(self) -> None:
        """Check both arrays elementwise (each entry in the declared range) and their lengths."""
        k = _positive_array("stiffness", self.stiffness, "N/m")
        W = _positive_array("slip_force", self.slip_force, "N")
        if k.size != W.size:
            raise ValueError(f"stiffness and slip_force must have the same length (one entry per element), "
                             f"got {k.size} and {W.size}")
        object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "slip_force", W)

    def __eq__(self, other: object) -> bool:
        return (type(other) is type(self) and np.array_equal(self.stiffness, other.stiffness)
                and np.array_equal(self.slip_force, other.slip_force))

    def __hash__(self) -> int:
        return hash((type(self).__qualname__, tuple(self.stiffness.tolist()), tuple(self.slip_force.tolist())))

    def __reduce__(self) -> tuple:
        # rebuilt (and re-validated) from the numbers: the arrays come back read-only
        return (type(self), (self.stiffness.tolist(), self.slip_force.tolist()))

    # --- normalisation ---------------------------------------------------------------------
    @property
    def n_elements(self) -> int:
        """Number of elements ``N``."""
        return int(self.stiffness.size)

    @property
    def sigma(self) -> float:  # type: ignore[override]
        """Rest stiffness ``sum k_i`` [N/m]."""
        return math.fsum(self.stiffness.tolist())

    @property
    def Fc(self) -> float:  # type: ignore[override]
        """Gross-sliding force ``sum W_i`` [N]."""
        return math.fsum(self.slip_force.tolist())

    @property
    def slip_deflections(self) -> np.ndarray:
        """Element slip deflections ``W_i / k_i`` [m]."""
        return self.slip_force / self.stiffness

    @cached_property
    def _virgin(self) -> _Virgin:
        q = self.runtime_params()
        n = self.n_elements
        return _Virgin(q[:n], q[n:])

    def virgin_curve(self, x: Any) -> np.ndarray:
        """Force [N] on the virgin curve at displacement ``x`` [m] from the unloaded state
        (odd in ``x``): ``sign(x) sum_i min(k_i |x|, W_i)``."""
        x = np.asarray(x, dtype=float)
        return np.sign(x) * np.minimum(np.abs(x)[..., None] * self.stiffness, self.slip_force).sum(axis=-1)

    @property
    def k_min(self) -> float:
        """Least tangent stiffness [N/m] on an unloading branch from a reversal at ``|F| <= Fc``:
        ``sigma`` times the slope of the virgin curve just below ``F = Fc / 2``."""
        v = self._virgin
        j = int(np.searchsorted(v.F, 0.5, side="left")) - 1  # F_j < 1/2 <= F_{j+1}
        return self.sigma * float(v.k[max(j, 0)])

    # --- structure and numbers ------------------------------------------------------------
    @property
    def n_states(self) -> int:
        """``N`` element forces and the retrace guard ``r`` (class notes)."""
        return self.n_elements + 1

    @property
    def n_flags(self) -> int:
        return self.n_elements

    @property
    def n_events(self) -> int:
        return self.n_elements

    def structure_key(self) -> Hashable:
        return ("MaxwellSlip", self.n_elements)

    def runtime_params(self) -> np.ndarray:
        """``(kappa_1..N, w_1..N)``: ``k_i / sigma`` and ``W_i / Fc``."""
        return np.concatenate((self.stiffness / self.sigma, self.slip_force / self.Fc))

    # --- dynamics -------------------------------------------------------------------------
    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """The state on the virgin curve with normalised force ``f0`` (``|f0| <= 1``); elements
        at their limit slip if ``s`` is the direction of ``f0``."""
        if not abs(f0) <= 1.0 + 1e-12:
            raise ValueError(f"f0 must lie in [-1, 1] (F0 within [-Fc, Fc]), got {f0!r}")
        n = self.n_elements
        if f0 == 0.0:
            return [0.0] * (n + 1), [0.0] * n
        q = self.runtime_params()
        kappa, w = q[:n], q[n:]
        v = self._virgin
        a = abs(f0)
        j = int(v.segment_of_force(np.array(a)))
        y = float(v.inverse(np.array(a)))
        order = np.argsort(w / kappa, kind="stable")
        at_limit = np.zeros(n, dtype=bool)
        at_limit[order[:j]] = True  # segment j: the j smallest slip deflections have slipped
        sg = 1.0 if f0 > 0 else -1.0
        z = [sg * float(w[i]) if at_limit[i] else sg * float(kappa[i]) * y for i in range(n)]
        m = [1.0 if (at_limit[i] and s * sg > 0) else 0.0 for i in range(n)]
        return z + [0.0], m

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        n = self.n_elements
        back = -2.0 * s * v  # > 0 only past a reversal inside a trial step of the integrator
        back = ca.fmax(back, 0.0) if _symbolic(back) else max(back, 0.0)
        return [q[i] * v * (1.0 - m[i]) for i in range(n)] + [back]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        total = z[0]
        for i in range(1, self.n_elements):
            total = total + z[i]
        return total

    def _indicator(self, j: int, z: Sequence[Any], s: Any, q: Any) -> Any:
        """Slip indicator of element ``j``: ``1 - s (z_j + kappa_j r) / w_j`` (``r = 0`` on a branch)."""
        n = self.n_elements
        return 1.0 - s * (z[j] + q[j] * z[n]) / q[n + j]

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        sym = _symbolic(z, m, s, q)
        out = []
        for i in range(self.n_elements):
            ind = self._indicator(i, z, s, q)
            out.append(ca.if_else(m[i] > 0.5, 1.0, ind) if sym else (1.0 if m[i] > 0.5 else ind))
        return out

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        n = self.n_elements
        sym = _symbolic(z, m, s, q)
        zn, mn = list(z), list(m)
        for j in range(n):
            w = q[n + j]
            if j == k:
                zn[j], mn[j] = s * w, 1.0 + 0.0 * w
                continue
            ind = self._indicator(j, z, s, q)
            if sym:
                hit = ca.logic_and(m[j] < 0.5, ind <= TIE)
                zn[j] = ca.if_else(hit, s * w, z[j])
                mn[j] = ca.if_else(hit, 1.0, m[j])
            elif m[j] < 0.5 and ind <= TIE:
                zn[j], mn[j] = s * w, 1.0
        return zn, mn

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        n = self.n_elements
        s_old = -s_new
        sym = _symbolic(z, m, s_new, q, snap)
        zn = []
        for j in range(n):
            w = q[n + j]
            near = 1.0 - s_old * z[j] / w < snap  # reached its limit at the reversal (or slips)
            if sym:
                zn.append(ca.if_else(near, s_old * w, z[j]))
            else:
                zn.append(s_old * float(w) if near else z[j])
        return zn + [0.0 * z[n]], [0.0] * n

    # --- energy ---------------------------------------------------------------------------
    def branch_energy_of_force(self, F: np.ndarray, s: Any) -> np.ndarray:
        """Normalised stored energy on a branch of direction ``s`` at the normalised forces ``F``.

        ``s F <= 0`` (unloading, e.g. just after a reversal): ``4 Phi*(|F| / 2)``, the energy the
        Masing branch from a reversal at ``F`` returns until its force crosses zero; exact at a
        reversal whose preceding reversal force has the other sign, so at every reversal of
        unforced motion from an :meth:`initial_state` (class notes).
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
        kappa, w = qq[:n], qq[n:]
        g = s * np.asarray(z[:n], dtype=float)
        f0 = math.fsum(g.tolist())
        if f0 > 0.0:
            return float(self.branch_energy_of_force(np.array([s * f0]), s)[0])
        room = np.where(np.asarray(m, dtype=float) > 0.5, 0.0, np.maximum(w - g, 0.0))
        brk = room / kappa  # distance to each element's slip
        order = np.argsort(brk, kind="stable")
        f, K, d, E = f0, math.fsum(kappa[room > 0.0].tolist()), 0.0, 0.0
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
