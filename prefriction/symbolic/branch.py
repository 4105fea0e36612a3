"""CasADi Functions of a friction model on one branch: :func:`branch_functions`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import casadi as ca
import numpy as np

from prefriction.models import FrictionModel, Oscillator
from prefriction.units import Scales

__all__ = ["BranchFunctions", "branch_functions"]


@dataclass(frozen=True, repr=False)
class BranchFunctions:
    """The equations of a friction model on a branch of direction ``s`` as CasADi Functions.

    Everything is in the normalised units of :class:`prefriction.Scales` (force ``F~ = F / Fc``,
    velocity ``v~ = v sqrt(m sigma) / Fc``, time ``t~ = t sqrt(sigma / m)``); ``z`` are the
    model's continuous states, ``m`` its flags (0.0 or 1.0), ``q`` its run-time numbers
    (:meth:`prefriction.FrictionModel.runtime_params_for`). Each Function accepts numbers, ``SX``
    and ``MX`` alike, so it can be called inside a user's NLP.

    Attributes
    ----------
    s : float
        Direction of the branch, ``+1`` or ``-1`` (the sign of the velocity on it).
    rate : casadi.Function
        ``rate(z, m, v, q) -> dz/dt~``: the state rate (Dahl: ``dF~/dt~ = v~ (1 - s F~)^gamma``, (3.2)).
    force : casadi.Function
        ``force(z, m, v, q) -> F~``: the normalised friction force.
    events : casadi.Function
        ``events(z, m, v, q) -> indicators``: in-branch event indicators (positive before an
        event; an empty vector for models without events).
    reset : casadi.Function
        ``reset(z, m, q, snap) -> (z_new, m_new)``: the state just after the reversal that ends this
        branch, on the new branch of direction ``-s`` (``snap``: tolerance within which an event
        coincides with the reversal).
    on_event : tuple of casadi.Function
        ``on_event[k](z, m, q) -> (z_new, m_new)``: the state just after in-branch event ``k``.
    q : numpy.ndarray
        The run-time numbers of the model (for the system's mass if one was given, else 1 kg).
    scales : Scales or None
        The units of the system, if one was given.
    """

    s: float
    rate: ca.Function
    force: ca.Function
    events: ca.Function
    reset: ca.Function
    on_event: tuple
    q: np.ndarray
    scales: Optional[Scales]

    def summary(self) -> str:
        """One line: the direction and the sizes of the state, flags, events and numbers."""
        return (f"branch s = {self.s:+.0f}: {self.rate.numel_out(0)} states, {self.force.numel_in(1)} flags, "
                f"{self.events.numel_out(0)} events, {self.q.size} run-time numbers")

    def __repr__(self) -> str:
        return f"BranchFunctions(s={self.s:+.0f}, nz={self.rate.numel_out(0)}, nq={self.q.size})"


def branch_functions(model: Any, s: float) -> BranchFunctions:
    """CasADi Functions of the state rate, force, event indicators and resets of a model on a branch.

    Parameters
    ----------
    model : FrictionModel or Oscillator
        The friction model, or a system (then ``q`` holds the numbers for its mass, which
        rate-dependent models such as LuGre need).
    s : {1.0, -1.0}
        Direction of the branch (sign of the velocity).

    Returns
    -------
    BranchFunctions

    Raises
    ------
    TypeError
        If ``model`` is neither a :class:`prefriction.FrictionModel` nor a :class:`prefriction.Oscillator`.
    ValueError
        If ``s`` is not +1 or -1.

    Examples
    --------
    >>> import prefriction as pf
    >>> b = pf.symbolic.branch_functions(pf.Dahl(sigma=1e4, Fc=1.0), 1.0)
    >>> float(b.force([0.5], [], 1.0, b.q))        # F~ = 1 - exp(-L) at the log-gap L = 0.5
    0.3934693402873666
    """
    scales = None
    if isinstance(model, Oscillator):
        scales = Scales.of(model)
        model, q = model.friction, model.friction.runtime_params_for(scales)
    elif isinstance(model, FrictionModel):
        q = model.runtime_params()
    else:
        raise TypeError(f"model must be a prefriction.FrictionModel or Oscillator, got {model!r} of type "
                        f"{type(model).__name__}")
    if s not in (1.0, -1.0) or isinstance(s, bool):
        raise ValueError(f"s must be +1.0 or -1.0 (the branch direction), got {s!r}")
    s = float(s)
    nz, nm, nq = model.n_states, model.n_flags, len(q)
    z, m, v = ca.SX.sym("z", nz), ca.SX.sym("m", nm), ca.SX.sym("v")
    qs, snap = ca.SX.sym("q", nq), ca.SX.sym("snap")
    zl, ml = [z[i] for i in range(nz)], [m[i] for i in range(nm)]
    ins, names = [z, m, v, qs], ["z", "m", "v", "q"]
    rate = ca.Function("rate", ins, [ca.vertcat(*model.rate(zl, ml, v, s, qs))], names, ["dz"])
    force = ca.Function("force", ins, [model.force(zl, ml, v, s, qs)], names, ["F"])
    events = ca.Function("events", ins, [ca.vertcat(ca.SX(0, 1), *model.events(zl, ml, v, s, qs))], names,
                         ["indicators"])
    zr, mr = model.reverse(zl, ml, -s, qs, snap)
    reset = ca.Function("reset", [z, m, qs, snap], [_col(zr), _col(mr)], ["z", "m", "q", "snap"], ["z_new", "m_new"])
    on_event = []
    for k in range(model.n_events):
        ze, me = model.on_event(k, zl, ml, s, qs)
        on_event.append(ca.Function(f"on_event{k}", [z, m, qs], [_col(ze), _col(me)], ["z", "m", "q"], ["z_new", "m_new"]))
    return BranchFunctions(s=s, rate=rate, force=force, events=events, reset=reset, on_event=tuple(on_event),
                           q=np.asarray(q, dtype=float), scales=scales)


def _col(values: list) -> ca.SX:
    """A column of SX from a list of numbers and symbols (an empty list gives a 0 x 1 column)."""
    return ca.vertcat(ca.SX(0, 1), *[ca.SX(x) for x in values])
