"""Friction models in parallel: the forces summed, each model with its own state.

``pf.Dahl(...) + pf.Viscous(b)`` builds a :class:`Parallel`. See :class:`Parallel` for the
normalised units of a sum and the names of its parameters in a fit.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Any, Hashable, Optional, Sequence

import casadi as ca
import numpy as np

from prefriction.models.base import FrictionModel
from prefriction.models.parallel_units import ParallelUnits, _len

__all__ = ["MAX_MODELS", "MAX_STATES", "Parallel", "local_names", "qualified_names"]

MAX_MODELS = 16
MAX_STATES = 256
"""Most continuous states a sum of models may hold in all (each model's own limit, e.g. 100
elements, held per term only: ten 100-element Maxwell-slip models took 106 s to compile for a
1,001-sample run). Generated code and compile time grow with the states."""
"""Most models in one sum."""


def local_names(model: FrictionModel) -> list[str]:
    """A model's parameter names as a fit knows them: ``"sigma"``, ``"stiffness[0]"`` for an entry
    of an array parameter."""
    out = []
    for par in type(model).parameters:
        val = getattr(model, par.name)
        out += [par.name] if np.ndim(val) == 0 else [f"{par.name}[{i}]" for i in range(np.size(val))]
    return out


def qualified_names(models: Sequence[FrictionModel]) -> list[list[str]]:
    """The names of the models' parameters in their sum (:class:`Parallel`, naming rule).

    A name that only one model has is kept (``"b"``); a name that several have is prefixed with
    the lower-case class name of its model and a dot (``"dahl.Fc"``, ``"lugre.Fc"``), with the
    model's 1-based rank among the models of its class when the class occurs more than once
    (``"dahl1.sigma"``, ``"dahl2.sigma"``).
    """
    names = [local_names(m) for m in models]
    count = Counter(n for ns in names for n in set(ns))
    classes = Counter(type(m).__name__ for m in models)
    seen: Counter = Counter()
    out = []
    for m, ns in zip(models, names):
        cls = type(m).__name__
        seen[cls] += 1
        prefix = cls.lower() + (str(seen[cls]) if classes[cls] > 1 else "") + "."
        out.append([prefix + n if count[n] > 1 else n for n in ns])
    return out


@dataclass(frozen=True, eq=False)
class Parallel(ParallelUnits, FrictionModel):
    """Friction models in parallel: ``F = sum_i F_i`` [N], each model ``i`` with its own state.

    Built by ``+`` (``pf.Dahl(sigma=1e5, Fc=1.0) + pf.Viscous(b=20.0)``; sums are flattened) or
    :meth:`of`. A sum is itself a :class:`FrictionModel`: :func:`prefriction.friction_along`,
    :func:`prefriction.identify.fit` and :func:`prefriction.simulate` take it.

    Parameters
    ----------
    models : tuple of FrictionModel
        The models summed: 1 to 16, none of them a :class:`Parallel`.

    Raises
    ------
    TypeError
        If ``models`` is not a tuple of friction models, or one of them is a ``Parallel``.
    ValueError
        If there are fewer than 1 or more than 16 models.

    Notes
    -----
    **Units.** The reference stiffness and force of the sum are ``sigma = sum sigma_i`` and
    ``Fc = sum Fc_i`` over the models with a state (a :class:`prefriction.Viscous` term has
    none and only nominal units; 1 N/m and 1 N if no model has a state). Model ``i`` keeps
    its own normalised units: with ``phi_i = Fc_i / Fc`` and ``tau_i = sqrt(sigma_i / sigma)``
    its velocity is ``v~_i = v~ tau_i / phi_i``, its time ``t~_i = t~ tau_i`` and the force
    ``F~ = sum_i phi_i F~_i``. Run-time numbers: ``q = (phi_1, tau_1, q_1, phi_2, tau_2, q_2,
    ...)``; the structure is the tuple of the models' structures.

    **State.** The states, flags and events of the models one after the other; a reversal
    reverses each. ``initial_state(f0, s)`` gives each model with a state the share
    ``F0 max_i / sum_j max_j`` of the force (``max_i`` its ``max_hysteretic_force``).
    Rate-dependent (``rate_independent = False``): the energy of a branch of the sum is not
    the sum of the models' branch energies.

    **Names in a fit** (:func:`prefriction.identify.fit`, ``fixed=``, ``free=``, ``bounds=``):
    :func:`qualified_names`. A name only one model has is kept (``"b"``, ``"gamma"``); a name
    several models have is prefixed with its model's lower-case class name (``"dahl.Fc"``,
    ``"lugre.Fc"``), numbered when a class occurs more than once (``"dahl1.sigma"``).

    Examples
    --------
    >>> import prefriction as pf
    >>> model = pf.Dahl(sigma=1e5, Fc=1.0) + pf.LuGre(2e5, 300.0, 0.0, 0.5, 0.8, 1e-3) + pf.Viscous(20.0)
    >>> model.parameter_names
    ('sigma', 'dahl.Fc', 'gamma', 'sigma0', 'sigma1', 'sigma2', 'lugre.Fc', 'Fs', 'vs', 'b')
    >>> model.sigma, model.Fc  # [N/m], [N]
    (300000.0, 1.5)
    """

    models: tuple

    rate_independent = False

    def __post_init__(self) -> None:
        if not isinstance(self.models, tuple) or not all(isinstance(m, FrictionModel) for m in self.models):
            raise TypeError(f"models must be a tuple of prefriction.FrictionModel, got {self.models!r}")
        if any(isinstance(m, Parallel) for m in self.models):
            raise TypeError("models must not contain a Parallel (use Parallel.of or +, which flatten sums)")
        if not 1 <= len(self.models) <= MAX_MODELS:
            raise ValueError(f"models must hold 1 to {MAX_MODELS} friction models, got {len(self.models)}")
        total = sum(int(m.n_states) for m in self.models)
        if total > MAX_STATES:
            raise ValueError(f"models must hold at most {MAX_STATES} states in all (MAX_STATES: the generated code "
                             f"and its compile time grow with them), got {total} in "
                             f"{[f'{type(m).__name__}: {m.n_states}' for m in self.models]}; merge the terms into "
                             f"one model (e.g. one MaxwellSlip with all the elements, up to its own limit)")

    @classmethod
    def of(cls, *models: FrictionModel) -> "Parallel":
        """The sum of ``models``, sums among them flattened into their terms."""
        flat: list[FrictionModel] = []
        for m in models:
            flat += list(m.models) if isinstance(m, Parallel) else [m]
        return cls(tuple(flat))

    def __repr__(self) -> str:
        return " + ".join(repr(m) for m in self.models)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Parallel) and self.models == other.models

    def __hash__(self) -> int:
        return hash(("Parallel", self.models))

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The names of the models' parameters in a fit, in order (class notes)."""
        return tuple(n for ns in qualified_names(self.models) for n in ns)

    # --- structure ----------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return sum(m.n_states for m in self.models)

    @property
    def n_flags(self) -> int:
        return sum(m.n_flags for m in self.models)

    @property
    def n_events(self) -> int:
        return sum(m.n_events for m in self.models)

    def structure_key(self) -> Hashable:
        return ("Parallel",) + tuple((type(m).__name__, m.structure_key()) for m in self.models)

    def _parts(self, z: Sequence[Any], m: Sequence[Any], v: Any, q: Any):
        """Per model: ``(model, z_i, m_i, v~_i, tau_i, phi_i, q_i)``."""
        iz = im = iq = 0
        for model in self.models:
            nq = _len(model.runtime_params())
            phi, tau = q[iq], q[iq + 1]
            q_i = [q[iq + 2 + j] for j in range(nq)]
            z_i, m_i = list(z[iz:iz + model.n_states]), list(m[im:im + model.n_flags])
            yield model, z_i, m_i, (None if v is None else v * tau / phi), tau, phi, q_i
            iz, im, iq = iz + model.n_states, im + model.n_flags, iq + 2 + nq

    # --- dynamics -------------------------------------------------------------------------
    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """Each model with a state at its share of the force (class notes)."""
        total = math.fsum(m.max_hysteretic_force for m in self._stateful)
        z: list[float] = []
        flags: list[float] = []
        for m in self.models:
            share = 0.0 if m.n_states == 0 or total == 0.0 else f0 * self.Fc * m.max_hysteretic_force / total
            z_i, m_i = m.initial_state(share / m.Fc, s)
            z, flags = z + list(z_i), flags + list(m_i)
        return z, flags

    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        out: list[Any] = []
        for model, z_i, m_i, v_i, tau, _phi, q_i in self._parts(z, m, v, q):
            out += [r * tau for r in model.rate(z_i, m_i, v_i, s, q_i)]
        return out

    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        total = 0.0
        for model, z_i, m_i, v_i, _tau, phi, q_i in self._parts(z, m, v, q):
            total = total + phi * model.force(z_i, m_i, v_i, s, q_i)
        return total

    def velocity_scale(self, q: Any) -> Any:
        """The least of the models' velocity scales in the sum's units (``vs~_i phi_i / tau_i``),
        or None if no model has one (:meth:`FrictionModel.velocity_scale`)."""
        out = None
        for model, _z, _m, _v, tau, phi, q_i in self._parts([], [], None, q):
            vs = model.velocity_scale(q_i)
            if vs is not None:
                vs = vs * phi / tau
                out = vs if out is None else (min(out, vs) if isinstance(out + vs, float) else ca.fmin(out, vs))
        return out

    def events(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        out: list[Any] = []
        for model, z_i, m_i, v_i, _tau, _phi, q_i in self._parts(z, m, v, q):
            out += list(model.events(z_i, m_i, v_i, s, q_i))
        return out

    def on_event(self, k: int, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> tuple[list[Any], list[Any]]:
        zn: list[Any] = []
        mn: list[Any] = []
        for model, z_i, m_i, _v, _tau, _phi, q_i in self._parts(z, m, None, q):
            if 0 <= k < model.n_events:
                z_i, m_i = model.on_event(k, z_i, m_i, s, q_i)
            k -= model.n_events
            zn, mn = zn + list(z_i), mn + list(m_i)
        return zn, mn

    def reverse(self, z: Sequence[Any], m: Sequence[Any], s_new: Any, q: Any, snap: Any) -> tuple[list[Any], list[Any]]:
        zn: list[Any] = []
        mn: list[Any] = []
        for model, z_i, m_i, _v, _tau, _phi, q_i in self._parts(z, m, None, q):
            z_i, m_i = model.reverse(z_i, m_i, s_new, q_i, snap)
            zn, mn = zn + list(z_i), mn + list(m_i)
        return zn, mn

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> Optional[tuple[list[Any], list[Any]]]:
        """Each model's exact step in its own units; ``None`` if one model has none."""
        zn: list[Any] = []
        mn: list[Any] = []
        for model, z_i, m_i, v_i, tau, _phi, q_i in self._parts(z, m, v, q):
            step = model.advance(z_i, m_i, v_i, dt * tau, s, q_i)
            if step is None:
                return None
            zn, mn = zn + list(step[0]), mn + list(step[1])
        return zn, mn


FrictionModel._sum = Parallel.of  # ``a + b`` of any two models (FrictionModel.__add__)
