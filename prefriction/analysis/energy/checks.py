"""Argument checks of the energy analysis (:mod:`prefriction.energy`): sample arrays, quadrature
method, Dahl friction model; messages name the argument, its value and the allowed range."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from prefriction.models import GMS, ElastoPlastic, FrictionModel, LuGre, MaxwellSlip, check_oscillator

QUADRATURES = ("trapezoid", "simpson")
"""Quadrature rules of the power integrals: cumulative trapezoid or Simpson (scipy)."""
ROUNDING = 64 * np.finfo(float).eps
"""Relative slack of the checks ``|F| <= Fc`` and ``E_p <= bound`` for rounding errors."""


def _describe(values: Any) -> str:
    """Short ``repr`` of an argument for a message (long arrays cut)."""
    text = repr(values)
    return text if len(text) <= 80 else text[:77] + "..."


def real_array(name: str, values: Any, *, what: str = "a 1-D array of real numbers") -> np.ndarray:
    """Return ``values`` as a float array (any shape), or raise ``TypeError`` naming ``name``.

    Refused with ``TypeError``: ``None``, strings and bytes, complex numbers, and anything numpy
    cannot convert to float (ragged lists, objects).
    """
    if values is None or isinstance(values, (str, bytes)):
        raise TypeError(f"{name} must be {what}, got {_describe(values)} of type {type(values).__name__}")
    try:
        raw = np.asarray(values)
        if np.iscomplexobj(raw):
            raise TypeError("complex entries")
        arr = np.asarray(raw, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be {what}, got {_describe(values)} ({'complex entries' if 'complex' in str(exc) else 'not convertible to real numbers'})") from None
    return arr


def first_bad(name: str, arr: np.ndarray, bad: np.ndarray, allowed: str) -> None:
    """Raise ``ValueError`` naming the first entry of ``arr`` flagged in ``bad``, if any."""
    if np.any(bad):
        i = np.unravel_index(int(np.flatnonzero(bad)[0]), arr.shape)
        where = f"{name}[{', '.join(str(int(k)) for k in i)}]" if arr.ndim else name
        raise ValueError(f"{name} must be {allowed} (every entry), got {where} = {float(arr[i])!r}")


def finite_energy(what: str, E: np.ndarray, inputs: str) -> np.ndarray:
    """``E`` [J] if every entry is finite; else ``ValueError`` naming the first overflow and its inputs."""
    bad = ~np.isfinite(E)
    if np.any(bad):
        i = int(np.flatnonzero(bad.ravel())[0])
        raise ValueError(
            f"{what} overflows the double-precision range (|E| > 1.8e308 J) at entry {i}: {inputs} are too large; "
            f"allowed: inputs whose energies stay below 1.8e308 J (rescale the units)")
    return E


def value_array(name: str, values: Any, *, nonnegative: bool = False, min_size: int = 1, ndim: int = 1) -> np.ndarray:
    """Return ``values`` as a finite float array of at most ``ndim`` dimensions (a number counts
    as length 1) with at least ``min_size`` entries, entries >= 0 if ``nonnegative``."""
    arr = real_array(name, values)
    if arr.ndim > ndim:
        raise ValueError(f"{name} must be a number or a 1-D array, got an array of shape {arr.shape}")
    if arr.size < min_size:
        raise ValueError(f"{name} must hold at least {min_size} value{'s' if min_size > 1 else ''}, got {arr.size} (shape {arr.shape})")
    first_bad(name, arr, ~np.isfinite(arr), "finite (allowed: finite reals)")
    if nonnegative:
        first_bad(name, arr, arr < 0.0, ">= 0 (allowed range: 0 <= value < inf)")
    return arr


def sample_array(name: str, values: Any) -> np.ndarray:
    """Return ``values`` as a finite 1-D float array of length >= 2, or raise naming ``name``."""
    arr = real_array(name, values)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got an array of shape {arr.shape}")
    if arr.size < 2:
        raise ValueError(f"{name} must hold at least 2 samples, got {arr.size}")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} must be finite, got {name}[{i}] = {float(arr[i])!r} (allowed: finite reals)")
    return arr


def check_samples(**arrays: Any) -> list[np.ndarray]:
    """Validate sample arrays: the first is time (strictly increasing), all of equal length."""
    names = list(arrays)
    out = [sample_array(name, arrays[name]) for name in names]
    n = out[0].size
    for name, arr in zip(names[1:], out[1:]):
        if arr.size != n:
            raise ValueError(
                f"{name} has length {arr.size} but {names[0]} has length {n} "
                "(all sample arrays must have the same length)"
            )
    if names[0] == "t":
        dt = np.diff(out[0])
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ValueError(
                f"t must be strictly increasing, got t[{i + 1}] = {float(out[0][i + 1])!r} <= t[{i}] = {float(out[0][i])!r}"
            )
    return out


def check_method(method: Any) -> str:
    """Return the quadrature ``method`` if it is one of :data:`QUADRATURES`; ``ValueError`` otherwise."""
    if method not in QUADRATURES:
        raise ValueError(f"method must be one of {QUADRATURES}, got {method!r}")
    return method


def check_flag(name: str, value: Any) -> bool:
    """Return ``value`` if it is ``True`` or ``False`` (numpy booleans too); ``TypeError`` otherwise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {_describe(value)} of type {type(value).__name__}")
    return bool(value)


def check_system(system: Any, *, lugre: bool = False) -> tuple[FrictionModel, float]:
    """Return the friction model the energy analysis works with and the mass of ``system``.

    The model is :func:`check_model`'s (a rate-independent model, a GMS in its rate-independent
    configuration as the equal Maxwell-slip model); with ``lugre`` a :class:`prefriction.LuGre`
    model is returned as it is, and so is a :class:`prefriction.ElastoPlastic` model (the same
    bristle, the same stored energy ``sigma0 z^2 / 2``). ``TypeError`` otherwise.
    """
    friction = check_oscillator(system, "the energy analysis")
    if lugre and isinstance(friction, (LuGre, ElastoPlastic)):
        return friction, system.mass
    return check_model(friction), system.mass


def gms_as_maxwell_slip(friction: GMS) -> Optional[MaxwellSlip]:
    """The Maxwell-slip model equal to ``friction`` (``W_i = alpha_i Fc``) if the GMS model is in
    its rate-independent configuration (``Fs = Fc``, no micro-damping, ``sigma2 = 0``), else None."""
    if friction.Fs == friction.Fc and friction.sigma2 == 0.0 and not np.any(friction.damping):
        return MaxwellSlip(np.asarray(friction.k), np.asarray(friction.alpha) * friction.Fc)
    return None


def check_model(friction: Any) -> FrictionModel:
    """Return ``friction`` if it is a rate-independent :class:`prefriction.FrictionModel` with a
    branch energy (the energy analysis (2.3)-(2.12) needs it), or the equal
    :class:`prefriction.MaxwellSlip` of a :class:`prefriction.GMS` in its rate-independent
    configuration; ``TypeError`` otherwise."""
    if not isinstance(friction, FrictionModel):
        raise TypeError(f"friction must be a prefriction.FrictionModel such as Dahl, got {_describe(friction)} "
                        f"of type {type(friction).__name__}")
    if isinstance(friction, GMS):
        equal = gms_as_maxwell_slip(friction)
        if equal is None:
            raise TypeError(
                "the energy analysis needs a rate-independent friction model; this GMS is rate-dependent "
                f"(Fs = {friction.Fs!r} N vs Fc = {friction.Fc!r} N, sigma2 = {friction.sigma2!r} N s/m, damping "
                f"{np.asarray(friction.damping).tolist()!r} N s/m): with Fs = Fc and no damping it is Maxwell-slip "
                "and analysed as such; otherwise its stored energy sum F_i^2/(2 k_i) needs the element forces, "
                "which samples of (t, x, v, F) do not hold"
            )
        return equal
    if not friction.rate_independent:
        extra = " (LuGre: pass the Oscillator to analyze_samples, which splits viscous and hysteretic dissipation)" \
            if isinstance(friction, LuGre) else ""
        raise TypeError(f"the energy analysis needs a rate-independent friction model, got {type(friction).__name__}{extra}")
    if friction.n_states != 1 and type(friction).branch_energy_of_force is FrictionModel.branch_energy_of_force:
        raise TypeError(f"the energy analysis needs the branch energy as a function of the force; "
                        f"{type(friction).__name__} does not define branch_energy_of_force")
    return friction
