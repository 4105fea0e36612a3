"""The C code of a friction model for the native driver: CasADi Functions of the unforced oscillator.

The normalised unforced oscillator ``x~' = v~``, ``v~' = -F~``, ``z' = rate(z, m, v~, s, q)``
(``docs/mathematics.md#normalised-units``) is written as seven small CasADi Functions of the
state ``y = (x~, v~, z...)``, the flags ``m``, the branch direction ``s`` and the model's
run-time numbers ``q``. :func:`model_source` generates their C code (``Function.generate``,
one file) with the sizes the driver (``driver.c``) needs as ``#define`` lines:

``pf_rhs(y, m, s, q) -> y'``
    the right-hand side;
``pf_ind(y, m, s, q) -> g``
    the model's event indicators (:meth:`~prefriction.FrictionModel.events`);
``pf_event(y, m, s, q, k) -> (z, m)``
    the state after model event ``k`` (:meth:`~prefriction.FrictionModel.on_event`);
``pf_reverse(y, m, s_new, q, snap) -> (z, m, F~)``
    the state after a reversal into direction ``s_new`` and the force there
    (:meth:`~prefriction.FrictionModel.reverse`);
``pf_force(y, m, s, q) -> F~`` and ``pf_pot(z, m, s, q) -> potential``
    the force and the branch potential (:meth:`~prefriction.FrictionModel.branch_potential`;
    0 for a model without one);
``pf_vscale(y, m, s, q) -> vs~``
    the model's velocity scale (:meth:`~prefriction.FrictionModel.velocity_scale`; 0 for none),
    near which the driver bounds its steps.

The model's methods build the expressions, as for the CasADi plant
(:mod:`prefriction.simulation.plant`): one source per :meth:`~prefriction.FrictionModel.structure_key`,
every number a run-time input.
"""

from __future__ import annotations

import warnings

import casadi as ca

from prefriction.models.base import FrictionModel
from prefriction.simulation.compiled import generated_source
from prefriction.simulation.plant import EPS_DIED, _event_indices, _select, has_potential, model_event

__all__ = ["model_functions", "model_source"]


def model_functions(model: FrictionModel) -> list[ca.Function]:
    """The seven Functions of the module notes for ``model`` (its structure, numbers symbolic)."""
    nz, nm, nq = model.n_states, model.n_flags, len(model.runtime_params())
    y, m, s, q = ca.SX.sym("y", 2 + nz), ca.SX.sym("m", nm), ca.SX.sym("s"), ca.SX.sym("q", nq)
    v = y[1]
    z, mm = [y[2 + i] for i in range(nz)], [m[i] for i in range(nm)]
    args, names = [y, m, s, q], ["y", "m", "s", "q"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        F = model.force(z, mm, v, s, q)
        rhs = ca.vertcat(v, -F, *model.rate(z, mm, v, s, q))
        ind = ca.vertcat(*model.events(z, mm, v, s, q)) if model.n_events else ca.SX(1, 1)
        k = ca.SX.sym("k")
        posts = []
        for kk in _event_indices(model, k):
            zn, mn = model_event(model, kk, z, mm, s, q)
            posts.append(ca.vertcat(*zn, *mn))
        event = _select(k, [], posts, model.n_events, []) if posts else ca.SX.zeros(nz + nm)
        snap = ca.SX.sym("snap")
        zr, mr = model.reverse(z, mm, -s, q, snap)
        F_rev = model.force(zr, mr, 0.0, -s, q)
        pot = model.branch_potential(z, mm, s, q) if has_potential(model) else 0.0
        vscale = model.velocity_scale(q)
    funs = [
        ca.Function("pf_rhs", args, [rhs], names, ["dy"]),
        ca.Function("pf_ind", args, [ind], names, ["g"]),
        ca.Function("pf_event", args + [k], [event[:nz], event[nz:]], names + ["k"], ["z_next", "m_next"]),
        ca.Function("pf_reverse", args + [snap], [ca.vertcat(*zr), ca.vertcat(*mr), F_rev],
                    names + ["snap"], ["z_next", "m_next", "F"]),
        ca.Function("pf_force", args, [F], names, ["F"]),
        ca.Function("pf_pot", args, [ca.SX(pot)], names, ["pot"]),
        ca.Function("pf_vscale", args, [ca.SX(0.0 if vscale is None else vscale)], names, ["vs"]),
    ]
    return funs


def model_source(model: FrictionModel, extra: tuple[ca.Function, ...] = ()) -> str:
    """C source of :func:`model_functions` and the ``extra`` Functions (e.g. the input force of
    :mod:`~prefriction.simulation.native.forced`) with the driver's size definitions (``PF_NZ``, ...)."""
    funs = model_functions(model) + list(extra)
    code = generated_source("pf_model", funs)
    sizes = {
        "PF_NZ": model.n_states,
        "PF_NM": model.n_flags,
        "PF_NQ": len(model.runtime_params()),
        "PF_NE": model.n_events,
        "PF_POT": int(has_potential(model)),
        "PF_VSCALE": int(model.velocity_scale(model.runtime_params()) is not None),
        "PF_RATE_INDEPENDENT": int(model.rate_independent),
        "PF_NORM_X": int(not model.tracks_position),
        "PF_NOISE": repr(EPS_DIED),
        "PF_SZ_ARG": max(f.sz_arg() for f in funs),
        "PF_SZ_RES": max(f.sz_res() for f in funs),
        "PF_SZ_IW": max(f.sz_iw() for f in funs) + 1,
        "PF_SZ_W": max(f.sz_w() for f in funs) + 1,
    }
    head = "".join(f"#define {k} {v}\n" for k, v in sizes.items())
    return head + code
