"""Optional closed forms of a friction model's branch, mixed into :class:`prefriction.FrictionModel`.

A branch is the motion between two velocity reversals (direction ``s`` fixed). A model may give
its exact state over one interval at a constant velocity (:meth:`BranchHooks.advance`), its
unforced motion along the branch in closed form (:meth:`BranchHooks.free_branch`), the
potential of its force up to the next event (:meth:`BranchHooks.branch_potential`), the
displacement between two states (:meth:`BranchHooks.travel`) and the energy stored on the branch
(:meth:`BranchHooks.branch_energy`, :meth:`BranchHooks.branch_energy_of_force`; ``E_p`` of
(3.9)). The defaults here say "no closed form" (the simulator integrates) or compute the stored
energy of a one-state model by quadrature (:mod:`prefriction.models.defaults`). Everything is
in the normalised units of :mod:`prefriction.units`.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from prefriction.models.defaults import branch_energy_by_quadrature

__all__ = ["BranchHooks"]


class BranchHooks:
    """The optional branch closed forms of a friction model (module notes); a model overrides
    those it has. Used through :class:`prefriction.FrictionModel`, which supplies ``force`` and
    ``n_states``."""

    def advance(self, z: Sequence[Any], m: Sequence[Any], v: Any, dt: Any, s: Any,
                q: Any) -> Optional[tuple[list[Any], list[Any]]]:
        """Exact state after ``dt`` time units at the constant velocity ``v`` on a branch of
        direction ``s`` (floats and CasADi ``SX`` alike), in-branch events included.

        The optional hook of :func:`prefriction.friction_along` and the force-displacement fit
        (:func:`prefriction.identify.stepping.interval_function`): a closed form over one
        sample interval of a prescribed piecewise-linear motion. Every event that falls inside
        the interval is applied where it occurs (``docs/along.md#exact-steps``). ``None`` (the
        default): the interval is integrated with Runge-Kutta sub-steps instead.
        """
        return None

    @property
    def has_free_branch(self) -> bool:
        """True if :meth:`free_branch` may give closed-form branches for this instance (default:
        if the class overrides it); the unforced simulation then keeps the compact CasADi loop,
        which takes them, instead of the native driver (``docs/simulator.md#native``)."""
        return type(self).free_branch is not BranchHooks.free_branch

    def free_branch(self, z: Sequence[float], m: Sequence[float], v: float, s: float, q: Any,
                    horizon: float) -> Optional[tuple[float, float, list[float], list[float], float, int]]:
        """Closed-form unforced motion on the current branch, if the model has one (floats).

        The normalised oscillator ``x~'' = -F~`` (unit mass, no input) from the state
        ``(z, m)``, velocity ``v`` and direction ``s``, followed for at most ``horizon`` time
        units and no further than the next reversal. The unforced simulation (compact model)
        takes this instead of integrating: a motion without truncation error, e.g. a linear
        branch, whose integration error would otherwise accumulate over the cycles, or one
        across a singular point that a Runge-Kutta step would cross at a reduced order.

        Returns
        -------
        tuple or None
            ``(dt, v1, z1, m1, dx, events)``: the time taken (``dt < horizon``: a reversal at
            ``dt``, ``v1 = 0``, the state before :meth:`reverse`), the velocity, the state and
            the displacement at its end, and the number of model events on the way (counted as
            the simulator counts them: the flags they change). ``None`` (the default) if there
            is no closed form for this state: the simulator integrates.
        """
        return None

    def branch_potential(self, z: Sequence[Any], m: Sequence[Any], s: Any, q: Any) -> Any:
        """Potential of the friction force along the current branch up to its next model event
        (floats and CasADi symbols alike), for models whose branch is elastic until then.

        On such a stretch the force depends on the position along the branch alone, so
        ``v~^2 / 2 + branch_potential - W~`` (``W~`` the input's work) is conserved, and the
        simulator sets the speed at each model event from it: the event is located on the
        integrator's dense output, which is of low order next to a singular point such as
        Dahl's saturation for gamma < 1. ``None`` (the default): no such correction.
        """
        return None

    def travel(self, z0: Sequence[float], z1: Sequence[float], s: float, q: Any) -> float:
        """Normalised displacement between states ``z0`` and ``z1`` of one branch (if
        :attr:`tracks_position`)."""
        raise NotImplementedError(f"{type(self).__name__} does not track the position")

    # --- energy (rate-independent models) -------------------------------------------------
    def branch_energy(self, z: Sequence[float], m: Sequence[float], s: float, q: Any) -> float:
        """Normalised energy stored on the current branch (direction ``s``) in state ``(z, m)``.

        The area between the branch and the displacement axis from the state back to the
        branch's force zero crossing: the potential energy ``E_p`` (3.9) when taken just after
        a reversal. The default uses :meth:`branch_energy_of_force` with the state's force.
        """
        return float(self.branch_energy_of_force(np.array([float(self.force(z, m, 0.0, s, q))]), s)[0])

    def branch_energy_of_force(self, F: np.ndarray, s: Any) -> np.ndarray:
        """Normalised stored energy on a branch of direction ``s`` at forces ``F~`` (numpy),
        for models whose branch energy depends on the force alone (Dahl); the sample-based
        energy analysis needs it. Default for a one-state model: ``-int F dx`` from the state of
        force ``F~`` to the force's zero crossing, by quadrature (:mod:`prefriction.models.defaults`);
        other models raise ``NotImplementedError``."""
        if self.n_states != 1:
            raise NotImplementedError(
                f"{type(self).__name__} gives no branch energy as a function of the force alone "
                f"(define branch_energy_of_force(F, s); the quadrature default serves one-state models)"
            )
        return branch_energy_by_quadrature(self, F, s)
