"""An independent reference for sampled-data loops on the Dahl stage: scipy with event restarts.

:func:`zoh_reference` steps a discrete controller ``xc[k+1] = A xc[k] + B e[k]``,
``u[k] = C xc[k] + D e[k]`` by hand and integrates the plant over each hold interval with
``scipy.integrate.solve_ivp`` (DOP853), in normalised units (``docs/mathematics.md``), on one
Dahl branch at a time: ``x~' = v~``, ``v~' = u~ - F~``, ``F~' = v~ w(s F~)``, ``w(f) = (1 - f)^gamma``
(3.2) with the branch direction ``s`` fixed. A terminal event at ``s v~ = 0`` (direction -1)
stops the branch; the mass then moves on in the direction of the net force ``u~ - F~`` (a
reversal if it differs from ``s``), or rests until the next sample if the net force is below
``rest`` (relative to ``Fc``). Nothing of :mod:`prefriction.simulation` is used. It costs about
a millisecond per sample: a reference for benchmarks and tests, not a simulator.
"""

from __future__ import annotations

import math

import control
import numpy as np
from scipy.integrate import solve_ivp

from prefriction.models import Dahl, Oscillator
from prefriction.units import Scales

__all__ = ["zoh_reference"]


def zoh_reference(
    system: Oscillator, controller: control.StateSpace, r: np.ndarray, Ts: float, *, rtol: float = 1e-12,
    rest: float = 1e-13,
) -> np.ndarray:
    """Positions [m] at the sample instants ``k Ts`` of the sampled loop ``u = C(r - x)``.

    Parameters
    ----------
    system : prefriction.Oscillator
        Stage with :class:`prefriction.Dahl` friction, starting at rest at ``x = 0``, ``F = 0``.
    controller : control.StateSpace
        Discrete controller (error [m] to force [N]), zero initial state.
    r : numpy.ndarray
        Reference [m] at the sample instants; its length is the number of samples.
    Ts : float
        Sample time [s].
    rtol : float, default 1e-12
        ``solve_ivp`` tolerance (``atol`` is ``rtol`` times 1e-3 of the normalised scales).
    rest : float, default 1e-13
        Net force [Fc] below which a mass at zero velocity rests until the next sample.

    Returns
    -------
    numpy.ndarray
        Positions [m], same length as ``r``.
    """
    fr = system.friction
    if not isinstance(fr, Dahl):
        raise TypeError(f"zoh_reference needs a prefriction.Dahl friction model, got {fr!r}")
    sc, gamma = Scales.of(system), fr.gamma
    A, B, C, D = (np.asarray(M, dtype=float) for M in (controller.A, controller.B, controller.C, controller.D))
    xc = np.zeros(A.shape[0])
    y = np.zeros(3)  # x~, v~, F~
    s = 0.0  # branch direction (0: at rest)
    h = Ts / sc.t
    out = np.empty(len(r))
    for k in range(len(r)):
        out[k] = y[0] * sc.x
        e = r[k] - out[k]
        u = float(C[0] @ xc + D[0, 0] * e) / sc.F
        xc = A @ xc + B[:, 0] * e
        t = 0.0
        while t < h:
            if y[1] == 0.0:  # at zero velocity: move in the direction of the net force, or rest
                acc = u - y[2]
                if abs(acc) <= rest:
                    break
                s = math.copysign(1.0, acc)
            sol = _branch(y, u, s, gamma, t, h, rtol)
            y = sol.y[:, -1].copy()
            t = sol.t[-1]
            if sol.status == 1:  # the velocity reached zero on this branch
                y[1] = 0.0
    return out


def _branch(y: np.ndarray, u: float, s: float, gamma: float, t0: float, t1: float, rtol: float):
    """One Dahl branch in normalised units from ``t0`` until ``s v = 0`` or ``t1``."""

    def rhs(_t: float, z: np.ndarray) -> list:
        w = max(1.0 - s * z[2], 0.0) ** gamma
        return [z[1], u - z[2], z[1] * w]

    def stop(_t: float, z: np.ndarray) -> float:
        return s * z[1]

    stop.terminal, stop.direction = True, -1.0
    return solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=rtol, atol=rtol * 1e-3, events=stop)
