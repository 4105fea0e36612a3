"""What a friction model must provide, checked once per structure before a plant is built.

A user model whose ``rate()`` returns more entries than ``n_states``, or whose ``events()``
returns fewer indicators than ``n_events``, used to fail deep inside the plant (a ``KeyError``
such as ``'z1'``) or run without the event. :func:`check_sizes` calls the symbolic methods
once with CasADi symbols and names the method, its count and the declared one.
"""

from __future__ import annotations

from typing import Any, Hashable

import casadi as ca

__all__ = ["check_sizes"]

_CHECKED: set = set()  # (class, structure key) of the models that passed: checked once per structure


def _count(what: Any) -> int:
    try:
        return len(what)
    except TypeError:
        return -1


def check_sizes(model: Any) -> None:
    """``TypeError`` naming the method whose output size differs from the model's declared sizes,
    or a rate-independent model without ``branch_energy_of_force`` (every run's reversal table
    takes its potential energies from it). A structure that passed is not checked again (the
    class and :meth:`~prefriction.FrictionModel.structure_key` fix every size)."""
    key: Hashable = (type(model).__module__, type(model).__qualname__, model.structure_key())
    if key in _CHECKED:
        return
    _check(model)
    _CHECKED.add(key)


def _check(model: Any) -> None:
    """:func:`check_sizes` without the memory of structures that passed."""
    name = type(model).__name__
    from prefriction.models.base import FrictionModel

    if (model.rate_independent and model.n_states != 1
            and type(model).branch_energy_of_force is FrictionModel.branch_energy_of_force):
        raise TypeError(
            f"{name} is rate-independent (rate_independent = True) with {model.n_states} states but does not "
            f"implement branch_energy_of_force(F, s), which gives the potential energy E_p at every reversal (the "
            f"quadrature default serves one-state models): implement it (docs/models.md#energy), or declare "
            f"rate_independent = False if the model is not")
    nz, nm, ne = int(model.n_states), int(model.n_flags), int(model.n_events)
    nq = len(model.runtime_params())
    z, m = ca.SX.sym("z", nz), ca.SX.sym("m", nm)
    zl, ml = [z[i] for i in range(nz)], [m[i] for i in range(nm)]
    v, s, q = ca.SX.sym("v"), ca.SX.sym("s"), ca.SX.sym("q", nq)

    def need(method: str, got: Any, want: int, declared: str) -> None:
        k = _count(got)
        if k != want:
            shown = f"{k} entries" if k >= 0 else f"a {type(got).__name__}, not a list"
            raise TypeError(f"{name}.{method} returned {shown}; the model declares {declared} = {want} "
                            f"(return exactly one entry per {declared[2:].rstrip('s')})")

    need("rate()", model.rate(zl, ml, v, s, q), nz, "n_states")
    need("events()", model.events(zl, ml, v, s, q), ne, "n_events")
    F = ca.SX(model.force(zl, ml, v, s, q))
    if F.numel() != 1:
        raise TypeError(f"{name}.force() returned {F.numel()} values; it must return one force (a scalar)")
    zr, mr = model.reverse(zl, ml, -s, q, 1e-9)
    need("reverse() states", zr, nz, "n_states")
    need("reverse() flags", mr, nm, "n_flags")
    for k in range(ne):
        ze, me = model.on_event(k, zl, ml, s, q)
        need(f"on_event({k}) states", ze, nz, "n_states")
        need(f"on_event({k}) flags", me, nm, "n_flags")
