"""The friction-model contract: a model's mathematics, and the bookkeeping the base derives from it.

A model declares its parameters (:class:`Parameter`), ``n_states``, ``rate`` and ``force`` on a
branch of fixed direction, and, only if it has them, in-branch ``events`` with ``on_event``.
Everything else has a default here (template-method style): the reversal keeps the state, the
structure key is the class and its sizes, the run-time numbers are the declared parameters in
normalised units, the units come from the parameters named or measured in ``N/m`` and ``N``,
rate independence is read off ``rate`` and ``force``, and the branch energy of a one-state model
is a quadrature (:mod:`prefriction.models.defaults`). Closed forms of a branch (``advance``,
``free_branch``, ``branch_energy_of_force``, ...: :mod:`prefriction.models.branch_hooks`) are
optional overrides that make a model faster; the defaults of ``events``, ``on_event`` and
``reverse`` are in :mod:`prefriction.models.event_hooks`. See ``docs/models.md#add-a-model``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar, Hashable, Sequence

import casadi as ca
import numpy as np

from prefriction._validation import check_nonnegative, check_positive, check_real
from prefriction.models.branch_hooks import BranchHooks
from prefriction.models.defaults import detect_rate_independent, normalised_parameters, state_of_force
from prefriction.models.event_hooks import EventHooks

if TYPE_CHECKING:  # prefriction.units imports the models
    from prefriction.units import Scales

__all__ = ["FrictionModel", "Parameter"]


@dataclass(frozen=True)
class Parameter:
    """Declaration of one model parameter: name, unit and allowed closed range ``[low, high]``.

    ``low_open``/``high_open`` make an end of the range open (``0 < sigma`` is ``low=0,
    low_open=True``).
    """

    name: str
    unit: str
    low: float = -np.inf
    high: float = np.inf
    low_open: bool = False
    high_open: bool = False

    def check(self, value: Any) -> float:
        """Return ``value`` as a float inside the range; ``TypeError``/``ValueError`` naming it."""
        if self.low == 0.0 and self.high == np.inf:
            return (check_positive if self.low_open else check_nonnegative)(self.name, value)
        v = check_real(self.name, value)
        lo_ok = v > self.low if self.low_open else v >= self.low
        hi_ok = v < self.high if self.high_open else v <= self.high
        if not (np.isfinite(v) and lo_ok and hi_ok):
            lo = "(" if self.low_open else "["
            hi = ")" if self.high_open else "]"
            raise ValueError(
                f"{self.name} must be a finite number in {lo}{self.low!r}, {self.high!r}{hi} "
                f"[{self.unit}], got {v!r}"
            )
        return v


_UNITS = {"sigma": "N/m", "Fc": "N"}
"""The units of the reference stiffness and force, by which the base finds them among the parameters."""


def unit_of(par: Parameter) -> str:
    """The unit of ``par`` with single spaces."""
    return " ".join(par.unit.split())


class FrictionModel(EventHooks, BranchHooks, ABC):
    """Contract of a friction model for the simulator, the sweeps and the energy analysis.

    **Required** (the mathematics): :attr:`parameters`, :attr:`n_states`, :meth:`rate`,
    :meth:`force`; with events also :meth:`events` and :meth:`on_event` (and :attr:`n_flags` if
    the events set flags). A missing one is refused at construction, naming it. Everything else
    is a default that a model may override with a closed form (module notes).

    Everything is stated in the normalised units of :mod:`prefriction.units`, built on the
    model's reference stiffness ``sigma`` [N/m] and reference force ``Fc`` [N]: force
    ``F~ = F / Fc``, displacement ``x~ = x sigma / Fc``, time ``t~ = t sqrt(sigma / m)``,
    velocity ``v~ = v sqrt(m sigma) / Fc``, energy ``E~ = E sigma / Fc^2``.

    Between two velocity reversals the direction ``s = sign(v) = +-1`` is fixed and the model
    is smooth: the simulator integrates it with an adaptive Runge-Kutta method, locates every
    zero of ``s v`` (a reversal, where it calls :meth:`reverse`) and every zero of the
    indicators of :meth:`events` (where it calls :meth:`on_event`).

    The state of a model is

    - ``z``: ``n_states`` continuous states, normalised so that they are of the size of the
      normalised force; the simulator scales them by the current force amplitude for its
      error control (so small motions get the same relative accuracy as large ones);
    - ``m``: ``n_flags`` discrete flags (modes such as "saturated" or "slipping"), 0.0 or 1.0,
      changed only by :meth:`on_event` and :meth:`reverse`.

    **Compile once per structure.** The simulator builds one CasADi function per
    :meth:`structure_key`. Everything that may change without changing the generated code is a
    run-time number returned by :meth:`runtime_params_for` (``q``; by default the declared
    parameters in normalised units, in their order); :meth:`rate`, :meth:`force`,
    :meth:`events`, :meth:`on_event` and :meth:`reverse` must build their expressions from
    ``q`` and never from the instance's own numbers, and must work on Python floats, numpy
    arrays and CasADi ``SX`` symbols alike (the test helper
    :func:`prefriction.testing.check_model` checks this).

    **Rate-independent models** (``rate_independent = True``) return a rate proportional to
    ``v`` and a force independent of ``v``, and give the energy stored on the current branch
    (:meth:`branch_energy`), which the energy analysis (2.3)-(2.12) needs: the potential
    energy ``E_p`` at a reversal is the stored energy of the branch that starts there.
    ``k_min`` is the least tangent stiffness on an unloading branch [N/m], for the bound (2.12).
    """

    parameters: ClassVar[tuple[Parameter, ...]] = ()
    """The physical parameters, validated on construction (each an attribute of that name)."""
    tracks_position: ClassVar[bool] = False
    """True if :meth:`travel` gives the displacement along a branch from the state alone (the
    simulator then integrates no position state in unforced runs)."""

    def __new__(cls, *args: Any, **kwargs: Any) -> "FrictionModel":
        missing = sorted(getattr(cls, "__abstractmethods__", ()))
        if missing:
            raise TypeError(f"{cls.__name__} does not define {', '.join(missing)}: a friction model needs its state "
                            f"size n_states, its rate(z, m, v, s, q) and its force(z, m, v, s, q), which the "
                            f"simulator integrates and records (docs/models.md#add-a-model)")
        return super().__new__(cls)

    def __post_init__(self) -> None:
        self._validate()

    def _validate(self) -> None:
        """Check every declared parameter, refuse a model without the units ``sigma`` and ``Fc``
        (defined, or a parameter in ``N/m`` and in ``N``) and events without ``on_event``
        (called by ``__post_init__``)."""
        for par in self.parameters:
            object.__setattr__(self, par.name, par.check(getattr(self, par.name)))
        for role, unit in _UNITS.items():
            if not hasattr(self, role):
                raise TypeError(f"{type(self).__name__} has no {role}, the reference "
                                f"{'stiffness' if role == 'sigma' else 'force'} [{unit}] of the normalised units: "
                                f"declare a parameter in {unit} or define {role}")
        cls = type(self)
        if cls.events is not FrictionModel.events and cls.on_event is FrictionModel.on_event:
            raise TypeError(f"{cls.__name__} defines events() but not on_event(k, z, m, s, q), the state just "
                            f"after event k, which the simulator applies at every event")

    def __getattr__(self, name: str) -> Any:
        """``sigma`` and ``Fc`` of a class that does not define them: the first declared parameter
        in ``N/m`` and in ``N`` (read each time, so a copy with other numbers has its own)."""
        declared = [p.name for p in type(self).parameters if name in _UNITS and unit_of(p) == _UNITS[name]]
        if not declared:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        return getattr(self, declared[0])

    @cached_property
    def rate_independent(self) -> bool:  # type: ignore[override]
        """True if the force ignores ``v`` and the rate is ``v`` times a function of the state: the
        energy analysis (2.3)-(2.12) applies. Default: read off :meth:`force` and :meth:`rate` on
        CasADi symbols (a class may declare it)."""
        return detect_rate_independent(self)

    # --- normalisation: attributes (or properties) of every model -----------------------
    sigma: float
    """Reference (rest) stiffness [N/m] of the normalised units."""
    Fc: float
    """Reference force [N] of the normalised units (the Coulomb force for Dahl)."""

    @property
    def max_hysteretic_force(self) -> float:
        """Largest friction force [N] of the model's state at rest: ``simulate`` accepts an initial
        force ``|F0|`` up to it. Default ``Fc`` (Dahl: the Coulomb force)."""
        return self.Fc

    @property
    def k_min(self) -> float:
        """Least tangent stiffness on an unloading branch [N/m], for the bound (2.12)."""
        return self.sigma

    # --- structure and numbers ----------------------------------------------------------
    @property
    @abstractmethod
    def n_states(self) -> int:
        """Number of continuous states ``z``."""

    @property
    def n_flags(self) -> int:
        """Number of discrete flags ``m`` (0.0 or 1.0 each)."""
        return 0

    @cached_property
    def n_events(self) -> int:  # type: ignore[override]
        """Number of in-branch event indicators returned by :meth:`events` (default: counted on symbols)."""
        if type(self).events is FrictionModel.events:
            return 0
        z = [ca.SX.sym(f"z{i}") for i in range(self.n_states)]
        m = [ca.SX.sym(f"m{i}") for i in range(self.n_flags)]
        q = ca.SX.sym("q", len(self.runtime_params()))
        return len(self.events(z, m, ca.SX.sym("v"), ca.SX.sym("s"), [q[i] for i in range(q.numel())]))

    def structure_key(self) -> Hashable:
        """What changes the generated code; models with equal keys share one compiled plant."""
        return (type(self).__module__, type(self).__qualname__, self.n_states, self.n_flags, self.n_events)

    def runtime_params(self) -> np.ndarray:
        """Normalised numbers ``q`` that enter the compiled plant as run-time inputs, for a unit
        mass (:meth:`runtime_params_for` with ``m = 1 kg``)."""
        return normalised_parameters(self, self.Fc / self.sigma, self.Fc, 1.0 / np.sqrt(self.sigma))

    def runtime_params_for(self, scales: "Scales") -> np.ndarray:
        """Normalised numbers ``q`` for a system with the units ``scales`` (:class:`prefriction.Scales`).

        The simulator calls this. Default: every declared parameter in the order of
        :attr:`parameters`, divided by its unit in ``scales`` (``N/m`` by ``sigma``, ``N`` by
        ``scales.F``, ``m`` by ``scales.x``, ``N s/m`` by ``scales.F / scales.v``, ...), so
        ``q[i]`` is the ``i``-th parameter in normalised units. A class that overrides only
        :meth:`runtime_params` (numbers independent of the mass, e.g. Dahl's ``gamma``) gets those.
        """
        if type(self).runtime_params is not FrictionModel.runtime_params:
            return self.runtime_params()
        return normalised_parameters(self, scales.x, scales.F, scales.t)

    # --- dynamics (floats, numpy and CasADi SX alike) ------------------------------------
    def initial_state(self, f0: float, s: float) -> tuple[list[float], list[float]]:
        """State ``(z, m)`` with normalised force ``f0`` at the start of a branch of direction ``s``.

        Default: zero state and flags for ``f0 = 0``; for a one-state model the state whose force
        at rest is ``f0`` (solved); otherwise ``NotImplementedError`` naming this method."""
        if f0 == 0.0 and float(self.force([0.0] * self.n_states, [0.0] * self.n_flags, 0.0, s,
                                          self.runtime_params().tolist())) == 0.0:
            return [0.0] * self.n_states, [0.0] * self.n_flags
        if self.n_states != 1:
            raise NotImplementedError(f"{type(self).__name__} does not define initial_state(f0, s), the state of "
                                      f"a given force at rest, which a start from F0 != 0 needs")
        return [state_of_force(self, float(f0), float(s), self.runtime_params().tolist())], [0.0] * self.n_flags

    @abstractmethod
    def rate(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> list[Any]:
        """Time derivative ``dz/dt~`` on a branch of direction ``s`` at normalised velocity ``v``."""

    @abstractmethod
    def force(self, z: Sequence[Any], m: Sequence[Any], v: Any, s: Any, q: Any) -> Any:
        """Normalised friction force ``F~``."""

    def velocity_scale(self, q: Any) -> Any:
        """Normalised velocity below which the force changes sharply with the speed (a Stribeck
        velocity ``vs~``), or ``None`` (the default: no such scale).

        A Runge-Kutta step that crosses ``|v~| < vs~`` without a stage inside it cannot see the
        curve in its error estimate; the native driver therefore bounds its steps near the curve
        so that the speed changes by at most ``vs~ / 2`` per step within ``3 vs~`` of zero
        (``docs/simulator.md#narrow-stribeck``). ``q`` are the run-time numbers (floats or
        CasADi symbols).
        """
        return None

    _sum: ClassVar[Any] = None
    """``Parallel.of``, set by :mod:`prefriction.models.parallel` (which subclasses this class)."""

    def __add__(self, other: "FrictionModel") -> "FrictionModel":
        """``a + b``: the models in parallel (forces summed, each with its own state),
        :class:`prefriction.Parallel`."""
        if not isinstance(other, FrictionModel):
            return NotImplemented
        return FrictionModel._sum(self, other)
