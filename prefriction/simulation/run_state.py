"""The state of one :func:`prefriction.simulate` run and its bookkeeping (normalised units inside).

:class:`RunState` holds what every driver of a run reads and writes: the plant it was built
with, the current state ``st``, the reversals found (``rev`` and their half-cycles' model
events ``rev_events``) and the call statistics. The drivers (the CasADi loop of
:class:`~prefriction.simulation.run.Run`, the native drivers in
:mod:`prefriction.simulation.native`, the dense-output loop) take a state from a call with
:meth:`RunState._accept`, record reversals with :meth:`RunState._record`, read a sample with
:meth:`RunState.sample` and report a failure with :meth:`RunState._failure`; they depend on this
module, not on one another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from prefriction.errors import SolverError
from prefriction.models import Oscillator
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.integrator import BufferedIntegrator
from prefriction.simulation.plant import Layout, PlantSpec
from prefriction.simulation.reversal_log import ReversalLog
from prefriction.units import Scales

__all__ = ["BuiltPlant", "DIED_OUT", "RunState"]

DIED_OUT = 1e-20  # normalised speed below which an unforced motion has died out (no reversal comes)


@dataclass(frozen=True)
class BuiltPlant:
    """The plant of a run (:func:`prefriction.simulation.build.build_plant`): its layout ``L``
    and exactly one driver (``f1``: CasADi's integrator; ``native``: the unforced native driver;
    ``native_forced``: the forced one; ``native_loop``: the sampled loop of a sampled controller;
    the others None), the setup time [s] (0 if reused) and the JIT mode (``"interpreted"``,
    ``"cached"``, ...)."""

    L: Layout
    f1: Optional[BufferedIntegrator]
    native: Any
    native_forced: Any
    setup_time: float
    mode: str
    native_loop: Any = None


class RunState:
    """The state of a run: the system, its plant and scales, the current state and the reversals.

    Parameters
    ----------
    system : Oscillator
        The simulated oscillator (SI).
    spec : PlantSpec
        The structure of the plant.
    fb : LinearFeedback or None
        The closed loop, if any.
    eps : float
        Run-time tolerance (states are scaled by amplitude times ``eps``).
    plant : BuiltPlant
        The built plant: its layout and the one driver that integrates it.
    sc : Scales, optional
        Normalised units of ``system`` (computed if not given).

    Notes
    -----
    ``st`` holds the normalised ``t, x, v, F, z, m, s, rest, W, Ef, xc`` (and ``ne``, ``Eb``,
    ``uhold`` where used); :func:`prefriction.simulate` sets it and the run constants
    (``snap``, ``force_scale``, ``breaks``, ``P0``, ``eps_native``) before the run.
    """

    def __init__(self, system: Oscillator, spec: PlantSpec, fb: Optional[LinearFeedback],
                 eps: float, plant: BuiltPlant, sc: Optional[Scales] = None) -> None:
        self.system, self.spec, self.fb = system, spec, fb
        self.sc = Scales.of(system) if sc is None else sc  # (simulate has them already)
        self.model = system.friction
        self.q = self.model.runtime_params_for(self.sc)  # may depend on the mass (units)
        self.eps = eps  # run-time tolerance: states are scaled by amplitude * eps
        self.eps_native = eps  # the same for the native drivers' norm over the active states (simulate sets it)
        # a sampled controller on a plant without a hold control: its force joins the input piece
        self.hold_in_piece = fb is not None and fb.sampled and spec.fb == "none"
        self.L, self.f1, self.native, self.native_forced = plant.L, plant.f1, plant.native, plant.native_forced
        self.native_loop = plant.native_loop
        self.setup_time, self.mode = plant.setup_time, plant.mode
        self.calls = 0
        self.steps: Optional[int] = 0
        self.max_chunk = math.inf  # longest next call of advance (finite after a failed call)
        self.rev = ReversalLog()  # (t~, x~, F~, W~) per reversal
        self.rev_events: list[int] = []  # model events of the half-cycle ending at each reversal
        self.st: dict = {}  # current state, normalised (set by simulate)
        self.snap = 0.0  # reversal-event coincidence tolerance (e.g. Dahl saturation)
        self.force_scale = 0.0  # size of the applied force / Fc
        self.A_max = 0.0  # largest amplitude seen (forced)
        self.breaks = np.zeros(0)  # sample times of sampled signals (normalised)
        self.S = np.ones(spec.n_c)  # controller state scales (times eps)
        self.P0 = np.zeros(self.L.np)  # parameters fixed during the run
        self.note = ""  # a change of method during the run, for the result's message

    def _failure(self, why: str) -> SolverError:
        """The SolverError of a failed call: time, state, reversals so far and what to try."""
        sc, st = self.sc, self.st
        if not self.spec.forced and abs(st["v"]) < DIED_OUT and abs(st["F"]) < DIED_OUT ** 0.5:
            n = len(self.rev)
            return SolverError(
                f"simulate stopped at t = {st['t'] * sc.t:.9g} s: the motion has died out after {n} "
                f"reversal{'' if n == 1 else 's'} (v = {st['v'] * sc.v:.3g} m/s, F = {st['F'] * sc.F:.3g} N, "
                f"x = {st['x'] * sc.x:.6g} m), so it will not reverse again and the requested reversals cannot "
                f"come ({why}). Give t_end to simulate up to a time instead, or ask for at most {n} "
                f"reversal{'' if n == 1 else 's'}."
            )
        return SolverError(
            f"simulate failed after t = {st['t'] * sc.t:.9g} s (state there: x = {st['x'] * sc.x:.6g} m, "
            f"v = {st['v'] * sc.v:.6g} m/s, F = {st['F'] * sc.F:.6g} N, direction {int(st['s']):+d}, "
            f"{len(self.rev)} reversals so far): {why}. Try a looser rtol, a shorter t_end or fewer "
            f"reversals" + (", or a smoother input force (samples closer together)." if self.spec.forced else ".")
        )

    def _record(self, out: dict) -> None:
        """Append the reversals of the unpacked state ``out`` and their half-cycles' event counts."""
        self.rev.extend(out["new"])
        self.rev_events.extend(out["new_events"])

    def _accept(self, out: dict, t: float) -> None:
        """Take the unpacked state ``out``, at normalised time ``t`` unless the call stopped early."""
        self._record(out)
        for k in ("x", "v", "F", "z", "m", "s", "rest", "W", "Ef", "xc", "ne"):
            self.st[k] = out[k]
        if "Eb" in out:
            self.st["Eb"] = out["Eb"]
        self.st["t"] = t if out["t"] is None else out["t"]

    def sample(self) -> tuple[Any, ...]:
        """Current state as a sample (t~, x~, v~, F~, E_f~, xc)."""
        st = self.st
        return (st["t"], st["x"], st["v"], st["F"], st["Ef"], np.array(st["xc"], dtype=float))
