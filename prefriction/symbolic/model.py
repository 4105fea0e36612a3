"""A branch of the plant as named CasADi expressions, as acados and do-mpc take a model: :func:`branch_model`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from prefriction.models import Oscillator
from prefriction.symbolic.branch import branch_functions
from prefriction.units import Scales

__all__ = ["BranchModel", "branch_model"]


@dataclass(frozen=True, repr=False)
class BranchModel:
    """The stage on one branch of direction ``s`` in the naming of acados' ``AcadosModel`` and do-mpc.

    ``m x'' = u - F`` (2.1) with the friction model's state equations, in the normalised units
    of :class:`prefriction.Scales` (``x~ = x sigma / Fc``, ``v~``, ``u~ = u / Fc``, ``t~``),
    valid while the velocity keeps the sign ``s`` (``s v >= 0``).

    Attributes
    ----------
    name : str
        A C identifier for code generation (acados uses it for file names).
    x : casadi.SX
        State ``[x~, v~, z...]``: position, velocity, the model's continuous states.
    xdot : casadi.SX
        Symbols of the state's time derivative (same size as ``x``), for the implicit form.
    u : casadi.SX
        Control: the normalised force ``u~ = u / Fc`` (1 entry).
    p : casadi.SX
        Parameters: the model's run-time numbers ``q``, then its flags (0.0 or 1.0, constant on a
        branch between events; none for Dahl ``gamma >= 1`` and LuGre).
    f_expl_expr : casadi.SX
        ``dx/dt~`` as a function of ``x``, ``u``, ``p`` (acados' ``f_expl_expr``; do-mpc's
        right-hand sides, one per state).
    f_impl_expr : casadi.SX
        ``xdot - f_expl_expr`` (acados' implicit form).
    p_values : numpy.ndarray
        The values of ``p`` for the system (flags 0: the model's virgin state).
    force : casadi.Function
        ``force(x, p) -> F~``, the friction force on the branch.
    reset : casadi.Function
        ``reset(x, p) -> x_new``: the state on the new branch ``-s`` after a reversal at ``x``
        (the model's reversal map; position and velocity unchanged).
    s : float
        The branch direction, ``+1`` or ``-1``.
    scales : Scales
        The units: multiply ``x~`` by ``scales.x`` for metres, ``u~`` by ``scales.F`` for
        newtons, ``t~`` by ``scales.t`` for seconds.
    """

    name: str
    x: ca.SX
    xdot: ca.SX
    u: ca.SX
    p: ca.SX
    f_expl_expr: ca.SX
    f_impl_expr: ca.SX
    p_values: np.ndarray
    force: ca.Function
    reset: ca.Function
    s: float
    scales: Scales

    def __repr__(self) -> str:
        return (f"BranchModel({self.name!r}, s={self.s:+.0f}, nx={self.x.numel()}, nu=1, np={self.p.numel()}, "
                f"normalised units)")

    def summary(self) -> str:
        """A few lines: the branch, the sizes, the units."""
        sc = self.scales
        return "\n".join([repr(self),
                          f"x = [x~, v~, z...]: one x~ is {sc.x:.6g} m, one v~ {sc.v:.6g} m/s",
                          f"u~ = u / Fc: one u~ is {sc.F:.6g} N; one t~ is {sc.t:.6g} s"])


def branch_model(system: Any, s: float, *, name: str = "prefriction_stage") -> BranchModel:
    """The stage on the branch of direction ``s`` as named CasADi expressions (acados, do-mpc).

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage: mass [kg] and friction model (its input ``u`` is ignored: the control replaces it).
    s : {1.0, -1.0}
        Direction of the branch (sign of the velocity on it).
    name : str, default "prefriction_stage"
        Model name, a C identifier.

    Returns
    -------
    BranchModel

    Raises
    ------
    TypeError
        If ``system`` is not an :class:`prefriction.Oscillator`.
    ValueError
        If ``s`` is not +1 or -1, or ``name`` is not a C identifier.

    Notes
    -----
    Pre-sliding friction switches its equations at every velocity reversal: the expressions
    hold while ``s v~ >= 0``. An MPC or optimal control problem that reverses the motion uses one
    phase per direction: the model of ``s`` with the path constraint ``s v~ >= 0``, the model of
    ``-s`` after it, and at the join ``v~ = 0`` and the model states mapped by :attr:`reset`
    (acados: a multi-phase OCP; do-mpc: one model per phase). ``prefriction.optimal`` solves such
    problems with the same equations (``docs/symbolic.md#acados``).

    Examples
    --------
    >>> import prefriction as pf
    >>> model = pf.symbolic.branch_model(pf.Oscillator(pf.Dahl(sigma=2e6, Fc=3.0), mass=2.5), 1.0)
    >>> model.x.numel(), model.u.numel(), model.p.numel()
    (3, 1, 1)
    """
    if not isinstance(system, Oscillator):
        raise TypeError(f"system must be a prefriction.Oscillator, got {system!r} of type {type(system).__name__}")
    if not (isinstance(name, str) and name.isidentifier() and name.isascii()):
        raise ValueError(f"name must be a C identifier (letters, digits, underscores), got {name!r}")
    b = branch_functions(system, s)
    model = system.friction
    nz, nm, nq = model.n_states, model.n_flags, b.q.size
    pos, vel, u = ca.SX.sym("x"), ca.SX.sym("v"), ca.SX.sym("u")
    z, flags, q = ca.SX.sym("z", nz), ca.SX.sym("m", nm), ca.SX.sym("q", nq)
    x = ca.vertcat(pos, vel, z)
    p = ca.vertcat(q, flags)
    F = b.force(z, flags, vel, q)
    f_expl = ca.vertcat(vel, u - F, b.rate(z, flags, vel, q))
    xdot = ca.SX.sym("xdot", x.numel())
    z_new, _ = b.reset(z, flags, q, 0.0)
    return BranchModel(
        name=name, x=x, xdot=xdot, u=u, p=p, f_expl_expr=f_expl, f_impl_expr=xdot - f_expl,
        p_values=np.concatenate([b.q, np.zeros(nm)]),
        force=ca.Function("force", [x, p], [F], ["x", "p"], ["F"]),
        reset=ca.Function("reset", [x, p], [ca.vertcat(pos, vel, z_new)], ["x", "p"], ["x_new"]),
        s=b.s, scales=b.scales,
    )
