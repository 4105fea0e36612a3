"""The plant of one run, built: its layout and the driver that integrates it.

The compact unforced model runs on the native driver where it exists
(:mod:`prefriction.simulation.native.library`, ``docs/simulator.md#native``), forced and dense
open-loop runs on the forced native driver (:mod:`prefriction.simulation.native.forced`), a
continuous controller on the same driver (:mod:`prefriction.simulation.native.closed`), a sampled
controller on the native sampled loop under any input force
(:mod:`prefriction.simulation.loops.feedback_loop`), and everything else (``method="erk"``,
``jit=False``, no C compiler) on CasADi's integrator
(:mod:`prefriction.simulation.integrator`). Each is built once per model structure and process
and reused (numbers and tolerances are run-time inputs).
"""

from __future__ import annotations

from typing import Optional

from prefriction.models.base import FrictionModel
from prefriction.models.sizes import check_sizes
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.integrator import integrator
from prefriction.simulation.loops.feedback_loop import feedback_loop_driver
from prefriction.simulation.native.closed import closed_driver
from prefriction.simulation.native.forced import forced_driver
from prefriction.simulation.native.library import native_driver
from prefriction.simulation.plant import Layout, PlantSpec
from prefriction.simulation.run_state import BuiltPlant

__all__ = ["build_plant"]


def build_plant(model: FrictionModel, spec: PlantSpec, fb: Optional[LinearFeedback], jit: bool,
                native: bool = True, held_input: bool = False) -> BuiltPlant:
    """Build (or reuse) the plant of ``spec`` for the friction ``model``, on the native drivers
    where they apply (``native`` and ``jit``, no controller ``fb`` for the forced one), else on
    CasADi's integrator (compiled if ``jit``); ``held_input``: a sampled controller ``fb`` runs on the
    native sampled loop (its held force added to the oscillator's input, any kind). The model's sizes are checked first, once per structure (:func:`~prefriction.models.sizes.check_sizes`), for
    every driver alike."""
    check_sizes(model)
    L = Layout(spec)  # the same for any number of outputs per call
    drv, setup = native_driver(model) if spec.stops_at_reversal and jit and native else (None, 0.0)
    drv_forced = None
    if native and jit and fb is None and not spec.stops_at_reversal:
        drv_forced, setup = forced_driver(model, spec.u_sig)
    elif native and jit and spec.fb == "continuous":  # the controller in C (native/closed.py)
        drv_forced, setup = closed_driver(model, spec)
    if native and jit and fb is not None and fb.sampled and held_input:
        drv_loop, setup = feedback_loop_driver(spec, fb.n_states)
        if drv_loop is not None:
            return BuiltPlant(L, None, None, None, setup, drv_loop.info.mode if setup else "cached", drv_loop)
    if drv_forced is not None:
        return BuiltPlant(L, None, drv, drv_forced, setup, drv_forced.info.mode if setup else "cached")
    if drv is not None:
        return BuiltPlant(L, None, drv, None, setup, drv.info.mode if setup else "cached")
    f1, setup, mode = integrator(spec, jit)
    return BuiltPlant(L, f1, None, None, setup, mode)
