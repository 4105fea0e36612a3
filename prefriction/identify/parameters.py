"""The parameter vector of a fit: names, start values, bounds, free and fixed entries.

A model's declared :class:`prefriction.Parameter` objects give the physical parameters. Scalar
parameters keep their name (``"sigma"``); array parameters (Maxwell-slip) become one entry per
element (``"stiffness[0]"``). The units of the normalised model (``sigma``, ``Fc``) and its
run-time numbers ``q`` are rebuilt as CasADi expressions of these entries, so that the fit
differentiates through them (``docs/models.md#structure``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import casadi as ca
import numpy as np

from prefriction._validation import check_positive
from prefriction.identify.entry_bounds import OPEN as _OPEN, ParameterConstraints
from prefriction.identify.theta_maps import ThetaMaps
from prefriction.models.base import FrictionModel, Parameter

__all__ = ["ParameterSpace", "symbolic_units"]



@dataclass(frozen=True)
class _Entry:
    name: str
    field: str
    index: int | None
    unit: str
    value: float
    low: float
    high: float
    part: int | None = None
    local: str = ""


def _entries(model: FrictionModel) -> list[_Entry]:
    from prefriction.models.parallel import Parallel, qualified_names

    if isinstance(model, Parallel):  # a sum: each model's entries under its names in the sum
        names = qualified_names(model.models)
        return [dataclasses.replace(e, name=names[i][j], part=i, local=e.name)
                for i, m in enumerate(model.models) for j, e in enumerate(_entries(m))]
    out = []
    for par in type(model).parameters:
        val = getattr(model, par.name)
        vals = [float(val)] if np.ndim(val) == 0 else np.asarray(val, dtype=float).ravel().tolist()
        for i, v in enumerate(vals):
            low, high = _structure_range(model, par, v)
            name = par.name if np.ndim(val) == 0 else f"{par.name}[{i}]"
            out.append(_Entry(name, par.name, None if np.ndim(val) == 0 else i, par.unit, v, low, high))
    return out


def _structure_range(model: FrictionModel, par: Parameter, value: float) -> tuple[float, float]:
    """The declared range of ``par``, open ends kept at a margin, narrowed to the values that keep
    the start model's structure (Dahl: ``gamma >= 1`` or ``gamma < 1``, ``docs/models.md#structure``)."""
    from prefriction.models.dahl import Dahl

    low, high = par.low, par.high
    if par.low_open:
        low = low + _OPEN * (abs(low) if low != 0.0 else abs(value))
    if par.high_open:
        high = high - _OPEN * (abs(high) if high != 0.0 else abs(value))
    if isinstance(model, Dahl) and par.name == "gamma":
        low, high = (1.0, high) if value >= 1.0 else (low, 1.0 - _OPEN)
    return low, high


def _structure_bound(model: FrictionModel, name: str, value: float) -> tuple[str, str]:
    """What each end of ``name``'s range is: the declared range or a structure boundary."""
    from prefriction.models.dahl import Dahl

    if isinstance(model, Dahl) and name == "gamma":
        side = "the Dahl structure boundary gamma = 1"
        return (side, "the declared range") if value >= 1.0 else ("the declared range", side)
    return "the declared range", "the declared range"


def _relations(model: FrictionModel) -> list[tuple[str, str]]:
    """``(low, high)`` entry names with ``value[high] >= value[low]`` required by the model's
    constructor: ``Fs >= Fc`` of LuGre, ElastoPlastic and GMS (each term of a sum under its qualified
    names)."""
    from prefriction.models.elasto_plastic import ElastoPlastic
    from prefriction.models.gms import GMS
    from prefriction.models.lugre import LuGre
    from prefriction.models.parallel import Parallel

    if isinstance(model, Parallel):
        entries = _entries(model)
        out = []
        for i, m in enumerate(model.models):
            local = {e.local: e.name for e in entries if e.part == i}
            out += [(local[a], local[b]) for a, b in _relations(m)]
        return out
    return [("Fc", "Fs")] if isinstance(model, (LuGre, ElastoPlastic, GMS)) else []


def _fractions(model: FrictionModel) -> list[tuple[str, str, str]]:
    """``(name, num, den)`` entry names with ``value[name] < value[num] / value[den]`` required by the
    model's constructor: ElastoPlastic's ``z_ba < Fc / sigma0`` (each term of a sum under its
    qualified names)."""
    from prefriction.models.elasto_plastic import ElastoPlastic
    from prefriction.models.parallel import Parallel

    if isinstance(model, Parallel):
        entries = _entries(model)
        out = []
        for i, m in enumerate(model.models):
            local = {e.local: e.name for e in entries if e.part == i}
            out += [(local[a], local[b], local[c]) for a, b, c in _fractions(m)]
        return out
    return [("z_ba", "Fc", "sigma0")] if isinstance(model, ElastoPlastic) else []


class ParameterSpace(ThetaMaps, ParameterConstraints):
    """Which of a model's parameters (and the mass) a fit moves, their start values and bounds.

    Relations between parameters that the model's constructor checks (``Fs >= Fc`` of LuGre
    and GMS) are part of the problem, so a fit always returns a model that constructs: with
    ``Fs`` fixed, ``Fc`` is bounded by it (and ``Fs`` by a fixed ``Fc``); with both free, the
    fit moves ``Fc`` and the excess ``Fs - Fc >= 0`` (bounded below by 0), and the statistics are
    transformed back to ``Fs`` (:meth:`physical_jacobian`).

    Parameters
    ----------
    model : FrictionModel
        The start model (its parameter values are the starting values).
    free : sequence of str or None
        Names to fit; ``None`` fits every parameter not in ``fixed``.
    fixed : sequence of str or None
        Names held at their start values.
    bounds : dict or None
        ``{name: (low, high)}`` in the parameter's unit, inside its declared range.
    mass : float or None
        Start value [kg] of a fitted mass (``"mass"`` becomes a free entry); ``None`` if the mass
        is known or not involved.
    offset : float or None
        Scale [N] of a fitted force offset (``"offset"`` becomes a free entry, started at
        ``offset0`` and moved as ``offset / scale``); ``None`` for no offset.
    offset0 : float, default 0.0
        Start value [N] of the fitted offset.

    Raises
    ------
    ValueError
        For an unknown name, a name both free and fixed, no free parameter, or bounds outside
        the declared range or not containing the start value.
    """

    def __init__(self, model: FrictionModel, free: Sequence[str] | None, fixed: Sequence[str] | None,
                 bounds: dict | None, mass: float | None = None, offset: float | None = None,
                 offset0: float = 0.0) -> None:
        self.model = model
        entries = _entries(model)
        if mass is not None:
            entries.append(_Entry("mass", "mass", None, "kg", float(mass), _OPEN * float(mass), math.inf))
        if offset is not None:
            entries.append(_Entry("offset", "offset", None, "N", float(offset0), -math.inf, math.inf))
        self.entries = entries
        names = [e.name for e in entries]
        free_l = _names("free", free, names, model)
        fixed_l = _names("fixed", fixed, names, model)
        both = sorted(set(free_l or []) & set(fixed_l or []))
        if both:
            raise ValueError(f"free and fixed both name {both}: a parameter is either fitted or held")
        if free_l is None:
            free_l = [n for n in names if n not in set(fixed_l or [])]
        for extra in ("mass", "offset"):
            if extra in names and extra not in free_l and extra not in (fixed_l or []):
                free_l.append(extra)
        if not free_l:
            raise ValueError(f"no parameter left to fit: free = {free!r}, fixed = {fixed!r} (allowed names: {names})")
        self.free = [n for n in names if n in set(free_l)]
        self.fixed = [n for n in names if n not in set(self.free)]
        self.low = {e.name: e.low for e in entries}
        self.high = {e.name: e.high for e in entries}
        self.start = {e.name: e.value for e in entries}
        self.units = {e.name: e.unit for e in entries}
        self._scale = {e.name: e.value for e in entries}
        if offset is not None:
            self._scale["offset"] = check_positive("offset scale", offset)
        self.why_low, self.why_high = {}, {}
        parts = getattr(model, "models", ())
        for e in entries:
            owner = parts[e.part] if e.part is not None else model
            self.why_low[e.name], self.why_high[e.name] = _structure_bound(owner, e.local or e.name, e.value)
        for name, lim in _bound_items(bounds):
            self._set_bound(name, lim, names)
        self.excess: dict[str, str] = {}
        """``{high: low}`` of the relations with both ends free: ``high`` is moved as ``high - low``."""
        for lo_name, hi_name in _relations(model):
            self._relate(lo_name, hi_name)
        self.fraction: dict[str, tuple[str, str]] = {}
        """``{name: (num, den)}`` of the bounds ``name < num / den`` with ``name`` free: ``name`` is moved
        as ``q = value[name] (value[den] / value[num]) (start[num] / start[den])``, bounded by
        ``start[num] / start[den]`` (the start values of ``num`` and ``den`` are their scales, or
        their fixed values: inputs of the compiled steps, so one step serves every start)."""
        for name, num, den in _fractions(model):
            self._bound_by_ratio(name, num, den)
        for name in self.free:
            if self._scale[name] == 0.0:
                raise ValueError(f"the start value of {name} is 0: a fitted parameter needs a non-zero start "
                                 f"value (its scale); give the model a small positive {name}")

    # ------------------------------------------------------------------ vectors
    @property
    def n_free(self) -> int:
        return len(self.free)

    @property
    def scale(self) -> np.ndarray:
        """Scales of the free entries (their start values; the offset's force scale; the start
        excess of a related ``high`` entry): the fit moves ``theta = p / scale``
        (``theta = (p_high - p_low) / scale`` for a related pair)."""
        return np.array([self._scale[n] for n in self.free])

    @property
    def theta0(self) -> np.ndarray:
        """The scaled start values (1, or ``offset0 / scale``, or the start excess over its scale)."""
        return self.theta_of(self.start)

    def fixed_values(self) -> np.ndarray:
        return np.array([self.start[n] for n in self.fixed])

    def build(self, values: dict[str, float]) -> FrictionModel:
        """A model of the start model's class with ``values`` (the constructor validates them).

        Raises
        ------
        ValueError
            If the model rejects the values (e.g. LuGre with ``Fs < Fc``); the message says so.
        """
        try:
            return _build(self.model, [e for e in self.entries if e.field not in ("mass", "offset")], values)
        except ValueError as exc:
            raise ValueError(f"the fitted values do not make a valid {type(self.model).__name__}: {exc}; "
                             f"bound the parameters (bounds=...) or fix some (fixed=...)") from exc


def _bound_items(bounds: Any) -> list[tuple[str, Any]]:
    """The ``(name, (low, high))`` pairs of ``bounds``, which must be a mapping."""
    if bounds is None:
        return []
    if not isinstance(bounds, Mapping):
        raise TypeError(f"bounds must be a dict {{name: (low, high)}} in the parameters' units, e.g. "
                        f"bounds={{'sigma': (1e3, 1e6)}}, got {bounds!r} of type {type(bounds).__name__} "
                        f"(a list cannot say which parameter each pair bounds)")
    return list(bounds.items())


def _build(model: FrictionModel, entries: list[_Entry], values: dict[str, float]) -> FrictionModel:
    """A model of ``model``'s class (a sum: of each term's class) with the entries' ``values``."""
    from prefriction.models.parallel import Parallel

    if isinstance(model, Parallel):
        return Parallel(tuple(
            _build(m, [dataclasses.replace(e, name=e.local, part=None) for e in entries if e.part == i],
                   {e.local: values[e.name] for e in entries if e.part == i})
            for i, m in enumerate(model.models)))
    kwargs: dict[str, Any] = {}
    for e in entries:
        if e.index is None:
            kwargs[e.field] = values[e.name]
        else:
            kwargs.setdefault(e.field, np.array(getattr(model, e.field), dtype=float).copy())
            kwargs[e.field][e.index] = values[e.name]
    return dataclasses.replace(model, **kwargs)


def name_list(arg: str, value: Any) -> list[str] | None:
    """``value`` of the option ``arg`` (``free`` or ``fixed``) as a list of names: ``None``, one
    name or a sequence of names; ``TypeError`` naming ``arg`` for anything else."""
    if value is None:
        return None
    if isinstance(value, str):
        return [value]
    try:
        out = list(value)
    except TypeError:
        out = None
    if out is None or not all(isinstance(n, str) for n in out):
        raise TypeError(f"{arg} must be None, a parameter name or a sequence of names (e.g. {arg}=['sigma', 'Fc']), "
                        f"got {value!r} of type {type(value).__name__}")
    return out


def _names(arg: str, value: Any, names: list[str], model: FrictionModel) -> list[str] | None:
    if value is None:
        return None
    if isinstance(value, str):
        value = [value]
    out = list(value)
    for n in out:
        if n not in names:
            raise ValueError(f"{arg} names an unknown parameter {n!r} of {type(model).__name__} "
                             f"(allowed: {names})")
    return out


@dataclass(frozen=True)
class _SymScales:
    """The velocity unit of a system, as a CasADi expression (what ``runtime_params_for`` reads)."""

    x: Any
    F: Any
    t: Any
    v: Any
    E: Any


def symbolic_units(model: FrictionModel, values: dict[str, Any], mass: Any) -> tuple[Any, Any, Any]:
    """``(sigma, Fc, q)`` of ``model``'s class as CasADi expressions of the physical ``values``.

    Parameters
    ----------
    model : FrictionModel
        The start model (its class and structure).
    values : dict
        Physical values by entry name (CasADi ``SX`` or floats).
    mass : SX or float
        Mass [kg] of the system (the velocity unit of rate-dependent models).

    Returns
    -------
    (SX, SX, SX)
        Reference stiffness [N/m], reference force [N] and the column of run-time numbers.

    Raises
    ------
    TypeError
        If the model's ``sigma``, ``Fc`` or ``runtime_params_for`` cannot be evaluated on CasADi
        symbols (it uses ``math`` functions on its numbers).
    """
    from prefriction.models.gms import GMS
    from prefriction.models.maxwell_slip import MaxwellSlip
    from prefriction.models.parallel import Parallel

    if isinstance(model, Parallel):  # each term in its own units, composed (Parallel.compose)
        entries = _entries(model)
        units = [symbolic_units(m, {e.local: values[e.name] for e in entries if e.part == i}, mass)
                 for i, m in enumerate(model.models)]
        sigma, Fc, q = model.compose(units)
        return sigma, Fc, ca.vertcat(*q)
    fields: dict[str, Any] = {}
    for par in type(model).parameters:
        val = getattr(model, par.name)
        if np.ndim(val) == 0:
            fields[par.name] = values[par.name]
        else:
            fields[par.name] = ca.vertcat(*[values[f"{par.name}[{i}]"] for i in range(np.size(val))])
    if isinstance(model, MaxwellSlip):
        k, W = fields["stiffness"], fields["slip_force"]
        sigma, Fc = ca.sum1(k), ca.sum1(W)
        return sigma, Fc, ca.vertcat(k / sigma, W / Fc)
    if isinstance(model, GMS):  # GMS.runtime_params_for, written for CasADi columns
        f = fields
        sigma, Fc = ca.sum1(f["k"]), f["Fc"]
        V = Fc / ca.sqrt(mass * sigma)
        kappa = f["k"] / sigma
        tail = ca.vertcat(f["Fs"] / Fc - 1.0, V / f["vs"], 0.5 * f["delta"], f["C"] / (sigma * V), f["sigma2"] * V / Fc)
        return sigma, Fc, ca.vertcat(kappa, f["alpha"], f["damping"] * V / Fc / kappa, tail)
    sym = object.__new__(type(model))
    for f in dataclasses.fields(model):
        object.__setattr__(sym, f.name, getattr(model, f.name))
    for name, val in fields.items():
        object.__setattr__(sym, name, val)
    try:
        sigma, Fc = sym.sigma, sym.Fc
        V = Fc / ca.sqrt(mass * sigma)
        scales = _SymScales(x=Fc / sigma, F=Fc, t=ca.sqrt(mass / sigma), v=V, E=Fc * Fc / sigma)
        q = sym.runtime_params_for(scales)
        q = ca.vertcat(*[q[i] for i in range(len(q))]) if len(q) else ca.SX(0, 1)
    except Exception as exc:
        raise TypeError(f"fit cannot express the normalised numbers of {type(model).__name__} through CasADi "
                        f"symbols ({type(exc).__name__}: {exc}); its sigma, Fc and runtime_params_for must "
                        f"use arithmetic or casadi functions on the parameters") from exc
    return sigma, Fc, q
