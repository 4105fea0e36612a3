"""Exact reference of the unforced Maxwell-slip oscillator, and what the paper's analysis predicts.

Closed form, event by event (normalised units of :mod:`prefriction.units` with ``sigma = sum
k_i``, ``Fc = sum W_i``; ``kappa_i = k_i / sigma``, ``w_i = W_i / Fc``, slip deflections
``Delta_i = w_i / kappa_i``). Between two events the direction ``s`` is fixed and the force seen
in the direction of motion is ``f = f_0 + K u``, ``u`` the distance travelled since the phase
began and ``K`` the sum of ``kappa_i`` over the sticking elements, so ``u'' = -f``:

- ``K > 0``: a harmonic oscillation of frequency ``sqrt(K)`` about ``u = -f_0 / K``. A state is
  the point ``(f, sqrt(K) V)`` (``V = |v|``) turning clockwise at the rate ``sqrt(K)``; the time
  between two states is their angle over ``sqrt(K)``, ``atan2(sqrt(K) (V_0 f_1 - f_0 V_1),
  f_0 f_1 + K V_0 V_1) / sqrt(K)`` (no cancellation near tangency, the limit ``K -> 0`` is
  ``(V_0 - V_1) / f``);
- ``K = 0`` (every element slips, ``f = 1``): uniform deceleration.

The next event is the least of the sticking elements' slip distances ``(w_i - s z_i) / kappa_i``
and the reversal distance ``u_r`` with ``V_0^2 = 2 f_0 u_r + K u_r^2``; the speed at a slip
follows from ``V^2 = V_0^2 - u (2 f_0 + K u)``. An element that reaches its limit at the
reversal itself (within 4 ulp) is put on it without a slip, as the simulator's ``snap`` does.

**What the paper's analysis predicts** (derivation in ``docs/mathematics.md``, Maxwell-slip
section; ``phi(y) = sum_i min(kappa_i y, w_i)`` the virgin curve):

1. *Masing rule.* After a reversal at force ``F_r`` the branch is ``f = -a + 2 phi(delta / 2)``
   (``a = |F_r|/Fc``, ``delta`` the distance from the reversal) over at least the span of the
   preceding half-cycle, for any state.
2. *Potential energy* at the reversal: ``E_p = 4 Phi*(a / 2)``, ``Phi*`` the complementary
   energy of ``phi`` (``a^2 / 2`` while ``a <= 2 Delta_min``).
3. *The next excursion reaches at most the same force.* The next reversal is at the span
   ``delta*`` where the mean of ``2 phi(u / 2)`` over ``[0, delta*]`` equals ``a``, and ``a' =
   2 phi(delta* / 2) - a <= a`` by concavity, with equality if and only if no element slips in
   the half-cycle, that is iff ``a <= Delta_min`` (``|F_r| <= sigma min W_i / k_i``). ``E_d >= 0``
   and dissipation happens only while elements slip.
4. *Undamped after the last slip.* Once ``|F_r| <= sigma min_i W_i / k_i`` every element sticks
   for ever: an undamped oscillation of stiffness ``sigma`` (half-period ``pi sqrt(m / sigma)``,
   constant ``|F_r|`` and ``E_p = F_r^2 / (2 sigma)``), unlike Dahl's ``t^-2`` decay. The
   amplitudes always converge to at most ``Delta_min``.
5. *Whether that happens after finitely many half-cycles* depends on ``kappa_1``, the
   stiffness fraction of the elements with the least slip deflection: near ``Delta_min`` the
   map is ``a' - Delta_min = (1 - 2 kappa_1)(a - Delta_min) + O((a - Delta_min)^2)`` (exactly,
   with ``h = delta* - 2 Delta_min`` while only those elements slip: ``a - Delta_min = h/2 -
   kappa_1 h^2 / (2 delta*)``, ``a' - Delta_min = (1/2 - kappa_1) h + kappa_1 h^2 / (2
   delta*)``). ``kappa_1 > 1/2``: the amplitude falls below ``Delta_min`` after finitely many
   half-cycles, then no element slips again. ``kappa_1 <= 1/2``: once only those elements slip
   (a reversal below :attr:`DissipationLimit.single_group_force`) it never gets there; ``a_n -
   Delta_min`` decays geometrically (ratio ``-> 1 - 2 kappa_1``, quadratically for ``kappa_1 =
   1/2``) and the elements slip a little in every half-cycle. Before that, a half-cycle in which
   more elements slip may jump below ``Delta_min`` (history-dependent). Either way the decay is
   geometric or finite, never algebraic like Dahl's ``3 / (2 n)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from prefriction._validation import check_array_interval, check_count, check_interval, check_nonnegative
from prefriction.analysis.exact_input import check_initial_state
from prefriction.models import Oscillator
from prefriction.models.maxwell_slip import MaxwellSlip
from prefriction.reversals import ReversalTable
from prefriction.units import Scales

__all__ = [
    "MAX_REVERSALS",
    "MaxwellSlipTrajectory",
    "first_reversal",
    "DissipationLimit",
    "dissipation_limit",
    "masing_amplitudes",
    "masing_next",
    "maxwell_slip_reversals",
    "maxwell_slip_trajectory",
]

MAX_REVERSALS = 1_000_000
"""Most reversals of one exact Maxwell-slip reference (a Python loop over events: about a minute)."""

_TANGENT = 4.0 * np.finfo(float).eps  # slip within this (relative) of the reversal: at the reversal


def _check_system(system: Any, purpose: str) -> MaxwellSlip:
    if not isinstance(system, Oscillator) or not isinstance(system.friction, MaxwellSlip):
        raise TypeError(f"system must be a prefriction.Oscillator with MaxwellSlip friction ({purpose}), got "
                        f"{system!r} of type {type(system).__name__}")
    if system.u is not None:
        raise ValueError(f"system must be unforced: {purpose} covers the unforced system only, got an oscillator "
                         "with an input force u (allowed: system.u is None); use prefriction.simulate for forced motion")
    return system.friction


def _check_model(model: Any) -> MaxwellSlip:
    if not isinstance(model, MaxwellSlip):
        raise TypeError(f"model must be a prefriction.MaxwellSlip model, got {model!r} of type {type(model).__name__}")
    return model


class _Sum:
    """Running sum with Neumaier compensation (times and positions over many phases)."""

    def __init__(self, value: float = 0.0) -> None:
        self.s, self.c = float(value), 0.0

    def add(self, x: float) -> None:
        t = self.s + x
        self.c += (self.s - t) + x if abs(self.s) >= abs(x) else (x - t) + self.s
        self.s = t

    @property
    def value(self) -> float:
        return self.s + self.c


def _phase_time(f0: float, V0: float, f1: float, V1: float, K: float) -> float:
    """Time from ``(f0, V0)`` to ``(f1, V1)`` on one phase (angle of the clockwise turn)."""
    cross = V0 * f1 - f0 * V1
    dot = f0 * f1 + K * V0 * V1
    if K <= 0.0:
        return (V0 - V1) / f0
    om = math.sqrt(K)
    return math.atan2(om * cross, dot) / om


@dataclass(frozen=True)
class _Phase:
    """One phase between events (normalised): start time, position, direction, force in the
    direction of motion, speed, sticking stiffness and duration."""

    t0: float
    x0: float
    s: float
    f0: float
    V0: float
    K: float
    dt: float


@dataclass(frozen=True, eq=False)
class MaxwellSlipTrajectory:
    """Exact trajectory of the unforced Maxwell-slip oscillator up to its ``n``-th reversal.

    Attributes
    ----------
    table : ReversalTable
        Reversal times [s], positions [m], forces [N], ``E_p`` (state-based, exact), ``E_d``
        (2.10) and ``E_0`` [J], as :func:`prefriction.exact_reversals` gives them for Dahl.
    slips : numpy.ndarray
        Number of element slips in the half-cycle ending at each reversal (int).
    slip_t, slip_x : numpy.ndarray
        Times [s] and positions [m] of every slip, in order.
    slip_element : numpy.ndarray
        Index of the element of every slip (int).
    slip_work : numpy.ndarray
        Work of the slipping elements [J] in the half-cycle ending at each reversal: the
        mechanical energy lost there (``sum W_i`` times slip distance).
    slip_gap : numpy.ndarray
        Distance [m] from every slip to the reversal that ends its half-cycle. A slip within a
        tolerance of its reversal is a near-coincidence a simulation may resolve either way.
    margin : numpy.ndarray
        Shape ``(n, N)``: at each reversal, ``1 - |k_i d_i| / W_i`` of every element that did
        not slip in the half-cycle (NaN for those that did). A margin near zero is an element
        touching its slip force at the reversal (in the undamped regime after the last slip the
        last elements to slip touch it at every other reversal).
    """

    table: ReversalTable
    slips: np.ndarray
    slip_t: np.ndarray
    slip_x: np.ndarray
    slip_element: np.ndarray
    slip_work: np.ndarray
    slip_gap: np.ndarray
    margin: np.ndarray
    _phases: list = field(repr=False, default_factory=list)
    _scales: Optional[Scales] = field(repr=False, default=None)

    def sample(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position [m], velocity [m/s] and friction force [N] at the times ``t`` [s] (within
        ``[0, table.t[-1]]``), in closed form on each phase.

        Parameters
        ----------
        t : array_like
            Times [s].

        Returns
        -------
        (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        """
        sc = self._scales
        tn = np.atleast_1d(np.asarray(t, dtype=float)) / sc.t
        starts = np.array([p.t0 for p in self._phases])
        k = np.clip(np.searchsorted(starts, tn, side="right") - 1, 0, len(self._phases) - 1)
        x, v, F = np.empty_like(tn), np.empty_like(tn), np.empty_like(tn)
        for i, ti in enumerate(tn):
            p = self._phases[k[i]]
            tau = min(max(ti - p.t0, 0.0), p.dt)
            if p.K > 0.0:
                om = math.sqrt(p.K)
                sn = math.sin(om * tau) / om
                hv = math.sin(0.5 * om * tau) / om
                u = p.V0 * sn - p.f0 * 2.0 * hv * hv
                V = p.V0 * math.cos(om * tau) - p.f0 * sn
            else:
                u = p.V0 * tau - 0.5 * p.f0 * tau * tau
                V = p.V0 - p.f0 * tau
            x[i] = p.x0 + p.s * u
            v[i] = p.s * V
            F[i] = p.s * (p.f0 + p.K * u)
        return x * sc.x, v * sc.v, F * sc.F


def maxwell_slip_reversals(system: Oscillator, v0: float, n: int, *, x0: float = 0.0, F0: float = 0.0) -> ReversalTable:
    """First ``n`` velocity reversals of the unforced Maxwell-slip oscillator, in closed form.

    Every slip and reversal time follows from the harmonic (or uniformly decelerated) motion
    between events (module notes): the reference for :func:`prefriction.simulate` with
    :class:`prefriction.MaxwellSlip` friction, to about 1e-15 relative.

    Parameters
    ----------
    system : Oscillator
        Unforced oscillator (``system.u is None``) with :class:`prefriction.MaxwellSlip` friction.
    v0 : float
        Initial velocity [m/s].
    n : int
        Number of reversals, ``>= 1``.
    x0 : float, default 0.0
        Initial position [m].
    F0 : float, default 0.0
        Initial friction force [N], ``|F0| <= Fc``; the initial state is on the virgin curve
        (:meth:`prefriction.MaxwellSlip.initial_state`). With ``v0 = 0`` the motion starts in
        the direction ``-sign(F0)``.

    Returns
    -------
    ReversalTable
        Times [s], positions [m], forces [N], potential energies ``E_p`` [J] (the exact
        state-based branch energy), dissipation ``E_d`` [J] (2.10) and ``E_0`` [J].

    Raises
    ------
    TypeError
        If ``system`` is not an Oscillator with MaxwellSlip friction, or an argument has the
        wrong type.
    ValueError
        If the system is forced, ``n < 1``, an argument is not finite, ``|F0| > Fc``, or
        ``v0 = F0 = 0``.
    """
    return maxwell_slip_trajectory(system, v0, n, x0=x0, F0=F0).table


def maxwell_slip_trajectory(system: Oscillator, v0: float, n: int, *, x0: float = 0.0, F0: float = 0.0) -> MaxwellSlipTrajectory:
    """The exact trajectory behind :func:`maxwell_slip_reversals`: reversal table, every slip
    (time, position, element), slips per half-cycle, slip work, and closed-form samples.

    Parameters
    ----------
    system : Oscillator
        Unforced oscillator with :class:`prefriction.MaxwellSlip` friction.
    v0 : float
        Initial velocity [m/s].
    n : int
        Number of reversals, ``>= 1``.
    x0, F0 : float, default 0.0
        Initial position [m] and friction force [N] (virgin-curve state), ``|F0| <= Fc``.

    Returns
    -------
    MaxwellSlipTrajectory

    Raises
    ------
    TypeError, ValueError
        As :func:`maxwell_slip_reversals`.
    """
    model = _check_system(system, "maxwell_slip_reversals")
    sc = Scales.of(system)
    v0, x0, F0, n = check_initial_state(system, sc, v0, x0, F0, n, maximum=MAX_REVERSALS)
    Fc = model.Fc
    q = model.runtime_params()
    N = model.n_elements
    kappa, w = q[:N].tolist(), q[N:].tolist()
    s = math.copysign(1.0, v0) if v0 != 0.0 else -math.copysign(1.0, F0)
    z, m = model.initial_state(F0 / Fc, s)
    z = z[:N]  # the element forces (without the retrace guard)
    V = abs(v0) / sc.v
    E0 = 0.5 * V * V + model.branch_energy(z, m, s, q)
    g = [s * zi for zi in z]  # element forces in the direction of motion
    stick = [mi < 0.5 for mi in m]
    V2 = V * V
    t, x = _Sum(), _Sum(x0 / sc.x)
    rows, Ep, slips, slip_t, slip_x, slip_el, phases, gaps, margins = [], [], [], [], [], [], [], [], []
    pending = []  # positions of this half-cycle's slips
    count = 0
    work = [0.5 * V * V + math.fsum(zi * zi / (2.0 * kappa[i]) for i, zi in enumerate(z))]  # mechanical energy
    while len(rows) < n:
        K = math.fsum(kappa[i] for i in range(N) if stick[i])
        f0 = math.fsum(g)
        disc = math.sqrt(f0 * f0 + K * V2)
        u_rev = V2 / (f0 + disc) if f0 > 0.0 else (disc - f0) / K
        u_slip, j = math.inf, -1
        for i in range(N):
            if stick[i]:
                ui = max(w[i] - g[i], 0.0) / kappa[i]
                if ui < u_slip:
                    u_slip, j = ui, i
        if u_slip < u_rev * (1.0 - _TANGENT):
            u = u_slip
            V2n = max(V2 - u * (2.0 * f0 + K * u), 0.0)
            Vn = math.sqrt(V2n)
            f1 = f0 + K * u
            dt = _phase_time(f0, math.sqrt(V2), f1, Vn, K)
            phases.append(_Phase(t.value, x.value, s, f0, math.sqrt(V2), K, dt))
            t.add(dt)
            x.add(s * u)
            for i in range(N):
                if stick[i]:
                    g[i] += kappa[i] * u
            for i in range(N):  # the element, and any other at its limit to round-off
                if stick[i] and (i == j or g[i] >= w[i] * (1.0 - 1e-14)):
                    g[i], stick[i] = w[i], False
                    count += 1
                    slip_t.append(t.value)
                    slip_x.append(x.value)
                    slip_el.append(i)
                    pending.append(x.value)
            V2 = V2n
            continue
        # reversal
        u = u_rev
        f1 = f0 + K * u
        dt = _phase_time(f0, math.sqrt(V2), f1, 0.0, K)
        phases.append(_Phase(t.value, x.value, s, f0, math.sqrt(V2), K, dt))
        t.add(dt)
        x.add(s * u)
        margin = [math.nan] * N
        for i in range(N):
            if stick[i]:
                g[i] = min(g[i] + kappa[i] * u, w[i])
                margin[i] = 1.0 - g[i] / w[i]
                if g[i] >= w[i] * (1.0 - 1e-14):
                    g[i] = w[i]
        margins.append(margin)
        gaps.extend(abs(x.value - xs) for xs in pending)
        pending = []
        rows.append((t.value, x.value, s * math.fsum(g)))
        slips.append(count)
        work.append(math.fsum(gi * gi / (2.0 * kappa[i]) for i, gi in enumerate(g)))  # at rest: elastic only
        s = -s
        g = [-gi for gi in g]
        stick = [True] * N
        V2 = 0.0
        Ep.append(model.branch_energy([s * gi for gi in g], [0.0] * N, s, q))
        count = 0
    t_r = np.array([r[0] for r in rows])
    x_r = np.array([r[1] for r in rows])
    F_r = np.array([r[2] for r in rows])
    E_p = np.array(Ep)
    E_d = np.empty(n)
    E_d[0] = E0 - E_p[0]
    E_d[1:] = E_p[:-1] - E_p[1:]
    table = ReversalTable(t=t_r * sc.t, x=x_r * sc.x, F=F_r * sc.F, E_p=E_p * sc.E, E_d=E_d * sc.E, E_0=float(E0 * sc.E))
    slip_w = -np.diff(np.array(work)) * sc.E
    return MaxwellSlipTrajectory(table=table, slips=np.array(slips, dtype=int), slip_t=np.array(slip_t) * sc.t,
                                 slip_x=np.array(slip_x) * sc.x, slip_element=np.array(slip_el, dtype=int),
                                 slip_work=slip_w, slip_gap=np.array(gaps) * sc.x, margin=np.array(margins),
                                 _phases=phases, _scales=sc)


# ------------------------------------------------------------------------------------------
# the Masing map: the paper's analysis for Maxwell-slip
# ------------------------------------------------------------------------------------------


def masing_next(model: MaxwellSlip, a: Any) -> tuple[np.ndarray, np.ndarray]:
    """One half-cycle of the unforced oscillator by the Masing rule, in normalised units.

    From rest at a reversal with ``|F| = a Fc`` the branch is ``-a + 2 phi(delta / 2)``; the next
    reversal is at the span ``delta*`` where the mean of the branch force vanishes (energy
    balance (2.9)), ``Phi(delta* / 2) = a delta* / 4``, and its force is ``a' = 2 phi(delta* / 2)
    - a``. Valid at every reversal of unforced motion from the virgin curve (module notes).

    Parameters
    ----------
    model : MaxwellSlip
        The friction model.
    a : float or array_like
        Reversal amplitudes ``|F_r| / Fc``, ``0 <= a <= 1``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Next amplitudes ``a'`` and spans ``delta*`` (normalised displacement, units ``Fc / sigma``).
    """
    v = _check_model(model)._virgin
    a = np.atleast_1d(check_array_interval("a", a, 0.0, 1.0)).ravel()
    out_a, out_d = np.empty_like(a), np.empty_like(a)
    H = v.P - 0.5 * a[:, None] * v.y[None, :]  # Phi(y_j) - a y_j / 2 at every breakpoint
    for i, ai in enumerate(a):
        if ai <= v.y[1]:  # linear: no element slips
            out_a[i], out_d[i] = ai, 2.0 * ai
            continue
        pos = np.flatnonzero(H[i, 1:] >= 0.0)
        j = int(pos[0]) if pos.size else v.n  # root in segment j (from y_j)
        C, B, k = H[i, j], v.F[j] - 0.5 * ai, v.k[j]
        if B >= 0.0:
            tt = -2.0 * C / (B + math.sqrt(B * B - 2.0 * k * C))
        else:
            tt = (-B + math.sqrt(B * B - 2.0 * k * C)) / k
        y = v.y[j] + tt
        out_a[i] = 2.0 * (v.F[j] + k * tt) - ai
        out_d[i] = 2.0 * y
    return out_a, out_d


def masing_amplitudes(model: MaxwellSlip, a1: float, n: int) -> np.ndarray:
    """Reversal amplitudes ``a_1 .. a_n`` (``|F_k| / Fc``) of the unforced oscillator by the
    Masing map :func:`masing_next`, from the first reversal amplitude ``a1``.

    Parameters
    ----------
    model : MaxwellSlip
        The friction model.
    a1 : float
        Amplitude at the first reversal, ``0 <= a1 <= 1``.
    n : int
        Number of amplitudes.

    Returns
    -------
    numpy.ndarray
    """
    _check_model(model)
    a1 = check_interval("a1", a1, 0.0, 1.0)
    n = check_count("n", n, minimum=1, maximum=MAX_REVERSALS, why="a Python loop: about a minute")
    out = np.empty(n)
    out[0] = a1
    for k in range(1, n):
        out[k] = masing_next(model, out[k - 1])[0][0]
    return out


def first_reversal(model: MaxwellSlip, E0: float) -> tuple[float, float]:
    """Span ``y1`` and amplitude ``a1 = phi(y1)`` of the first excursion from the unloaded
    virgin state with normalised energy ``E0`` (``Phi(y1) = E0``), in normalised units.

    Parameters
    ----------
    model : MaxwellSlip
        The friction model.
    E0 : float
        Initial energy ``v0^2 / 2`` in units of ``Fc^2 / sigma``.

    Returns
    -------
    (float, float)
        ``y1`` [``Fc / sigma``] and ``a1`` [``Fc``].
    """
    v = _check_model(model)._virgin
    E0 = check_nonnegative("E0", E0)
    j = int(np.searchsorted(v.P, E0, side="right") - 1)
    j = min(max(j, 0), v.n)
    dE = E0 - v.P[j]
    F, k = v.F[j], v.k[j]
    tt = 2.0 * dE / (F + math.sqrt(F * F + 2.0 * k * dE)) if (F > 0.0 or k > 0.0) else 0.0
    return v.y[j] + tt, F + k * tt


@dataclass(frozen=True)
class DissipationLimit:
    """Where the unforced Maxwell-slip oscillator stops dissipating (:func:`dissipation_limit`).

    Attributes
    ----------
    force : float
        ``sigma min_i W_i / k_i`` [N]: a reversal at ``|F| <= force`` is followed by an
        undamped oscillation with every element sticking (no element slips again).
    displacement : float
        ``min_i W_i / k_i`` [m]: the half-span of that undamped oscillation at most.
    kappa_1 : float
        Summed ``k_i / sigma`` of the elements with the least slip deflection [-].
    single_group_force : float
        ``Fc 2 Phi(Delta_2) / Delta_2`` [N] (``Delta_2`` the next larger normalised slip
        deflection; ``inf`` if every deflection is equal): below it only the weakest elements
        slip in a half-cycle, where the local map holds exactly.
    finite : bool or None
        ``True`` if ``kappa_1 > 1/2``: the amplitude falls to ``force`` or below after finitely
        many half-cycles, from any start. ``None`` if ``kappa_1 <= 1/2``: it depends on the
        history. A half-cycle in which other elements slip too may jump below ``force``, but once
        a reversal lies between ``force`` and ``single_group_force`` no such jump comes and the
        weakest elements slip a little in every half-cycle for ever (the amplitude converges to
        ``force`` geometrically, ratio ``-> 1 - 2 kappa_1``; quadratically for ``1/2``).
    """

    force: float
    displacement: float
    kappa_1: float
    single_group_force: float
    finite: Optional[bool]


def dissipation_limit(model: MaxwellSlip) -> DissipationLimit:
    """The force below which the unforced oscillator is undamped, and whether it gets there in
    finitely many half-cycles (module notes, items 3-5).

    Parameters
    ----------
    model : MaxwellSlip
        The friction model.

    Returns
    -------
    DissipationLimit
    """
    d = _check_model(model).slip_deflections
    dmin = float(np.min(d))
    group = d <= dmin * (1.0 + 1e-12)
    kappa1 = float(np.sum(model.stiffness[group]) / model.sigma)
    v = model._virgin
    rest = np.sort(d[~group])
    if rest.size:
        D2 = float(rest[0]) * model.sigma / model.Fc
        single = model.Fc * 2.0 * _virgin_energy_at(v, D2) / D2
    else:
        single = math.inf
    return DissipationLimit(force=model.sigma * dmin, displacement=dmin, kappa_1=kappa1,
                            single_group_force=single, finite=True if kappa1 > 0.5 else None)


def _virgin_energy_at(v: Any, y: float) -> float:
    """``Phi(y)``, the energy stored on the normalised virgin curve up to the distance ``y``."""
    j = int(np.clip(np.searchsorted(v.y, y, side="right") - 1, 0, v.n))
    t = y - v.y[j]
    return float(v.P[j] + v.F[j] * t + 0.5 * v.k[j] * t * t)
