"""Generalised Maxwell-slip (GMS) friction: N elements with a Stribeck curve, through the protocol::

    F = sum_i (F_i + damping_i F_i' / k_i) + sigma2 v,   F_i' = k_i v (sticking),
    F_i' = s C (1 - s F_i / (alpha_i S(v))) (slipping),   S(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)

F. Al-Bender, V. Lampaert and J. Swevers, "The generalized Maxwell-slip model: a novel model
for friction simulation and compensation", IEEE Transactions on Automatic Control 50(11),
1883-1887, 2005 (doi:10.1109/TAC.2005.858676). It generalises :class:`prefriction.MaxwellSlip`
(constant slip forces) with a velocity-dependent slip force ``alpha_i S(v)`` and a rate law for
the slipping elements; it is rate-dependent, so its numbers in normalised units depend on the
mass (:meth:`GMS.runtime_params_for`). See :class:`GMS` and ``docs/models.md#other-models``.

**The slipping law as written here.** It is quoted from the paper as ``dF_i/dt = sgn(v) C
(1 - F_i / (alpha_i s(v)))`` with the steady-sliding curve ``s(v)``, which is odd in ``v``
(``s(v) = sgn(v) S(v)``, so that ``F_i -> alpha_i s(v)`` in steady sliding); with the
magnitude ``S`` that is ``s C (1 - s F_i / (alpha_i S))``, the form used here. (With a
positive ``S`` and without the inner ``s``, ``F_i = +alpha_i S`` would be the target in
both directions, an unstable one for ``v < 0``.) ``C`` is the attraction rate of the element
*forces*, so its unit is N/s (``sgn(v) C`` is the initial slope ``F_i'`` of an element that
slips far below its curve); formulations in element deflections ``d_i' = sgn(v) C' (1 -
k_i d_i / (alpha_i s(v)))`` have ``C' = C / k_i`` [m/s] instead. The Stribeck curve with
the shape exponent ``delta`` (2 by default, the Gaussian form) is the usual one of GMS.

**Normalised numbers** (``docs/models.md``). The units are ``sigma = sum k_i`` (the rest
stiffness: every element sticks after a reversal) and ``Fc``. With the velocity unit ``V = Fc /
sqrt(m sigma)`` (it holds the mass ``m``) the run-time numbers are
(:meth:`GMS.runtime_params_for`)::

    q = (kappa_1..N, alpha_1..N, mu_1..N, Fs/Fc - 1, V/vs, delta/2, C~, sigma2~)

with ``kappa_i = k_i / sigma``, ``mu_i = sigma_i V / (Fc kappa_i)``, ``C~ = C / (sigma V)``
(``C`` times the time unit ``sqrt(m / sigma)`` over ``Fc``) and ``sigma2~ = sigma2 V / Fc``.
The structure is ``N`` alone: one compiled plant serves every GMS with ``N`` elements, whatever
its numbers or mass.

**Protocol** (the normalised numbers ``kappa_i``, ``mu_i``, ``C~``, ``sigma2~`` and the velocity
unit ``V`` above). States ``z_i = F_i / Fc`` and the retrace guard ``r`` of
:mod:`prefriction.models.elements` (``r' = 2 max(-s v~, 0)``, zero on every branch); flags
``m_i`` (element ``i`` slips). With ``S~(v~) = 1 + (Fs/Fc - 1) exp(-((v~ V/vs)^2)^(delta/2))``::

    z_i' = (1 - m_i) kappa_i v~ + m_i C~ (s - z_i / (alpha_i S~)),
    F~   = sum_i (z_i + mu_i z_i') + sigma2~ v~.

One event per element, indicator ``1 - s (z_i + kappa_i r) / (alpha_i S~(v~))`` while it
sticks (``+1`` while it slips); it depends on the velocity, which ``events`` receives. The
event sets ``m_i = 1`` and keeps ``z_i`` (``on_event`` does not receive the velocity, and
the event is located to round-off: ``z_i = s alpha_i S~`` there); a sticking element that
reaches its limit at the same instant (normalised force ``s z_j / alpha_j`` within
:data:`~prefriction.models.elements.TIE` of the firing element's) slips with it. A
reversal keeps every ``z_i``, clears the flags and the guard; a sticking element within
``snap`` of its limit at the reversal (``S~(0) = Fs/Fc``) is put on it.

``initial_state(f0, s)`` is the state on the virgin curve of the Maxwell-slip model with
slip forces ``alpha_i Fc`` (elements at their limit slip if they move along ``f0``): below
``alpha_i S(v)`` for every velocity, so no indicator starts negative, and ``|f0| <= 1``
(``|F0| <= Fc``) is always reachable.

**Force jumps with micro-damping.** ``sigma_i d_i'`` changes from ``sigma_i v`` to ``sigma_i
F_i' / k_i`` at a slip, and at a reversal a slipping element's ``F_i'`` does not vanish at ``v =
0`` (after the reversal it sticks); the reversal table of unforced runs records the force after
the model's reset, that of forced runs the force before it.

**Equal to Maxwell-slip.** With ``Fs = Fc`` and no damping (``damping``, ``sigma2`` zero) the
model *is* :class:`prefriction.MaxwellSlip` with ``W_i = alpha_i Fc`` for every ``C`` and
``vs``: a slipping element starts on its equilibrium ``s alpha_i Fc`` and stays there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Sequence

import numpy as np

from prefriction.models.base import Parameter
from prefriction.models.closed_form import exp, pick
from prefriction.models.elements import TIE, ParallelElements, nonnegative_array
from prefriction.models.gms_slips import GMSSlips
from prefriction.models.stribeck import StribeckCurve

if TYPE_CHECKING:  # units imports the models
    from prefriction.units import Scales

__all__ = ["GMS", "ALPHA_SUM_TOL"]

ALPHA_SUM_TOL = 1e-9
"""Allowed deviation of ``sum(alpha)`` from 1."""


@dataclass(frozen=True, eq=False)
class GMS(GMSSlips, StribeckCurve, ParallelElements):
    """Generalised Maxwell-slip friction (Al-Bender, Lampaert and Swevers 2005).

    ``N`` elements in parallel; element ``i`` is a spring ``k_i`` (force ``F_i = k_i d_i``) whose
    slip force is the fraction ``alpha_i`` of the Stribeck curve ``S(v) = Fc + (Fs - Fc)
    exp(-|v / vs|^delta)``. On a branch of direction ``s = sign(v)`` it sticks, ``F_i' = k_i v``,
    until ``s F_i`` reaches ``alpha_i S(v)`` (a slip event), then slips, ``F_i' = s C (1 - s F_i
    / (alpha_i S(v)))`` (towards ``s alpha_i S(v)`` at the rate ``C / (alpha_i S(v))``), until
    the velocity reverses. The force is ``F = sum_i (F_i + sigma_i F_i' / k_i) + sigma2 v``
    (micro-damping ``sigma_i``, argument ``damping``); in steady sliding ``F = sign(v) S(v) +
    sigma2 v`` (:meth:`steady_force`). Source, slipping law as written here, normalised numbers
    ``q``, states, events and reversal map: module notes of :mod:`prefriction.models.gms` and
    ``docs/models.md#other-models``.

    Parameters
    ----------
    k : array_like
        Element stiffnesses ``k_i`` [N/m]: 1-D, 1 to 100 entries, each finite and > 0.
    alpha : array_like
        Element fractions ``alpha_i`` of the Stribeck force [-]: as many entries as ``k``, each
        finite and > 0, summing to 1 (within 1e-9).
    Fc : float
        Coulomb force [N], ``0 < Fc < inf``: the force unit of the normalised units.
    Fs : float
        Static (break-away) force [N], ``Fc <= Fs < inf``.
    vs : float
        Stribeck velocity [m/s], ``0 < vs < inf``.
    C : float
        Attraction rate of slipping elements [N/s], ``0 < C < inf``.
    sigma2 : float, default 0.0
        Viscous coefficient [N s/m], ``0 <= sigma2 < inf``.
    damping : array_like or None, default None
        Micro-damping ``sigma_i`` of the elements [N s/m]: ``N`` entries, each finite and
        >= 0; ``None`` is zeros. (Named ``damping``, not ``sigma``: ``sigma`` is the protocol's
        reference stiffness ``sum k_i``.)
    delta : float, default 2.0
        Stribeck shape exponent [-], ``0 < delta < inf``.

    Raises
    ------
    TypeError
        If an argument is not a real number or an array of real numbers.
    ValueError
        If a value lies outside its range (the message names the argument, the value and the
        allowed range), the arrays' lengths differ, or ``alpha`` does not sum to 1.

    Notes
    -----
    Normalised units ``sigma = sum k_i`` (the rest stiffness) and ``Fc``; the run-time numbers
    contain the mass (:meth:`runtime_params_for`). ``F0`` of :func:`prefriction.simulate` is the
    elastic force ``sum F_i`` at the start. Rate-dependent: the table's ``E_p`` is NaN. With ``Fs
    = Fc`` and no damping (``damping``, ``sigma2`` zero) the model *is*
    :class:`prefriction.MaxwellSlip` with ``W_i = alpha_i Fc``, as which the energy analysis
    (:mod:`prefriction.energy`) analyses it; it refuses any other GMS with a ``TypeError``.

    Examples
    --------
    >>> import prefriction as pf
    >>> m = pf.GMS(k=[6e4, 3e4, 1e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-3, C=2e3)
    >>> m.sigma, m.Fc, m.n_states, m.structure_key()
    (100000.0, 1.0, 4, ('GMS', 3))
    >>> float(m.stribeck(0.0)), round(float(m.stribeck(1e-3)), 6)  # Fs, Fc + 0.5/e [N]
    (1.5, 1.18394)
    """

    k: Any
    alpha: Any
    Fc: float
    Fs: float
    vs: float
    C: float
    sigma2: float = 0.0
    damping: Any = None
    delta: float = 2.0

    parameters: ClassVar[tuple[Parameter, ...]] = (
        Parameter("k", "N/m", 0.0, math.inf, low_open=True),
        Parameter("alpha", "-", 0.0, 1.0, low_open=True),
        Parameter("Fc", "N", 0.0, math.inf, low_open=True),
        Parameter("Fs", "N", 0.0, math.inf, low_open=True),
        Parameter("vs", "m/s", 0.0, math.inf, low_open=True),
        Parameter("C", "N/s", 0.0, math.inf, low_open=True),
        Parameter("sigma2", "N s/m", 0.0, math.inf),
        Parameter("damping", "N s/m", 0.0, math.inf),
        Parameter("delta", "-", 0.0, math.inf, low_open=True),
    )
    rate_independent: ClassVar[bool] = False

    _stiffness_field: ClassVar[str] = "k"

    def _validate(self) -> None:
        """Check the arrays elementwise and their lengths, the scalars against their ranges,
        ``sum(alpha) = 1`` and ``Fs >= Fc``."""
        k, alpha = self._element_arrays(("k", "N/m"), ("alpha", "-"))
        total = math.fsum(alpha.tolist())
        if not abs(total - 1.0) <= ALPHA_SUM_TOL:
            raise ValueError(f"alpha must sum to 1 (the elements' fractions of the Stribeck force; allowed: "
                             f"|sum(alpha) - 1| <= {ALPHA_SUM_TOL:g}), got sum {total!r} from {alpha.tolist()!r}")
        for par in self.parameters:
            if par.name not in ("k", "alpha", "damping"):
                object.__setattr__(self, par.name, par.check(getattr(self, par.name)))
        damping = np.zeros(k.size) if self.damping is None else self.damping
        damping = nonnegative_array("damping", damping, k.size, "N s/m")
        object.__setattr__(self, "damping", damping)
        if not self.Fs >= self.Fc:
            raise ValueError(f"Fs must be a finite number in [Fc, inf) = [{self.Fc!r}, inf) [N] (the static "
                             f"force is at least the Coulomb force Fc), got {self.Fs!r}")

    # --- structure and numbers ------------------------------------------------------------
    def runtime_params_for(self, scales: "Scales") -> np.ndarray:
        """``q = (kappa_i, alpha_i, mu_i, Fs/Fc - 1, V/vs, delta/2, C/(sigma V), sigma2 V/Fc)``
        with the velocity unit ``V = scales.v = Fc / sqrt(m sigma)`` of the system (module notes)."""
        V, sig, Fc = scales.v, self.sigma, self.Fc
        kappa = self.k / sig
        mu = self.damping * V / Fc / kappa
        tail = [self.Fs / Fc - 1.0, V / self.vs, 0.5 * self.delta, self.C / (sig * V), self.sigma2 * V / Fc]
        return np.concatenate((kappa, self.alpha, mu, tail))

    def runtime_params(self) -> np.ndarray:
        """The numbers :meth:`runtime_params_for` gives for a unit mass (``m = 1 kg``)."""
        return self.runtime_params_for(_UnitMass(self.Fc / math.sqrt(self.sigma)))

    def _element_fractions(self) -> tuple[np.ndarray, np.ndarray]:
        """``(k_i / sigma, alpha_i)``: the Maxwell-slip elements with slip forces ``alpha_i Fc``."""
        return self.k / self.sigma, np.array(self.alpha, dtype=float)

    # --- dynamics -------------------------------------------------------------------------
    def _virgin_force(self, f0: float) -> float:
        """``f0`` within ``[-1, 1]``: ``alpha`` sums to 1 only within :data:`ALPHA_SUM_TOL`, so
        the virgin curve may end above ``Fc``; the initial force stays within ``Fc``."""
        return math.copysign(min(abs(f0), 1.0), f0)

    def velocity_scale(self, q: Any) -> Any:
        """The normalised Stribeck velocity ``vs~ = 1 / q[3N + 1]`` (:meth:`FrictionModel.velocity_scale`)."""
        return 1.0 / q[3 * self.n_elements + 1]

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        n = self.n_elements
        S = self._S(v, q, 3 * n)
        C = q[3 * n + 3]
        out = [(1.0 - m[i]) * (q[i] * v) + m[i] * (C * (s - z[i] / (q[n + i] * S))) for i in range(n)]
        return out + [self._guard_rate(v, s)]

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        n = self.n_elements
        dz = self.rate(z, m, v, s, q)
        total = z[0] + q[2 * n] * dz[0]
        for i in range(1, n):
            total = total + z[i] + q[2 * n + i] * dz[i]
        return total + q[3 * n + 4] * v

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> tuple[list[Any], list[Any]]:
        """Exact step over ``dt`` at the constant velocity ``v`` (``docs/along.md#exact-steps``).

        ``S~`` is constant. A sticking element moves by ``kappa_i v dt``; if it reaches its limit
        ``a_i = alpha_i S~`` (the distance ``d_i = a_i - s z_i``, reached after ``d_i / (kappa_i
        s v)``, or at once if ``d_i <= 0``) it slips from there; a slipping element relaxes,
        ``z_i -> s a_i + (z_i - s a_i) exp(-C~ t / a_i)`` over the time ``t`` it slips.
        """
        n = self.n_elements
        S, C = self._S(v, q, 3 * n), q[3 * n + 3]
        sv = s * v
        sv_safe = pick(sv > 0.0, sv, 1.0)
        zn, mn = list(z), list(m)
        for i in range(n):
            kappa, a = q[i], q[n + i] * S
            d = a - s * z[i]
            reach = (1.0 - m[i]) * (kappa * sv * dt - d) >= -TIE * a
            t_stick = pick(d > 0.0, d / (kappa * sv_safe), 0.0)
            t_slip = pick(m[i] > 0.5, dt, pick(reach, dt - t_stick, 0.0))
            z_on = pick(m[i] > 0.5, z[i], pick(d > 0.0, s * a, z[i]))
            slipped = s * a + (z_on - s * a) * exp(-C * t_slip / a)
            zn[i] = pick(m[i] > 0.5, slipped, pick(reach, slipped, z[i] + kappa * v * dt))
            mn[i] = pick(reach, 1.0, m[i])
        return zn, mn


@dataclass(frozen=True)
class _UnitMass:
    """The velocity unit of a unit-mass system (all :meth:`GMS.runtime_params_for` reads)."""

    v: float
