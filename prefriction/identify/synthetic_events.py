"""Forced motion of a mass with friction whose branches have events: a reference independent of
the fitter.

``m x'' = u(t) - F - F_off`` (2.1), integrated by scipy's ``solve_ivp`` (DOP853) in SI units from
the models' published equations, restarted at every sample (the force held or linear over it),
every velocity reversal and every in-branch event, each located as a terminal event of
``solve_ivp``; nothing of :mod:`prefriction.models` is evaluated, only its numbers are read.

- **Dahl** (3.2), ``dF/dx = sigma (1 - s F / Fc)^gamma``, ``s = sign(v)``, ``gamma < 1``: with
  the gap ``r = 1 - s F / Fc``, ``dr/dt = -(sigma / Fc) |v| r^gamma``, so ``w = r^(1 - gamma)``
  falls linearly with the travel, ``dw/dt = -(1 - gamma) (sigma / Fc) |v|``; saturation
  ``F = s Fc`` is the event ``w = 0``, after which ``F`` stays until the reversal. Any
  ``gamma >= 1`` integrates ``F`` itself (no event).
- **Maxwell-slip** (Iwan 1966; Lampaert, Al-Bender, Swevers 2003): element ``i`` sticks,
  ``F_i' = k_i v``, until ``s F_i = W_i`` (event), then slips at ``F_i = s W_i``; every element
  sticks after a reversal; ``F = sum F_i``.
- **GMS** (Al-Bender, Lampaert, Swevers 2005): element ``i`` sticks, ``F_i' = k_i v``, until
  ``s F_i = alpha_i S(v)``, ``S(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)`` (event), then slips,
  ``F_i' = s C (1 - s F_i / (alpha_i S(v)))``, until the reversal; ``F = sum (F_i + sigma_i
  F_i' / k_i) + sigma2 v`` (``sigma_i`` the micro-damping).
- **ElastoPlastic** (Dupont, Hayward, Armstrong, Altpeter 2002, eqs. (7)-(9)): the bristle
  deflection ``z`` with ``alpha(z, v)`` from its definition; the breakaway ``s z = z_ba`` and the
  first saturation ``s z = z_ss(v)`` on a branch are the events
  (:mod:`prefriction.identify.synthetic_elasto_plastic`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from scipy.integrate import solve_ivp

from prefriction.errors import SolverError
from prefriction.identify.data import Motion
from prefriction.identify.synthetic_elasto_plastic import ElastoPlasticLaw

__all__ = ["EventRun", "closed_loop_event_record", "event_motion", "event_record"]


@dataclass(frozen=True)
class EventRun:
    """Positions [m] and velocities [m/s] at the sample times, and the times [s] of the
    reversals and of the in-branch events (saturation, an element starting to slip)."""

    x: np.ndarray
    v: np.ndarray
    reversals: np.ndarray
    events: np.ndarray


class _Laws:
    """The friction of one model: states, rates, force and event indicators per mode."""

    def __init__(self, model: Any) -> None:
        name = type(model).__name__
        self.kind = name
        if name == "Dahl":
            self.sigma, self.Fc, self.gamma = float(model.sigma), float(model.Fc), float(model.gamma)
            self.n = 1
        elif name == "MaxwellSlip":
            self.k = np.asarray(model.stiffness, dtype=float)
            self.W = np.asarray(model.slip_force, dtype=float)
            self.n = self.k.size
        elif name == "GMS":
            self.k = np.asarray(model.k, dtype=float)
            self.alpha = np.asarray(model.alpha, dtype=float)
            self.Fc, self.Fs, self.vs, self.C = float(model.Fc), float(model.Fs), float(model.vs), float(model.C)
            self.delta, self.sigma2 = float(model.delta), float(model.sigma2)
            self.damping = np.asarray(model.damping, dtype=float)
            self.n = self.k.size
        else:
            raise TypeError(f"event_motion integrates Dahl, MaxwellSlip, GMS and ElastoPlastic, got {name}")
        self.n_events = self.n
        self.stiffness = float(self.k.sum()) if hasattr(self, "k") else self.sigma
        self.state_scale = 1.0

    def watched(self, i: int, sat: np.ndarray) -> bool:
        """Whether event ``i`` can still happen on this branch."""
        return not sat[i] and (self.kind != "Dahl" or self.saturating)

    def reverse(self, z: np.ndarray, s: float, sat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The state and flags after a reversal to ``-s``: the forces kept, every element sticking."""
        return self.to_state(self.forces(z, s, sat), -s), np.zeros(self.n_events, dtype=bool)

    @property
    def saturating(self) -> bool:
        return self.kind == "Dahl" and self.gamma < 1.0

    # --- states: Dahl [F] or [w] (gamma < 1), elements [F_1..F_N] --------------------------
    def to_state(self, F: np.ndarray, s: float) -> np.ndarray:
        if self.saturating:
            r = max(1.0 - s * F[0] / self.Fc, 0.0)
            return np.array([r ** (1.0 - self.gamma)])
        return np.array(F, dtype=float)

    def forces(self, z: np.ndarray, s: float, sat: np.ndarray) -> np.ndarray:
        if self.saturating:
            if sat[0]:
                return np.array([s * self.Fc])
            return np.array([s * self.Fc * (1.0 - max(z[0], 0.0) ** (1.0 / (1.0 - self.gamma)))])
        return np.asarray(z, dtype=float)

    def stribeck(self, v: float) -> float:
        return self.Fc + (self.Fs - self.Fc) * math.exp(-abs(v / self.vs) ** self.delta)

    def rates(self, z: np.ndarray, v: float, s: float, sat: np.ndarray) -> np.ndarray:
        if self.kind == "Dahl":
            if self.saturating:
                return np.array([0.0 if sat[0] else -(1.0 - self.gamma) * self.sigma / self.Fc * abs(v)])
            return np.array([self.sigma * v * max(1.0 - s * z[0] / self.Fc, 0.0) ** self.gamma])
        stick = self.k * v
        if self.kind == "MaxwellSlip":
            return np.where(sat, 0.0, stick)
        S = self.stribeck(v)
        slip = s * self.C * (1.0 - s * z / (self.alpha * S))
        return np.where(sat, slip, stick)

    def friction(self, z: np.ndarray, v: float, s: float, sat: np.ndarray) -> float:
        F = float(np.sum(self.forces(z, s, sat)))
        if self.kind == "GMS":
            F += float(np.sum(self.damping * self.rates(z, v, s, sat) / self.k)) + self.sigma2 * v
        return F

    def indicators(self, z: np.ndarray, v: float, s: float) -> np.ndarray:
        """Positive before each event (one per element, or Dahl's saturation)."""
        if self.kind == "Dahl":
            return np.array([z[0]])
        if self.kind == "MaxwellSlip":
            return self.W - s * z
        return self.alpha * self.stribeck(v) - s * z

    def on_event(self, z: np.ndarray, i: int, s: float) -> np.ndarray:
        z = np.array(z, dtype=float)
        if self.kind == "MaxwellSlip":
            z[i] = s * self.W[i]
        elif self.saturating:
            z[0] = 0.0
        return z


def event_motion(model: Any, mass: float, t: Any, u: Any, *, offset: float = 0.0, v0: float = 0.0,
                 hold: str = "zoh", rtol: float = 1e-11,
                 controller: Callable[[int, float], float] | None = None) -> EventRun:
    """The motion of ``mass`` under ``u`` and the friction of ``model`` from its virgin state.

    Parameters
    ----------
    model : Dahl, MaxwellSlip, GMS or ElastoPlastic
        The friction (its numbers only are read).
    mass : float
        Mass [kg].
    t, u : array_like
        Sample times [s] and the applied force [N] at them.
    offset : float, default 0.0
        Force offset ``F_off`` [N].
    v0 : float, default 0.0
        Initial velocity [m/s] (the direction at rest: that of ``u[0] - offset``).
    hold : {"zoh", "linear"}
        The force over a sample: ``u[k]`` held, or linear to ``u[k + 1]``.
    rtol : float, default 1e-11
        Relative tolerance of DOP853 (absolute: ``rtol`` times the position scale).
    controller : callable, optional
        ``(k, x_k) -> u_k``: a digital loop's force [N] at sample ``k`` from the true position
        there [m] (its encoder inside), held over the next interval (``hold="zoh"``); replaces
        ``u``, which then only sets the direction at rest through ``u[0]``.

    Returns
    -------
    EventRun
    """
    law: Any = ElastoPlasticLaw(model) if type(model).__name__ == "ElastoPlastic" else _Laws(model)
    t = np.asarray(t, dtype=float)
    u = np.asarray(u, dtype=float) * np.ones(t.size)
    if controller is not None:
        if hold != "zoh":
            raise ValueError(f"a controller holds its force over each sample: hold must be 'zoh', got {hold!r}")
        u[0] = controller(0, 0.0)
    s = 1.0 if v0 > 0 else -1.0 if v0 < 0 else (1.0 if u[0] - offset >= 0 else -1.0)
    sat = np.zeros(law.n_events, dtype=bool)
    z = law.to_state(np.zeros(law.n), s)
    y = np.r_[0.0, float(v0), z]
    scale = float(np.max(np.abs(u - offset)) + 1.0) / law.stiffness
    xs, vs = [0.0], [float(v0)]
    revs: list[float] = []
    evs: list[float] = []
    for k in range(t.size - 1):
        if controller is not None and k:
            u[k] = controller(k, float(y[0]))
        t0, t1 = float(t[k]), float(t[k + 1])
        slope = 0.0 if hold == "zoh" else (u[k + 1] - u[k]) / (t1 - t0)
        force: Callable[[float], float] = lambda tt, k=k, t0=t0, slope=slope: u[k] + slope * (tt - t0)  # noqa: E731
        while True:
            y, tend, what = _piece(law, mass, offset, force, y, s, sat, t0, t1, rtol, scale)
            if what is None:
                break
            t0 = tend
            if what == "reversal":
                z, sat = law.reverse(y[2:], s, sat)
                s = -s
                y = np.r_[y[0], 0.0, z]
                revs.append(tend)
            else:
                sat[what] = True
                y = np.r_[y[:2], law.on_event(y[2:], what, s)]
                evs.append(tend)
        xs.append(float(y[0]))
        vs.append(float(y[1]))
    return EventRun(np.array(xs), np.array(vs), np.array(revs), np.array(evs))


def _piece(law: Any, mass: float, offset: float, force: Callable[[float], float], y: np.ndarray, s: float,
           sat: np.ndarray, t0: float, t1: float, rtol: float, scale: float) -> tuple[np.ndarray, float, Any]:
    """Integrate from ``t0`` towards ``t1`` until the first reversal or event: the state, the
    time reached and what happened (``None``, ``"reversal"`` or the element's index)."""
    def rhs(tt: float, yy: np.ndarray) -> np.ndarray:
        v, z = yy[1], yy[2:]
        F = law.friction(z, v, s, sat)
        return np.r_[v, (force(tt) - F - offset) / mass, law.rates(z, v, s, sat)]

    def reversal(_tt: float, yy: np.ndarray) -> float:
        return s * yy[1]
    reversal.terminal, reversal.direction = True, -1  # type: ignore[attr-defined]
    events: list[Any] = [reversal]
    for i in range(law.n_events):
        if not law.watched(i, sat):
            continue

        def slip(_tt: float, yy: np.ndarray, i: int = i) -> float:
            return float(law.indicators(yy[2:], yy[1], s)[i])
        slip.terminal, slip.direction = True, -1  # type: ignore[attr-defined]
        slip.index = i  # type: ignore[attr-defined]
        events.append(slip)
    atol = np.r_[rtol * scale, rtol * scale / max(t1 - t0, 1e-300), np.full(y.size - 2, rtol * 1e-3 * law.state_scale)]
    sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=rtol, atol=atol, events=events)
    if sol.status == 1 and sol.t_events[0].size and sol.t_events[0][0] <= t0 + 1e-12 * (t1 - t0):
        reversal.terminal = False  # type: ignore[attr-defined]  # at rest under no net force: no reversal
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=rtol, atol=atol, events=events)
    if not sol.success:
        raise SolverError(f"DOP853 failed between t = {t0!r} s and {t1!r} s ({sol.message})")
    for ev, te in zip(events, sol.t_events):
        if te.size and sol.status == 1 and te[0] == sol.t[-1] and getattr(ev, "terminal", False):
            return sol.y[:, -1], float(te[0]), "reversal" if ev is reversal else ev.index  # type: ignore[attr-defined]
    return sol.y[:, -1], t1, None


def event_record(model: Any, mass: float, t: Any, u: Any, *, offset: float = 0.0, noise: float = 0.0,
                 rng: np.random.Generator | None = None, hold: str = "zoh", known_mass: bool = True) -> Motion:
    """:class:`Motion` data of :func:`event_motion` with Gaussian position noise [m]."""
    run = event_motion(model, mass, t, u, offset=offset, hold=hold)
    x = run.x if noise == 0.0 else run.x + noise * (rng or np.random.default_rng(0)).standard_normal(run.x.size)
    return Motion(np.asarray(t, dtype=float), x, np.asarray(u, dtype=float) * np.ones(len(x)),
                  mass if known_mass else None, hold)


def closed_loop_event_record(model: Any, mass: float, dt: float, r: Any, *, Kp: float, Ki: float = 0.0,
                             Kd: float = 0.0, offset: float = 0.0, quantum: float = 0.0, noise: float = 0.0,
                             rng: np.random.Generator | None = None, rtol: float = 1e-11) -> Motion:
    """A record of the stage of :func:`event_motion` under a digital PID on the encoder.

    At each sample ``k`` the encoder reads ``x_m = quantum round((x_k + n_k) / quantum)``
    (``n_k`` Gaussian of deviation ``noise``; no rounding for ``quantum = 0``) and the loop applies
    ``u_k = Kp (r_k - x_m,k) + Ki dt sum_{j<=k} (r_j - x_m,j) - Kd (x_m,k - x_m,k-1) / dt`` [N]
    over the next interval (``x_m,-1 = x_m,0``); the stage starts at rest at 0 on a virgin branch.

    Parameters
    ----------
    model : Dahl, MaxwellSlip, GMS or ElastoPlastic
        The friction.
    mass : float
        Mass [kg].
    dt : float
        Sample interval [s].
    r : array_like
        Reference positions [m], one per sample.
    Kp, Ki, Kd : float
        Gains [N/m], [N/(m s)], [N s/m].
    offset : float, default 0.0
        Force offset ``F_off`` [N].
    quantum, noise : float, default 0.0
        Encoder step [m] and noise deviation [m].
    rng : numpy.random.Generator, optional
        Source of the noise.
    rtol : float, default 1e-11
        Relative tolerance of DOP853.

    Returns
    -------
    Motion
        Encoder positions, the loop's force, the mass (known).
    """
    r = np.asarray(r, dtype=float)
    n = r.size
    e = noise * (rng or np.random.default_rng(0)).standard_normal(n)
    xm, u = np.empty(n), np.empty(n)
    total = [0.0]

    def controller(k: int, x: float) -> float:
        xm[k] = x + e[k] if quantum == 0.0 else quantum * np.round((x + e[k]) / quantum)
        total[0] += r[k] - xm[k]
        u[k] = Kp * (r[k] - xm[k]) + Ki * dt * total[0] - Kd * (xm[k] - xm[max(k - 1, 0)]) / dt
        return float(u[k])

    t = np.arange(n) * dt
    run = event_motion(model, mass, t, np.zeros(n), offset=offset, rtol=rtol, controller=controller)
    controller(n - 1, float(run.x[-1]))
    return Motion(t, xm, u, mass, "zoh")
