"""Rests of the mass between integrator calls: leaving one, and settling into one.

:class:`Rest` is the part of :class:`prefriction.simulation.run.Run` that decides, in Python,
whether the mass at ``v = 0`` stays at rest (a vanishing net force, ``docs/simulator.md#events``);
inside a call the plant's rest events do this.
"""

from __future__ import annotations

from typing import Callable, Optional

from prefriction.simulation.plant import EPS_REST, EPS_TOUCH
from prefriction.simulation.run_state import RunState

__all__ = ["Rest", "initial_direction"]


def initial_direction(v0: float, acc0: float, F0: float) -> tuple[float, float]:
    """Direction of the first branch and whether the mass starts at rest.

    Parameters
    ----------
    v0 : float
        Initial velocity (any unit; only its sign is used).
    acc0 : float
        Initial net force over ``Fc``, ``(u(0) - F0) / Fc`` [-].
    F0 : float
        Initial friction force (only its sign is used).

    Returns
    -------
    (float, float)
        ``s0`` (+1 or -1: the sign of ``v0``, else of the net force) and ``rest`` (1.0 when both
        vanish: the mass rests and the next branch opposes ``F0``, else 0.0).
    """
    if v0 != 0.0:
        return (1.0 if v0 > 0 else -1.0), 0.0
    if abs(acc0) > 1e-14:
        return (1.0 if acc0 > 0 else -1.0), 0.0
    return (-1.0 if F0 > 0 else 1.0), 1.0


class Rest(RunState):
    """Net force on the mass and the rest transitions made between calls.

    A part of :class:`~prefriction.simulation.run.Run` on the state of
    :class:`~prefriction.simulation.run_state.RunState`; the amplitude scales ``_scales`` come
    from :class:`~prefriction.simulation.state_io.StateIO`.
    """

    _scales: Callable[[], dict]

    def _net_force(self, state: Optional[dict] = None, t: Optional[float] = None) -> float:
        """Normalised net force ``u~ - F~`` on the mass in the current state (or in ``state``,
        an unpacked output column, at the normalised time ``t``)."""
        sc, fb = self.sc, self.fb
        st = self.st if state is None else state
        t_si = (self.st["t"] if t is None else t) * sc.t
        u = float(self.system.u(t_si)) if self.system.forced else 0.0
        if self.spec.fb == "continuous":
            e = float(self.fb.reference(t_si)) - st["x"] * sc.x
            u += float(self.fb.force(st["xc"], e))
        elif fb is not None and fb.sampled:
            u += self.st["uhold"]
        return u / sc.F - st["F"]

    def _leaves_rest_at(self, state: dict, t: float, Av: float) -> bool:
        """True if the mass of the unpacked output column ``state``, at rest at the normalised
        time ``t`` (a sample time of the input or reference, where it may jump), feels a net
        force above the rest threshold ``EPS_REST Av`` (``Av`` the call's velocity scale times
        ``eps``).

        Inside a call the end of a rest is an event (``eps_rest - |a~|`` turning negative),
        but an input that jumps at an output time makes the indicator jump between two output
        intervals, where no sign change is seen: such a call must end there
        (``docs/simulator.md#events``)."""
        return state["rest"] > 0.5 and abs(self._net_force(state, t)) > EPS_REST * Av

    def _leave_rest(self) -> None:
        """End a rest at the start of a call if the net force no longer vanishes (the input or the
        held force jumped at a sample time; inside a call the rest-exit event does this)."""
        acc = self._net_force()
        if abs(acc) <= EPS_REST * self.eps * self._scales()["Av"]:
            return
        st = self.st
        new_s = 1.0 if acc > 0 else -1.0
        if new_s != st["s"]:  # leaves backwards: a reversal at this instant
            self.rev.append((st["t"], st["x"], st["F"], st["W"]))
            self.rev_events.append(st.get("ne", 0))
            st["W"], st["ne"] = 0.0, 0
            st["z"], st["m"] = self.model.reverse(st["z"], st["m"], new_s, self.q, self.snap)
            st["s"] = new_s
            if "Eb" in st:  # at rest on the new branch
                st["Eb"] = float(self.model.branch_potential(st["z"], st["m"], new_s, self.q))
        st["rest"] = 0.0

    def _rest_at_noise_level(self) -> bool:
        """Put the mass at rest (``v = 0``) if its speed and net force are at the error level of
        the run (:data:`EPS_TOUCH` and :data:`EPS_REST` times ``Av = eps A``); True if it did.

        A loop that settles at equilibrium without a clean zero of the velocity (its speed
        decays into the integration error) shows "reversal pairs" that are noise; such a mass
        rests, as at a zero velocity with a vanishing net force (``docs/simulator.md#events``).
        """
        st = self.st
        Av = self.eps * self._scales()["Av"]
        if abs(st["v"]) > EPS_TOUCH * Av or abs(self._net_force()) > EPS_REST * Av:
            return False
        st["v"], st["rest"] = 0.0, 1.0
        st["F"] = float(self.model.force(st["z"], st["m"], 0.0, st["s"], self.q))  # rate-dependent models
        return True
