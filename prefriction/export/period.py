"""The sampled loop's period for an exported plant: the loop's step Function with the force as its
input, and the constants (parameters, sample time, the native driver's numbers) it runs with."""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

from prefriction.models import Oscillator
from prefriction.signals import Constant
from prefriction.simulation.loops.compiled_loop import NSTOP, LoopLayout, LoopSpec, _step
from prefriction.simulation.loops.records import plant_state
from prefriction.simulation.plant import Layout, PlantSpec
from prefriction.simulation.simulate import _CAL
from prefriction.units import Scales

__all__ = ["K", "Period"]

K = 2
"""The plant's register length: the sampled loop's."""


class Period:
    """The loop's period Function for a system, with its constants (parameters, sample time)."""

    def __init__(self, system: Oscillator, Ts: float, rtol: float, force_scale: float) -> None:
        model, sc = system.friction, Scales.of(system)
        self.model, self.sc, self.Ts = model, sc, Ts
        plant = PlantSpec.of(model, Constant(0.0), None, fb="none", n_c=0, energy=False, K=K, n_out=1,
                             method="erk", compact=True)
        self.spec = spec = LoopSpec(plant, 0, 1)
        self.LL = LL = LoopLayout(spec)
        L = Layout(plant)
        self.step = _step(spec, LL)
        par = np.zeros(LL.npar)
        P0 = par[LL.p_plant]
        P0[L.param["eps"]] = eps = rtol * _CAL * math.sqrt(L.n_active / L.nx)
        P0[L.param["snap"]] = rtol
        P0[L.param["tunit"]], P0[L.param["xunit"]], P0[L.param["Fc"]] = sc.t, sc.x, sc.F
        P0[L.q] = model.runtime_params_for(sc)
        par[LL.param["D"]] = 0.0
        par[LL.param["umax"]] = 0.0     # the loop's own controller is off: the force comes in as u
        par[LL.param["Ts"]] = Ts
        par[LL.param["force_scale"]] = force_scale / sc.F
        par[LL.p_delay.start] = 1.0     # the measurement of this sample (no delay; unused: no controller)
        self.par = par
        self.q = model.runtime_params_for(sc)
        # the native driver's numbers (forced.c cfg[]): the sampled loop's (loops/runner.py)
        self.cfg = np.array([rtol * _CAL, eps, rtol, sc.t, 1.0 / sc.F, par[LL.param["force_scale"]], 0.0, 1.0, 0.0])

    def function(self) -> ca.Function:
        """``(w, u, k) -> (w_next, y)``, ``y = [x, v, F, reversals, complete]`` at ``t_{k+1}`` (SI)."""
        LL, sc = self.LL, self.sc
        S, u, k = ca.MX.sym("w", LL.nS), ca.MX.sym("u"), ca.MX.sym("k")
        Ts_n = self.Ts / sc.t
        parts: list[Any] = [0.0] * LL.nw  # no reference, noise, input slope: zero
        for key, val in (("t0", k * Ts_n), ("t1", (k + 1.0) * Ts_n), ("active", 1.0), ("da", u)):
            parts[LL.inp[key]] = val
        S1, rec = self.step(S, ca.vertcat(*parts), ca.DM(self.par))
        n_new = rec[LL.rec["n_new"]]
        y = ca.vertcat(*self.outputs(S1), n_new + rec[LL.rec["lr"]], n_new < NSTOP - 0.5)
        return ca.Function("period", [S, u, k], [S1, y], ["w", "u", "k"], ["w_next", "y"])

    def outputs(self, S: Any) -> list[Any]:
        """Position [m], velocity [m/s] and friction force [N] of the loop state ``S``."""
        ix, sc, model = self.LL.state, self.sc, self.model
        z = [S[ix[f"z{i}"]] for i in range(model.n_states)]
        m = [S[ix[f"m{i}"]] for i in range(model.n_flags)]
        v = S[ix["v"]]
        F = model.force(z, m, v, S[ix["s"]], [self.q[i] for i in range(len(self.q))])
        return [S[ix["x"]] * sc.x, v * sc.v, F * sc.F]

    def initial(self, x0: float, v0: float, F0: float) -> np.ndarray:
        """The loop state at ``t = 0`` (as the sampled loop starts it, the force at ``t = 0`` unknown:
        a mass at rest starts at rest and leaves it when the first force moves it)."""
        return plant_state(self.model, self.sc, self.LL, x0, v0, F0, 0.0)[0]
