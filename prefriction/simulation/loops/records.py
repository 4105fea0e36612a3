"""Records of the compiled sampled loop: its initial state, the reversals in its records, the
periods finished by the Python loop of :func:`prefriction.simulate`, and its failures."""

from __future__ import annotations

import math
import numpy as np

from prefriction.errors import SolverError
from prefriction.models import FrictionModel, Oscillator
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.plant import PlantSpec
from prefriction.simulation.rest import initial_direction
from prefriction.simulation.build import build_plant
from prefriction.simulation.run import Run
from prefriction.units import Scales

from .compiled_loop import LoopLayout

__all__ = ["collect", "failure", "finish_in_python", "initial_state", "plant_state"]


def plant_state(model: FrictionModel, sc: Scales, LL: LoopLayout, x0: float, v0: float, F0: float,
                acc0: float) -> tuple[np.ndarray, float]:
    """Loop state at ``t = 0`` with the plant's entries set (position ``x0`` [m], velocity ``v0``
    [m/s], friction force ``F0`` [N], normalised acceleration ``acc0`` deciding the first direction
    at rest) and every other entry zero; and the initial direction."""
    s0, rest = initial_direction(v0, acc0, F0)
    z, m = model.initial_state(F0 / sc.F, s0)
    S = np.zeros(LL.nS)
    ix = LL.state
    S[ix["x"]], S[ix["v"]], S[ix["s"]], S[ix["rest"]] = x0 / sc.x, v0 / sc.v, s0, rest
    for i, zi in enumerate(z):
        S[ix[f"z{i}"]] = zi
    for i, mi in enumerate(m):
        S[ix[f"m{i}"]] = mi
    return S, s0


def initial_state(system: Oscillator, LL: LoopLayout, x0: float, v0: float, F0: float, xc0: np.ndarray,
                   u0: float, comp0: np.ndarray, y0: float) -> tuple[np.ndarray, float]:
    """Loop state at ``t = 0`` and the initial direction (as ``prefriction.simulate`` starts a
    loop), with the force ``u0`` [N] applied at ``t = 0``, the compensator's state ``comp0`` and
    the measurements before ``t = 0`` all ``y0`` [m]."""
    S, s0 = plant_state(system.friction, Scales.of(system), LL, x0, v0, F0, (u0 - F0) / system.friction.Fc)
    ix = LL.state
    S[ix["xc0"]: ix["xc0"] + len(xc0)] = xc0
    for i, ci in enumerate(comp0):
        S[ix[f"c{i}"]] = ci
    for key, i in ix.items():
        if key[0] == "y" and key[1:].isdigit():
            S[i] = y0
    return S, s0


def collect(rev: list, R: np.ndarray, LL: LoopLayout, K: int, *, skip_last: bool) -> None:
    """Append the reversals recorded in the periods ``R`` (a reversal when leaving rest at ``t_k``,
    then the plant's register, oldest first); the register of the last period only if not ``skip_last``."""
    r = LL.rec
    rows = np.nonzero((R[:, r["lr"]] > 0.5) | (R[:, r["n_new"]] > 0.5))[0]
    for j in rows:
        row = R[j]
        if row[r["lr"]] > 0.5:
            rev.append((row[r["lr_t"]], row[r["lr_x"]], row[r["lr_F"]], row[r["lr_W"]]))
        if skip_last and j == len(R) - 1:
            continue
        for i in range(min(int(row[r["n_new"]] + 0.5), K) - 1, -1, -1):
            b = LL.reg + 4 * i
            rev.append(tuple(row[b: b + 4]))


def finish_in_python(system: Oscillator, fb: LinearFeedback, plant: PlantSpec, eps: float, rtol: float, jit: bool,
                      S: np.ndarray, after: np.ndarray, LL: LoopLayout, tk: np.ndarray, j: int, u: float,
                      par: np.ndarray, rev: list, lr_recorded: bool) -> np.ndarray:
    """Redo the plant over period ``j`` from the state ``S`` at its start with :class:`Run` (any
    number of reversals), the force ``u`` [N] held; append its reversals (except one at ``t_k``,
    already recorded); return the state after it: the plant's from the Python loop, the
    controller's, the compensator's and the measurements' from ``after`` (the compiled step's)."""
    ix = LL.state
    run = Run(system, plant, fb, eps, build_plant(system.friction, plant, fb, jit))
    run.snap = rtol
    run.P0 = run._constant_params(run.L)
    run.force_scale = par[LL.param["force_scale"]]
    run.A_max = S[ix["Amax"]]
    z = [S[ix[f"z{i}"]] for i in range(LL.plant.nz)]
    m = [S[ix[f"m{i}"]] for i in range(LL.plant.nm)]
    s = S[ix["s"]]
    F = float(system.friction.force(z, m, S[ix["v"]], s, run.q))
    run.st = {"x": S[ix["x"]], "v": S[ix["v"]], "F": F, "z": z, "m": m, "t": tk[j], "s": s, "rest": S[ix["rest"]],
              "W": S[ix["W"]], "Ef": 0.0, "xc": np.zeros(0), "uhold": u}
    run.advance(tk[j + 1], math.inf)
    out = after.copy()
    st = run.st
    # a reversal at t_k when leaving rest is in the block's record already
    rev.extend(run.rev[1:] if lr_recorded else run.rev)
    for key in ("x", "v", "s", "rest", "W"):
        out[ix[key]] = st[key]
    for i, zi in enumerate(st["z"]):
        out[ix[f"z{i}"]] = zi
    for i, mi in enumerate(st["m"]):
        out[ix[f"m{i}"]] = mi
    out[ix["Amax"]] = run.A_max
    return out


def failure(S: np.ndarray, LL: LoopLayout, sc: Scales, ta: float, tb: float, why: str) -> SolverError:
    """The SolverError of a failed block: its time span, the state at its start, what to try."""
    ix = LL.state
    return SolverError(
        f"the sampled loop failed in the block of periods from t = {ta * sc.t:.9g} s to {tb * sc.t:.9g} s "
        f"(state at its start: x = {S[ix['x']] * sc.x:.6g} m, v = {S[ix['v']] * sc.v:.6g} m/s, direction "
        f"{int(S[ix['s']]):+d}): {why}. Try a looser rtol, a shorter sample time Ts, or a stable controller."
    )
