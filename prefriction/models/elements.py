"""N elements in parallel through the protocol: what :class:`prefriction.MaxwellSlip` and
:class:`prefriction.GMS` share.

Element ``i`` is a spring ``k_i`` in series with a slider; it sticks (its force follows the
displacement at ``k_i``) until its force reaches its slip limit, slips until the velocity
reverses, and sticks again after every reversal. In normalised units (``docs/models.md``,
``sigma = sum k_i``) the states are the element forces ``z_i`` and the retrace guard ``r``
(below), the flags ``m_i`` (element ``i`` slips), one event per element. A model supplies its
slip indicator (:meth:`ParallelElements._indicator`), its rates, force, event map and run-time
numbers; this module supplies the element arrays and their checks, equality, hashing and
pickling by the numbers, the structure ``(name, N)``, the virgin-curve initial state, the
events, the retrace guard's rate and the reversal map.

**The retrace guard** ``r`` (``r' = 2 max(-s v~, 0)``): zero on every branch, it grows only
past a reversal inside a trial step of the integrator, where ``s (z_i + kappa_i r)`` keeps
growing like the arc length travelled; the slip indicators use ``z_i + kappa_i r``. CasADi's
integrator looks at the indicators at the ends of a step (and projects their zero crossings
linearly): without the guard, an element that starts to slip shortly before a reversal has an
indicator that dips below zero and comes back within one step, and the slip was missed (the
element stuck on past its slip force). With the guard the indicator stays negative and keeps
falling past the reversal. The guard enters no rate of ``x``, ``v`` or ``z``, which stay smooth
(a kink in the element rates themselves cost 30-100 ``rtol`` of accuracy). A reversal resets it
to zero. A slip within a few ten ``rtol`` (relative distance) of a reversal can still be missed;
the reversal map then puts the element on its limit, which dissipates what the slip would have
(only the force recorded at that reversal is off, by the overshoot).
"""

from __future__ import annotations

import dataclasses
import math
from functools import cached_property
from typing import Any, ClassVar, Hashable, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.models.element_curves import VirginCurve

__all__ = ["MAX_ELEMENTS", "TIE", "ParallelElements", "nonnegative_array", "positive_array", "symbolic"]

MAX_ELEMENTS = 100
"""Largest number of elements of a :class:`prefriction.MaxwellSlip` or :class:`prefriction.GMS` model."""

TIE = 1e-12
"""Slip indicator (relative to the slip force) below which a sticking element slips together
with the element whose event fired: elements with equal slip deflections reach their limits at
the same instant to round-off, and an indicator that is already at or below zero after a
transition would never see the positive-to-negative crossing the integrator detects."""


def symbolic(*groups: Any) -> bool:
    """True if any argument, or any entry of a list/tuple argument, is a CasADi symbol."""
    for g in groups:
        if isinstance(g, (ca.SX, ca.MX)):
            return True
        if isinstance(g, (list, tuple)):
            for x in g:
                if isinstance(x, (ca.SX, ca.MX)):
                    return True
    return False


def _float_array(name: str, value: Any, allowed: str) -> np.ndarray:
    """``value`` as a float array, or ``TypeError`` naming ``name``, the value and ``allowed``."""
    if isinstance(value, (str, bytes, dict)) or value is None:
        raise TypeError(f"{name} must be {allowed}, got {value!r} of type {type(value).__name__}")
    try:
        raw = np.asarray(value)
    except Exception as exc:  # ragged nested sequences and the like
        raise TypeError(f"{name} must be {allowed}, got {value!r}") from exc
    if raw.dtype == bool or not (np.issubdtype(raw.dtype, np.integer) or np.issubdtype(raw.dtype, np.floating)):
        raise TypeError(f"{name} must be {allowed}, got {value!r} (dtype {raw.dtype})")
    return np.array(raw, dtype=float)


def _entries_in_range(name: str, arr: np.ndarray, unit: str, positive: bool) -> np.ndarray:
    """``arr`` made read-only if every entry is finite and > 0 (``positive``) or >= 0, else
    ``ValueError`` naming ``name``, the first offending entry and the allowed range."""
    bad = ~(np.isfinite(arr) & ((arr > 0.0) if positive else (arr >= 0.0)))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        op = "<" if positive else "<="
        raise ValueError(f"{name}[{i}] must be finite and {'>' if positive else '>='} 0, got {float(arr[i])!r} "
                         f"(allowed range: 0 {op} {name}[i] < inf [{unit}])")
    arr.flags.writeable = False
    return arr


def positive_array(name: str, value: Any, unit: str) -> np.ndarray:
    """``value`` as a read-only 1-D float array of 1..MAX_ELEMENTS finite entries > 0, or raise
    ``TypeError``/``ValueError`` naming ``name``, the offending value and the allowed range."""
    allowed = f"a 1-D array of 1 to {MAX_ELEMENTS} finite numbers > 0 [{unit}]"
    arr = _float_array(name, value, allowed)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be {allowed}, got an array of shape {arr.shape}")
    if not 1 <= arr.size <= MAX_ELEMENTS:
        raise ValueError(f"{name} must hold 1 to {MAX_ELEMENTS} elements, got {arr.size} "
                         f"(allowed: 1 <= len({name}) <= {MAX_ELEMENTS})")
    return _entries_in_range(name, arr, unit, positive=True)


def nonnegative_array(name: str, value: Any, n: int, unit: str) -> np.ndarray:
    """``value`` as a read-only 1-D float array of ``n`` finite entries >= 0, or raise
    ``TypeError``/``ValueError`` naming ``name``, the offending value and the allowed range."""
    allowed = f"a 1-D array of {n} finite numbers >= 0 [{unit}] (one per element)"
    arr = _float_array(name, value, allowed + " or None")
    if arr.ndim != 1 or arr.size != n:
        raise ValueError(f"{name} must be {allowed}, got an array of shape {arr.shape}")
    return _entries_in_range(name, arr, unit, positive=False)


class ParallelElements(FrictionModel):
    """Base of the models of N parallel elements (module notes): a frozen dataclass subclass
    names its stiffness field in ``_stiffness_field``, gives the elements' normalised
    stiffnesses and slip forces at rest (:meth:`_element_fractions`) and its slip indicator."""

    _stiffness_field: ClassVar[str]
    """Name of the dataclass field that holds the element stiffnesses ``k_i`` [N/m]."""

    def __post_init__(self) -> None:
        self._validate()

    def _element_arrays(self, first: tuple[str, str], second: tuple[str, str]) -> tuple[np.ndarray, np.ndarray]:
        """Check the two per-element array fields ``(name, unit)`` and their lengths; store
        them as read-only float arrays and return them."""
        a = positive_array(first[0], getattr(self, first[0]), first[1])
        b = positive_array(second[0], getattr(self, second[0]), second[1])
        if a.size != b.size:
            raise ValueError(f"{first[0]} and {second[0]} must have the same length (one entry per element), "
                             f"got {a.size} and {b.size}")
        object.__setattr__(self, first[0], a)
        object.__setattr__(self, second[0], b)
        return a, b

    def _numbers(self) -> tuple:
        """The field values, arrays as lists (equality, hashing, pickling)."""
        return tuple(v.tolist() if isinstance(v, np.ndarray) else v
                     for v in (getattr(self, f.name) for f in dataclasses.fields(self)))

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(np.array_equal(getattr(self, f.name), getattr(other, f.name)) for f in dataclasses.fields(self))

    def __hash__(self) -> int:
        return hash((type(self).__qualname__,) + tuple(tuple(v) if isinstance(v, list) else v for v in self._numbers()))

    def __reduce__(self) -> tuple:
        # rebuilt (and re-validated) from the numbers: the arrays come back read-only
        return (type(self), self._numbers())

    # --- normalisation ---------------------------------------------------------------------
    @property
    def n_elements(self) -> int:
        """Number of elements ``N``."""
        return int(getattr(self, self._stiffness_field).size)

    @property
    def sigma(self) -> float:  # type: ignore[override]
        """Rest stiffness ``sum k_i`` [N/m]."""
        return math.fsum(getattr(self, self._stiffness_field).tolist())

    def _element_fractions(self) -> tuple[np.ndarray, np.ndarray]:
        """Normalised element stiffnesses ``kappa_i = k_i / sigma`` and slip forces at rest
        (fractions of ``Fc``) of the virgin curve."""
        raise NotImplementedError

    @cached_property
    def _virgin(self) -> VirginCurve:
        return VirginCurve(*self._element_fractions())

    # --- structure ------------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        """``N`` element forces and the retrace guard ``r`` (module notes)."""
        return self.n_elements + 1

    @property
    def n_flags(self) -> int:
        """``N`` slip flags."""
        return self.n_elements

    @property
    def n_events(self) -> int:
        """One slip event per element."""
        return self.n_elements

    def structure_key(self) -> Hashable:
        """``(class name, N)``: one compiled plant serves every model with ``N`` elements."""
        return (type(self).__name__, self.n_elements)

    # --- dynamics -------------------------------------------------------------------------
    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """The state on the virgin curve (:meth:`_element_fractions`) with normalised force
        ``f0`` (``|f0| <= 1``); elements at their limit slip if ``s`` is the direction of ``f0``."""
        if not abs(f0) <= 1.0 + 1e-12:
            raise ValueError(f"f0 must lie in [-1, 1] (F0 within [-Fc, Fc]), got {f0!r}")
        z, m = self._virgin.loaded(self._virgin_force(f0), s)
        return z + [0.0], m

    def _virgin_force(self, f0: float) -> float:
        """The force on the virgin curve that :meth:`initial_state` loads to: ``f0`` itself."""
        return f0

    @staticmethod
    def _guard_rate(v: Any, s: Any) -> Any:
        """Rate ``2 max(-s v~, 0)`` of the retrace guard: > 0 only past a reversal inside a
        trial step of the integrator."""
        back = -2.0 * s * v
        return ca.fmax(back, 0.0) if symbolic(back) else max(back, 0.0)

    def _indicator(self, j: int, z: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        """Slip indicator of element ``j`` while it sticks: positive below its limit."""
        raise NotImplementedError

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        """The slip indicators of the sticking elements, ``+1`` for the slipping ones."""
        sym = symbolic(z, m, v, s, q)
        out = []
        for i in range(self.n_elements):
            ind = self._indicator(i, z, v, s, q)
            out.append(ca.if_else(m[i] > 0.5, 1.0, ind) if sym else (1.0 if m[i] > 0.5 else ind))
        return out

    def on_event_at(self, k: Any, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """:meth:`~prefriction.FrictionModel.on_event` for a symbolic event index ``k`` (a CasADi
        SX; 0-based element index): the same expressions for ``k = 0 ... N-1`` in one piece,
        of size proportional to ``N``, where one :meth:`on_event` per element and a selection by
        ``k`` cost ``N^2`` (30 elements: 22,000 of the 34,000 lines of the generated plant,
        23 s of gcc). The plant uses it when a model has it (``simulation.plant``)."""
        return self._event_at([k == j for j in range(self.n_elements)], z, m, s, q)

    def _event_at(self, is_k: list, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        """:meth:`on_event_at` from the symbolic flags ``is_k[j]`` (element ``j`` fired)."""
        raise NotImplementedError

    @staticmethod
    def _selected(is_k: list, values: Sequence[Any]) -> Any:
        """``values[k]`` for the symbolic index of :meth:`on_event_at` (a sum of zeros but one)."""
        out = 0.0
        for flag, value in zip(is_k, values):
            out = out + ca.if_else(flag, value, 0.0)
        return out

    def _put_on_limits(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any,
                       limits: Sequence[Any], sticking_only: bool) -> tuple[list[Any], list[Any]]:
        """The reversal map: element ``j`` within ``snap`` of its limit ``limits[j]`` (the
        direction before the reversal; if ``sticking_only``, only a sticking one) is put on
        it; every flag cleared and the guard reset."""
        n = self.n_elements
        s_old = -s_new
        sym = symbolic(z, m, s_new, q, snap)
        zn = []
        for j in range(n):
            lim = limits[j]
            near = 1.0 - s_old * z[j] / lim < snap
            if sym:
                zn.append(ca.if_else(ca.logic_and(m[j] < 0.5, near) if sticking_only else near, s_old * lim, z[j]))
            else:
                zn.append(s_old * float(lim) if (near and (m[j] < 0.5 or not sticking_only)) else z[j])
        return zn + [0.0 * z[n]], [0.0] * n
