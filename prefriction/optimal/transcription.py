"""Multiple-shooting transcription of a multi-phase motion problem for IPOPT (CasADi ``nlpsol``).

The state is ``y = [x, v, ...]`` (position and velocity first). Each phase ``k`` has its own dynamics ``y' = f_k(y, u)`` (normalised units), a duration ``T_k``
that is a decision variable, ``N`` control intervals of equal length ``T_k / N`` with a constant
force on each, and ``M`` classical Runge-Kutta (RK4) substeps per interval. The states at the
nodes are decision variables (multiple shooting); a jump map joins the phases.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import casadi as ca
import numpy as np

__all__ = ["Phase", "Transcription"]


@dataclass(frozen=True)
class Phase:
    """One phase: dynamics ``rhs(y, u) -> y'`` (on SX), and a path function ``path(y) >= 0`` at the
    nodes (on MX)."""

    rhs: Callable[[ca.SX, ca.SX], ca.SX]
    path: Optional[Callable[[ca.MX], ca.MX]] = None


def _interval(phase: Phase, ny: int, substeps: int) -> ca.Function:
    """The RK4 map over one control interval of length ``h`` with ``substeps`` steps."""
    y, u, h = ca.SX.sym("y", ny), ca.SX.sym("u"), ca.SX.sym("h")
    yk, dt = y, h / substeps
    for _ in range(substeps):
        k1 = phase.rhs(yk, u)
        k2 = phase.rhs(yk + 0.5 * dt * k1, u)
        k3 = phase.rhs(yk + 0.5 * dt * k2, u)
        k4 = phase.rhs(yk + dt * k3, u)
        yk = yk + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return ca.Function("interval", [y, u, h], [yk])


class Transcription:
    """The NLP of a multi-phase point-to-point problem and its solution with IPOPT.

    Decision vector: the durations ``T`` (one per phase), then per phase the node states
    (``ny x (N + 1)``, column-major) and the forces (``N``).
    """

    def __init__(self, phases: Sequence[Phase], ny: int, *, intervals: int, substeps: int,
                 y0: Sequence[float], jump: Callable[[ca.MX, int], ca.MX],
                 final: Callable[[ca.MX], ca.MX], u_max: float, objective: str,
                 t_total: Optional[float], t_min: float) -> None:
        self.n_ph, self.ny, self.N = len(phases), ny, intervals
        n_ph, N = self.n_ph, intervals
        # MX: the mapped interval Function stays one node, so building the Hessian is cheap
        T = ca.MX.sym("T", n_ph)
        Y = [ca.MX.sym(f"Y{k}", ny, N + 1) for k in range(n_ph)]
        U = [ca.MX.sym(f"U{k}", 1, N) for k in range(n_ph)]
        g, lbg, ubg = [], [], []

        def eq(expr: ca.MX) -> None:
            g.append(ca.vec(expr)), lbg.extend([0.0] * expr.numel()), ubg.extend([0.0] * expr.numel())

        eq(Y[0][:, 0] - ca.DM(list(y0)))
        effort = 0.0
        for k, phase in enumerate(phases):
            step = _interval(phase, ny, substeps).map(N)
            h = T[k] / N
            eq(step(Y[k][:, :N], U[k], h) - Y[k][:, 1:])
            effort = effort + h * ca.sumsqr(U[k])
            if phase.path is not None:
                for j in range(1, N):  # the ends are fixed by the joins and the final state
                    p = phase.path(Y[k][:, j])
                    g.append(p), lbg.extend([0.0] * p.numel()), ubg.extend([np.inf] * p.numel())
            if k + 1 < n_ph:  # a reversal: zero velocity, then the model's reset
                eq(Y[k][1, N])
                eq(Y[k + 1][:, 0] - jump(Y[k][:, N], k + 1))
        eq(final(Y[-1][:, N]))
        if t_total is not None:
            eq(ca.sum1(T) - t_total)
        self.y0 = np.asarray(y0, dtype=float)
        self._steps = [_interval(phase, ny, substeps) for phase in phases]
        yj = ca.MX.sym("y", ny)
        self._jumps = [None] + [ca.Function("jump", [yj], [jump(yj, k)]) for k in range(1, n_ph)]
        self.x = ca.vertcat(T, *[ca.vec(y) for y in Y], *[ca.vec(u) for u in U])
        f = ca.sum1(T) if objective == "time" else effort
        self.nlp = {"x": self.x, "f": f, "g": ca.vertcat(*g)}
        self.lbg, self.ubg = np.array(lbg), np.array(ubg)
        nY = n_ph * ny * (N + 1)
        self.lbx = np.concatenate([np.full(n_ph, t_min), np.full(nY, -np.inf), np.full(n_ph * N, -u_max)])
        self.ubx = np.concatenate([np.full(n_ph, np.inf), np.full(nY, np.inf), np.full(n_ph * N, u_max)])

    def pack(self, T: np.ndarray, Y: Sequence[np.ndarray], U: Sequence[np.ndarray]) -> np.ndarray:
        """Decision vector of durations ``T``, node states ``Y[k]`` (``ny x (N + 1)``) and forces ``U[k]``."""
        return np.concatenate([np.asarray(T, float)] + [np.asarray(y, float).ravel(order="F") for y in Y]
                              + [np.asarray(u, float).ravel() for u in U])

    def forward(self, T: Sequence[float], U: Sequence[np.ndarray]) -> np.ndarray:
        """Decision vector of the forces ``U`` and durations ``T`` with the node states integrated
        from the initial state (a consistent first guess)."""
        Y, y = [], self.y0
        for k in range(self.n_ph):
            if k:
                y = np.array(self._jumps[k](y)).ravel()
            cols = [y]
            for j in range(self.N):
                y = np.array(self._steps[k](y, U[k][j], T[k] / self.N)).ravel()
                cols.append(y)
            Y.append(np.array(cols).T)
        return self.pack(T, Y, U)

    def unpack(self, w: np.ndarray) -> tuple[np.ndarray, list, list]:
        """Durations, node states and forces of the decision vector ``w``."""
        n_ph, ny, N = self.n_ph, self.ny, self.N
        T, i = w[:n_ph], n_ph
        Y = []
        for _ in range(n_ph):
            Y.append(w[i:i + ny * (N + 1)].reshape((ny, N + 1), order="F"))
            i += ny * (N + 1)
        U = [w[i + k * N:i + (k + 1) * N] for k in range(n_ph)]
        return T, Y, U

    def solve(self, w0: np.ndarray, *, max_iter: int, tol: float,
              lam: Optional[tuple] = None) -> tuple[np.ndarray, tuple, dict, float]:
        """IPOPT from ``w0`` (and the multipliers ``lam = (lam_x, lam_g)`` of a solution of the
        same problem at another integration, for a warm start): the solution, its multipliers,
        CasADi's stats and IPOPT's wall time [s]."""
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": max_iter, "tol": tol,
                 "bound_relax_factor": 0.0}  # |u| <= u_max exactly
        args = {"x0": w0, "lbx": self.lbx, "ubx": self.ubx, "lbg": self.lbg, "ubg": self.ubg}
        if lam is not None:  # near the solution: start there, with a small barrier parameter
            ipopt.update({"warm_start_init_point": "yes", "mu_init": 1e-9, "warm_start_bound_push": 1e-12,
                          "warm_start_mult_bound_push": 1e-12, "warm_start_slack_bound_push": 1e-12})
            args.update(lam_x0=lam[0], lam_g0=lam[1])
        solver = ca.nlpsol("point_to_point", "ipopt", self.nlp,
                           {"print_time": False, "show_eval_warnings": False, "ipopt": ipopt})
        start = time.perf_counter()
        sol = solver(**args)
        wall = time.perf_counter() - start
        lam_out = (np.array(sol["lam_x"]).ravel(), np.array(sol["lam_g"]).ravel())
        return np.array(sol["x"]).ravel(), lam_out, solver.stats(), wall
