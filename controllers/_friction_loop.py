"""The friction force-displacement curve ``F(x)`` of a closed-loop run, through every reversal.

Rate-independent models with closed-form branches give the exact curve between the reversals,
however coarse the output samples: Dahl (the branch (3.4)/(3.5) through the previous reversal,
a function of ``x`` alone) and Maxwell-slip (each element a stop operator: it follows
``k_i dx`` until its slip force ``+-W_i``, Iwan 1966). For every other model (LuGre, GMS, a
model of the protocol without such branches) the force depends on the velocity history too:
the curve is the output samples with the reversals inserted in time order.
"""

from __future__ import annotations

import numpy as np

from prefriction.analysis.branch import force_after_distance
from prefriction.models import Dahl, MaxwellSlip, Oscillator
from prefriction.reversals import ReversalTable

__all__ = ["friction_curve"]


def friction_curve(system: Oscillator, t: np.ndarray, x: np.ndarray, F: np.ndarray, reversals: ReversalTable,
                   points_per_branch: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions [m] and friction forces [N] from the first output sample through every reversal
    to the last output sample.

    Parameters
    ----------
    system : prefriction.Oscillator
        The simulated stage.
    t, x, F : numpy.ndarray
        Output samples: times [s], positions [m], friction forces [N].
    reversals : prefriction.ReversalTable
        The run's reversals (times, positions and forces used).
    points_per_branch : int
        Points on each branch between two reversals (closed-form branches only), ``>= 2``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``x`` [m] and ``F`` [N] along the curve.
    """
    model = system.friction
    xs = np.concatenate(([x[0]], reversals.x, [x[-1]]))
    frac = np.linspace(0.0, 1.0, points_per_branch)[1:]
    if isinstance(model, Dahl):
        Fs = np.concatenate(([F[0]], reversals.F, [F[-1]]))
        return _dahl(model, xs, Fs, frac)
    if isinstance(model, MaxwellSlip):
        return _maxwell_slip(model, xs, float(F[0]), frac)
    order = np.argsort(np.concatenate((t, reversals.t)), kind="stable")
    return np.concatenate((x, reversals.x))[order], np.concatenate((F, reversals.F))[order]


def _dahl(model: Dahl, xs: np.ndarray, Fs: np.ndarray, frac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dahl branches (3.4)/(3.5) from each point ``(xs[i], Fs[i])`` to ``xs[i + 1]``."""
    cx, cF = [xs[:1]], [Fs[:1]]
    for i in range(len(xs) - 1):
        dx = xs[i + 1] - xs[i]
        if dx == 0.0:
            continue
        s = 1.0 if dx > 0 else -1.0
        xi = abs(dx) * frac * model.sigma / model.Fc
        f = force_after_distance(np.full(xi.shape, s * Fs[i] / model.Fc), xi, model.gamma)
        cx.append(xs[i] + dx * frac)
        cF.append(s * model.Fc * f)
    return np.concatenate(cx), np.concatenate(cF)


def _maxwell_slip(model: MaxwellSlip, xs: np.ndarray, F0: float, frac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stop operators ``F_i = clip(F_i(a) + k_i (x - x_a), -W_i, W_i)`` on each monotone segment
    from ``xs[a]`` to ``xs[a + 1]``, the elements starting on the virgin curve at the force ``F0``."""
    k, W = np.asarray(model.stiffness, dtype=float), np.asarray(model.slip_force, dtype=float)
    s0 = 1.0 if len(xs) < 2 or xs[1] >= xs[0] else -1.0
    z, _ = model.initial_state(F0 / model.Fc, s0)
    elements = np.asarray(z[: model.n_elements], dtype=float) * model.Fc
    cx, cF = [xs[:1]], [np.array([elements.sum()])]
    for a in range(len(xs) - 1):
        dx = xs[a + 1] - xs[a]
        if dx == 0.0:
            continue
        along = np.clip(elements + k * (dx * frac)[:, None], -W, W)  # (points, elements)
        cx.append(xs[a] + dx * frac)
        cF.append(along.sum(axis=1))
        elements = along[-1]
    return np.concatenate(cx), np.concatenate(cF)
