"""The harness's closed-loop record with the stage's true state kept (shared by the tests of
rests and hovers): the loop of ``prefriction.identify._success.stage_record`` re-run here, one
scipy LSODA integration per sample, restarted at reversals."""

from __future__ import annotations

import numpy as np

from prefriction.identify._success import _moves
from prefriction.identify.data import Motion
from prefriction.identify.synthetic_loop import _interval, _rhs


def true_run(stage, n: int, seed, rtol: float = 1e-10) -> tuple[Motion, np.ndarray]:
    """The record of ``stage_record`` (closed loop) and the true state of the stage at each sample
    (rows: position [m], velocity [m/s], the friction state: LuGre's bristle deflection [m] or
    Dahl's force [N]), from the same scipy integration (LSODA per sample at ``rtol``, restarted at
    reversals)."""
    loop = stage.loop
    rng = np.random.default_rng(seed)
    noise = loop.noise * rng.standard_normal(n)
    r = _moves(n, rng, stage.stroke, n)
    rhs = _rhs(loop)
    x, u, state = np.empty(n), np.empty(n), np.empty((3, n))
    y = np.array([r[0], 0.0, 0.0])
    prev = np.round(r[0] / loop.quantum) * loop.quantum
    for k in range(n):
        state[:, k] = y
        x[k] = np.round((y[0] + noise[k]) / loop.quantum) * loop.quantum
        u[k] = loop.Kp * (r[k] - x[k]) - loop.Kd * (x[k] - prev) / loop.dt
        prev = x[k]
        if k < n - 1:
            y = _interval(rhs, y, k * loop.dt, (k + 1) * loop.dt, u[k], rtol)
    return Motion(np.arange(n) * loop.dt, x, u, None, hold="zoh"), state
