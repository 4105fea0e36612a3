"""The bookkeeping :class:`prefriction.FrictionModel` derives from a model's mathematics
(``model`` is a :class:`prefriction.FrictionModel`, annotated ``Any``: the base imports this module).

A model declares its parameters, ``n_states``, ``rate`` and ``force`` (and, if it has them,
``events`` with ``on_event``); the base class fills in the rest from these functions:

- :func:`normalised_parameters`: the run-time vector ``q``, every declared parameter in the
  normalised units of its unit (``N/m`` by ``sigma``, ``N`` by ``Fc``, ``m`` by ``Fc / sigma``,
  ``s`` by ``sqrt(m / sigma)``, products and quotients of them);
- :func:`detect_rate_independent`: whether the force ignores ``v`` and the rate is ``v`` times
  a function of the state (traced once on CasADi symbols);
- :func:`state_of_force`: the state of a one-state model with a given force on a branch;
- :func:`branch_energy_by_quadrature`: the stored energy on a branch, ``-int F dx`` from the
  state back to the force's zero crossing, by ``scipy.integrate.quad``.
"""

from __future__ import annotations

import math
import re
from typing import Any

import casadi as ca
import numpy as np

__all__ = ["branch_energy_by_quadrature", "detect_rate_independent", "normalised_parameters", "state_of_force",
           "unit_exponents"]

_BASE = {"N": (1, 0, 0), "m": (0, 1, 0), "s": (0, 0, 1), "kg": (1, -1, 2), "J": (1, 1, 0), "Hz": (0, 0, -1),
         "-": (0, 0, 0), "1": (0, 0, 0), "rad": (0, 0, 0)}
_TOKEN = re.compile(r"^([A-Za-z]+|-|1)(?:\^(-?\d+))?$")


def unit_exponents(unit: str) -> tuple[int, int, int]:
    """Powers ``(a, b, c)`` of ``N^a m^b s^c`` of a unit written as ``"N s/m"``, ``"m/s^2"``,
    ``"N m"``, ``"kg"``, ``"1/s"`` or ``"-"`` (one ``/``; tokens ``N m s kg J Hz rad``, ``^k`` powers).
    ``ValueError`` naming the unit for anything else."""
    num, _, den = unit.partition("/")
    total = [0, 0, 0]
    for part, sign in ((num, 1), (den, -1)):
        for tok in part.replace("*", " ").replace("(", " ").replace(")", " ").split():
            match = _TOKEN.match(tok)
            if not match or match.group(1) not in _BASE:
                raise ValueError(f"unit {unit!r}: cannot read {tok!r} (allowed: N, m, s, kg, J, Hz, rad, -, "
                                 f"powers as m^2, one '/')")
            k = sign * int(match.group(2) or 1)
            total = [t + k * e for t, e in zip(total, _BASE[match.group(1)])]
    return total[0], total[1], total[2]


def normalised_parameters(model: Any, x: float, F: float, t: float) -> np.ndarray:
    """Every declared parameter of ``model`` divided by its unit ``F^a x^b t^c`` (the system's
    force, length and time units ``F = Fc``, ``x = Fc / sigma``, ``t = sqrt(m / sigma)``)."""
    out = []
    for par in model.parameters:
        try:
            a, b, c = unit_exponents(par.unit)
        except ValueError as err:
            raise TypeError(f"{type(model).__name__}: parameter {par.name}: {err}; declare a unit of that form "
                            f"or override runtime_params_for(scales), which gives the run-time numbers") from None
        out.append(getattr(model, par.name) / (F ** a * x ** b * t ** c))
    if any(isinstance(v, (ca.SX, ca.MX)) for v in out):  # the fit's symbolic parameters: a list of them
        return out  # type: ignore[return-value]
    return np.array(out, dtype=float)


_RATE_INDEPENDENT: dict = {}  # (class, structure key) -> bool: traced once per structure


def detect_rate_independent(model: Any) -> bool:
    """True if ``force`` does not depend on ``v`` and ``rate`` is ``v`` times a function of the state
    (the model traces the same curve at any speed), traced on CasADi symbols once per structure
    (the methods build their expressions from ``q``, so every instance of a structure agrees)."""
    key = (type(model), model.structure_key())
    if key not in _RATE_INDEPENDENT:
        _RATE_INDEPENDENT[key] = _trace_rate_independent(model)
    return _RATE_INDEPENDENT[key]


def _trace_rate_independent(model: Any) -> bool:
    """:func:`detect_rate_independent` for one instance."""
    nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
    z = [ca.SX.sym(f"z{i}") for i in range(nz)]
    m = [ca.SX.sym(f"m{i}") for i in range(nm)]
    q = ca.SX.sym("q", nq)
    v, s = ca.SX.sym("v"), ca.SX.sym("s")
    qs = [q[i] for i in range(nq)]
    F = model.force(z, m, v, s, qs)
    r = ca.vertcat(*model.rate(z, m, v, s, qs))
    if ca.depends_on(ca.SX(F), v):
        return False
    slope = ca.jacobian(r, v)
    if ca.depends_on(slope, v):
        return False
    at_rest = ca.Function("at_rest", [ca.vertcat(*z, *m, s, q)], [ca.substitute(r, v, ca.SX(0.0))])
    rng = np.random.default_rng(0)
    return all(float(np.max(np.abs(np.array(at_rest(rng.uniform(-0.5, 0.5, nz + nm + 1 + nq)))), initial=0.0)) == 0.0
               for _ in range(3))


def state_of_force(model: Any, f: float, s: float, q: Any) -> float:
    """The state ``z`` of a one-state model whose force at rest is ``f`` on a branch of direction
    ``s`` (the force increasing with ``s z``; bracketed by doubling, then ``brentq``)."""
    from scipy.optimize import brentq

    if f == 0.0 and float(model.force([0.0], [0.0] * model.n_flags, 0.0, s, q)) == 0.0:
        return 0.0

    def gap(z: float) -> float:
        return float(model.force([z], [0.0] * model.n_flags, 0.0, s, q)) - f

    lo, hi = -1.0, 1.0
    for _ in range(60):
        glo, ghi = gap(lo), gap(hi)
        if np.isfinite(glo) and np.isfinite(ghi) and glo * ghi <= 0.0:
            return float(brentq(gap, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps))
        lo, hi = 2.0 * lo if np.isfinite(glo) else 0.5 * lo, 2.0 * hi if np.isfinite(ghi) else 0.5 * hi
    raise ValueError(f"{type(model).__name__}: no state has the normalised force {f!r} at rest on a branch of "
                     f"direction {s!r}; give initial_state(f0, s) for this model")


def branch_energy_by_quadrature(model: Any, F: np.ndarray, s: Any) -> np.ndarray:
    """``-int F dx`` along the branch of direction ``s`` from the state of force ``F`` to the one of
    force zero, ``dx = s dz / rate(z, s)`` at unit speed: ``quad`` per entry (one-state models)."""
    from scipy.integrate import quad

    F, s = np.broadcast_arrays(np.asarray(F, dtype=float), np.asarray(s, dtype=float))
    q = np.asarray(model.runtime_params(), dtype=float).tolist()
    m0 = [0.0] * model.n_flags
    out = np.empty(F.shape)
    for i, (f, si) in enumerate(zip(F.ravel(), s.ravel())):
        z_f, z_0 = state_of_force(model, float(f), float(si), q), state_of_force(model, 0.0, float(si), q)

        def integrand(z: float, si: float = float(si)) -> float:
            return float(model.force([z], m0, 0.0, si, q)) * si / float(model.rate([z], m0, si, si, q)[0])

        val, _err = quad(integrand, z_f, z_0, epsabs=0.0, epsrel=1e-13, limit=200)
        out.flat[i] = -val if math.isfinite(val) else math.nan
    return out
