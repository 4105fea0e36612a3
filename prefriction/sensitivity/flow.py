"""Reversal-table and loop sensitivities through CasADi forward sensitivities of each branch.

Between two reversals the branch direction ``s`` is fixed and the right-hand side is smooth.
Each branch is one CasADi ``cvodes`` integration over ``tau in [0, 1]`` of ``y' = T f(y, P, s)``
with the duration ``T`` a parameter; its Jacobians with respect to the start state, the
numbers ``P`` and ``T`` come from CasADi's forward sensitivities. The reversal is the root of
``v(T) = 0`` (Newton from the time :func:`prefriction.simulate` found), and the implicit
function theorem gives ``dT/dp = -(dv/dp) / (dv/dT)``. The model's ``reverse`` (traced on
symbols) carries the state onto the next branch with its Jacobian. ``P`` holds
``sigma``, ``Fc``, the mass, the model's run-time numbers ``q``, the PID gains and ``v0``;
the map from the named parameters to ``P`` is algebraic and differentiated by central
differences (relative step 1e-6, error about 1e-11) (``docs/sensitivities.md#flow``).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional, Sequence

import casadi as ca
import numpy as np

from prefriction.errors import SolverError
from prefriction.models import Oscillator
from prefriction.units import Scales

_PID = ("kp", "ki", "kd", "tau")


class Flow:
    """The branch flow of one oscillator (optionally in a PID loop with a constant reference).

    Units are fixed at the nominal system (``Scales``); the equations carry the actual
    numbers ``P`` as symbols.
    """

    def __init__(self, system: Oscillator, pid: Any, reference: float, rtol: float) -> None:
        model = system.friction
        self.system, self.pid, self.r, self.rtol = system, pid, reference, rtol
        self.sc = sc = Scales.of(system)
        self.nq = len(model.runtime_params_for(sc))
        self.nz = model.n_states
        self.ki = pid is not None and pid.ki > 0.0
        self.kd = pid is not None and pid.kd > 0.0
        self.nc = int(self.ki) + int(self.kd)
        ny = 2 + self.nz + self.nc
        y = ca.SX.sym("y", ny)
        P = ca.SX.sym("P", 3 + self.nq + 5)  # sigma, Fc, m, q, kp, ki, kd, tau, v0
        T, s = ca.SX.sym("T"), ca.SX.sym("s")
        self.ny, self.nP = ny, P.numel()
        f = self._rhs(y, P, s)
        dae = {"x": y, "p": ca.vertcat(P, T, s), "ode": T * f}
        opts = {"abstol": rtol * 1e-2, "reltol": rtol, "max_num_steps": 200000, "ad_weight": 0.0, "ad_weight_sp": 0.0}
        phi = ca.integrator("branch", "cvodes", dae, 0.0, 1.0, opts)
        y0, p = ca.MX.sym("y0", ny), ca.MX.sym("p", self.nP + 2)
        yf = phi(x0=y0, p=p)["xf"]
        self.step = ca.Function("step", [y0, p], [yf, ca.jacobian(yf, y0), ca.jacobian(yf, p)])
        self.end = ca.Function("end", [y0, p], [yf])  # without sensitivities: Newton iterations
        self.rhs = ca.Function("rhs", [y, P, s], [f])
        zs, q, sn = ca.SX.sym("z", self.nz), P[3:3 + self.nq], ca.SX.sym("s")
        zr, _ = model.reverse([zs[i] for i in range(self.nz)], [], sn, [q[i] for i in range(self.nq)], 1e-300)
        zr = ca.vertcat(*zr)
        self.rev = ca.Function("rev", [zs, P, sn], [zr, ca.jacobian(zr, zs), ca.jacobian(zr, P)])
        Fv = P[1] * model.force([zs[i] for i in range(self.nz)], [], 0.0, sn, [q[i] for i in range(self.nq)])
        self.force = ca.Function("force", [zs, P, sn], [Fv, ca.jacobian(Fv, zs), ca.jacobian(Fv, P)])

    def _rhs(self, y: Any, P: Any, s: Any) -> Any:
        """``dy/dt^`` in the nominal units: ``y = [x^, v^, z, controller states]``."""
        model, sc = self.system.friction, self.sc
        sigma, Fc, m = P[0], P[1], P[2]
        q = [P[3 + i] for i in range(self.nq)]
        Ta, Va = ca.sqrt(m / sigma), Fc / ca.sqrt(m * sigma)
        xh, vh = y[0], y[1]
        z = [y[2 + i] for i in range(self.nz)]
        vt = vh * sc.v / Va  # actual normalised velocity
        F = Fc * model.force(z, [], vt, s, q)
        dz = [r * sc.t / Ta for r in model.rate(z, [], vt, s, q)]
        u, dc = 0.0, []
        if self.pid is not None:
            kp, ki, kd, tau = (P[3 + self.nq + i] for i in range(4))
            e = self.r - sc.x * xh  # [m]
            u = kp * e
            k = 2 + self.nz
            if self.ki:  # integral of e, scaled by x-unit * t-unit
                u = u + ki * y[k] * sc.x * sc.t
                dc.append(e / sc.x)
                k += 1
            if self.kd:  # filtered error xf' = (e - xf) / tau, scaled by x-unit
                xf = y[k] * sc.x
                u = u + kd / tau * (e - xf)
                dc.append(sc.t * (e - xf) / tau / sc.x)
        dv = (u - F) / m * sc.t / sc.v
        return ca.vertcat(vh, dv, *dz, *dc)

    def numbers(self, system: Oscillator, pid: Any, v0: float) -> np.ndarray:
        """``P`` of a (perturbed) system."""
        model = system.friction
        q = model.runtime_params_for(Scales.of(system))
        g = [pid.kp, pid.ki, pid.kd, pid.tau or 1.0] if pid is not None else [0.0, 0.0, 0.0, 1.0]
        return np.array([model.sigma, model.Fc, system.mass, *q, *g, v0], dtype=float)


def _perturbed(system: Oscillator, pid: Any, v0: float, name: str, value: float) -> tuple:
    if name == "mass":
        return Oscillator(system.friction, value, u=system.u), pid, v0
    if name == "v0":
        return system, pid, value
    if name in _PID:
        return system, dataclasses.replace(pid, **{name: value}), v0
    return Oscillator(dataclasses.replace(system.friction, **{name: value}), system.mass, u=system.u), pid, v0


def _value(system: Oscillator, pid: Any, v0: float, name: str) -> float:
    if name == "mass":
        return system.mass
    if name == "v0":
        return v0
    if name in _PID:
        return float(getattr(pid, name))
    return float(getattr(system.friction, name))


def parameter_jacobian(flow: Flow, system: Oscillator, pid: Any, v0: float, names: Sequence[str]) -> np.ndarray:
    """``dP/dtheta`` by central differences of the algebraic map (relative step 1e-6)."""
    cols = []
    for name in names:
        val = _value(system, pid, v0, name)
        h = 1e-6 * (abs(val) if val != 0.0 else 1.0)
        hi = flow.numbers(*_perturbed(system, pid, v0, name, val + h))
        lo = flow.numbers(*_perturbed(system, pid, v0, name, val - h))
        cols.append((hi - lo) / (2.0 * h))
    J = np.array(cols).T
    J[-1] = [1.0 if n == "v0" else 0.0 for n in names]  # v0 enters only the initial state
    return J


def _newton(flow: Flow, y: np.ndarray, Pn: np.ndarray, T: float, s: float, where: str) -> float:
    """Duration ``T`` of the branch until ``v = 0`` (Newton from the simulator's guess)."""
    for it in range(12):
        yf = np.asarray(flow.end(y, np.r_[Pn, T, s])).ravel()
        acc = float(flow.rhs(yf, Pn, s)[1])
        if acc == 0.0:
            break
        dT = -yf[1] / acc
        T += dT
        if abs(dT) <= 1e-13 * T or (it >= 2 and abs(dT) <= flow.rtol * T):  # at the integration noise
            return T
    state = np.array2string(yf, precision=6)
    if abs(acc) <= 1e-6 * max(1.0, float(np.max(np.abs(Pn)))):  # v = 0 and no acceleration: the mass sticks
        raise SolverError(
            f"sensitivities: the reversal {where} is a stick (the mass comes to rest there: v and the acceleration "
            f"both vanish, state {state}), where the reversal time has no derivative; sensitivities cover runs "
            f"whose reversals are crossings of v = 0: end t_end before it"
        )
    raise SolverError(
        f"sensitivities: the reversal {where} was not located (Newton on v = 0 from the simulator's time "
        f"did not converge; state {state}); try a tighter rtol"
    )


def run_flow(system: Oscillator, v0: float, names: Sequence[str], times: np.ndarray, *, pid: Any = None,
             reference: float = 0.0, t_end: Optional[float] = None, rtol: float = 1e-10) -> dict:
    """Integrate the branches between the reversal times ``times`` (guesses, SI) with sensitivities."""
    model = system.friction
    flow = Flow(system, pid, reference, rtol)
    sc = flow.sc
    Pn = flow.numbers(system, pid, v0)
    J = parameter_jacobian(flow, system, pid, v0, names)
    if v0 != 0.0:
        s = math.copysign(1.0, v0)
    else:
        gain = pid.kp + (pid.kd / pid.tau if flow.kd else 0.0)
        s = math.copysign(1.0, gain * reference)
    z0, _ = model.initial_state(0.0, s)
    y = np.array([0.0, v0 / sc.v, *z0, *([0.0] * flow.nc)], dtype=float)
    S = np.zeros((flow.ny, len(names)))
    S[1] = J[-1] / sc.v
    nP = flow.nP
    zsl = slice(2, 2 + flow.nz)
    t_acc, dt_acc = 0.0, np.zeros(len(names))
    rows, drows, starts = [], [], [(y.copy(), S.copy(), s, t_acc, dt_acc.copy())]
    for i, t_guess in enumerate(times):
        T = _newton(flow, y, Pn, float(t_guess) / sc.t - t_acc, s, f"{i} near t = {float(t_guess):.9g} s")
        yf, Jy, Jp = (np.asarray(a) for a in flow.step(y, np.r_[Pn, T, s]))
        yf = yf.ravel()
        dT = -(Jy[1] @ S + Jp[1, :nP] @ J) / Jp[1, nP]
        S = Jy @ S + Jp[:, :nP] @ J + np.outer(Jp[:, nP], dT)
        t_acc, dt_acc = t_acc + T, dt_acc + dT
        zr, Rz, RP = (np.asarray(a) for a in flow.rev(yf[zsl], Pn, -s))
        S[zsl] = Rz @ S[zsl] + RP @ J
        S[1] = 0.0
        y = yf.copy()
        y[1] = 0.0
        y[zsl] = zr.ravel()
        s = -s
        Fv, Fz, FP = (np.asarray(a) for a in flow.force(y[zsl], Pn, s))
        rows.append((sc.t * t_acc, sc.x * y[0], float(Fv.ravel()[0])))
        drows.append((sc.t * dt_acc, sc.x * S[0], (Fz @ S[zsl] + FP @ J).ravel()))
        starts.append((y.copy(), S.copy(), s, t_acc, dt_acc.copy()))
    out = {"rows": np.array(rows).reshape(-1, 3), "d": drows, "flow": flow, "J": J, "Pn": Pn, "starts": starts}
    if t_end is not None:
        T = t_end / sc.t - t_acc
        yf, Jy, Jp = (np.asarray(a) for a in flow.step(y, np.r_[Pn, T, s]))
        out["end"] = (yf.ravel(), Jy @ S + Jp[:, :nP] @ J - np.outer(Jp[:, nP], dt_acc))
    return out


def settling(out: dict, t_guess: float, band: float) -> tuple[float, np.ndarray]:
    """Settling time: the crossing ``|x - x_f| = band |x_f|`` near ``t_guess`` [s] and its derivatives.

    ``x_f = x(t_end)`` moves with the parameters, so ``dc/dp`` has the term of ``S_xf``.
    """
    flow, J, Pn = out["flow"], out["J"], out["Pn"]
    sc, nP = flow.sc, flow.nP
    yf_end, S_end = out["end"]
    xf, Sxf = yf_end[0], S_end[0]
    k = max(i for i, st in enumerate(out["starts"]) if st[3] * sc.t <= t_guess)
    y, S, s, t0, dt0 = out["starts"][k]
    T = t_guess / sc.t - t0
    for it in range(12):
        yT = np.asarray(flow.end(y, np.r_[Pn, T, s])).ravel()
        side = math.copysign(1.0, yT[0] - xf)
        c = side * (yT[0] - xf) - band * abs(xf)
        dT = -c / (side * yT[1])
        T += dT
        if abs(dT) <= 1e-13 * T or (it >= 2 and abs(dT) <= flow.rtol * T):
            break
    else:
        raise SolverError(f"sensitivities: the settling crossing near t = {float(t_guess):.9g} s was not located; "
                          f"try a tighter rtol")
    yT, Jy, Jp = (np.asarray(a) for a in flow.step(y, np.r_[Pn, T, s]))
    yT = yT.ravel()
    side = math.copysign(1.0, yT[0] - xf)
    Sx = Jy[0] @ S + Jp[0, :nP] @ J
    dc = side * (Sx - Sxf) - band * math.copysign(1.0, xf) * Sxf
    dTs = -dc / (side * yT[1])
    return sc.t * (t0 + T), sc.t * (dt0 + dTs)
