"""Fit a friction model to the motion of a mass (:class:`Motion`) by multiple shooting: one layout.

The record is cut into segments of ``K`` samples (:data:`SEGMENT`). Each segment starts at a
node with a free position, velocity and model state and is simulated sample by sample
(:mod:`prefriction.identify.motion_step`: ``m x'' + F + F_off = u`` (2.1), the applied force held
or linear over each sample as the data say, reversals located inside the sub-steps); the end
of a segment must meet the next node. The objective is the sum of squared position residuals,
minimised subject to the continuity of the segments by scipy's trust-region least squares in an
augmented Lagrangian on sparse matrices (:mod:`prefriction.identify.constrained_lsq`), with
forward sensitivities propagated sample by sample (:func:`_solve_record`). Which layouts a record
runs (the chain whole, cut after the long hovers, the moves alone) is
:mod:`prefriction.identify.layouts`; the continuation over a long record's first window and
over held parameters is :mod:`prefriction.identify.continuation`. Nothing holds more than a few
numbers per sample and sensitivity column, so the time and the memory of a fit grow linearly
with the samples (measured: ``docs/identify_motion.md``).

The statistics need the residual Jacobian on the constraint manifold: chaining the segment
sensitivities node to node gives it with respect to the parameters and the first node alone
(the single-shooting Jacobian), ``n`` rows by a few columns.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
import scipy.sparse as sp

from prefriction.errors import SolverError
from prefriction.identify.constrained_lsq import solve
from prefriction.identify.data import Motion
from prefriction.identify.held_first import held_first
from prefriction.identify.hovers import hover_nodes
from prefriction.identify.motion_start import derivatives_of
from prefriction.identify.motion_step import STATE_CAP, segment_functions
from prefriction.identify.parameters import ParameterSpace
from prefriction.identify.pieces import breaks_of
from prefriction.identify.polish import polish
from prefriction.identify.reversals import locate_reversals
from prefriction.identify.substep_rule import follows_data, rates_along
from prefriction.models.base import FrictionModel

__all__ = ["SEGMENT", "MotionSolution", "start_error"]

SEGMENT = 50
"""Samples per shooting segment."""
GTOL = 1e-5
"""Largest continuity defect of a converged fit, in the node scales (``1e-5`` of the pre-sliding
distance ``Fc / sigma`` in position, of the velocity unit, of the normalised state)."""
NATIVE_FROM = 1_000
"""Records of at least this many samples run the compiled sub-steps (:func:`segment_functions`).
Compiling once per structure and free set takes about 1 s for Dahl and LuGre and 9 s for
Maxwell-slip(3) (gcc ``-O1``, cached on disk); an evaluation of segments with sensitivities then
costs a fourth (Dahl, LuGre) to a twelfth (Maxwell-slip(3)) of the interpreted one
(``tests/test_identify_native_steps.py``)."""
INNER_TOL_EVENTS = 1e-5
"""``ftol`` of the inner solves before the last of a model with in-branch events
(:func:`prefriction.identify.constrained_lsq.solve`): its motion is only piecewise smooth in the
parameters (an event that moves from one sub-step to the next changes the error of its location),
and tighter inner solves creep on those kinks."""
FINAL_TOL_EVENTS = 1e-8
"""Least ``xtol`` and ``ftol`` of the last inner solve of a model with in-branch events: a tighter
one is never met on the kinks (a 2,000-sample Maxwell-slip(3) window ran 14 multiplier updates
of 80 evaluations each with its defects at 1e-10); the polish then measures the rest in
standard errors."""
_NODE_WINDOW = 7
"""Samples of the Savitzky-Golay window of the node start values (short: coarse records)."""
_MAPPED: dict[Any, tuple[ca.Function, ca.Function]] = {}


@dataclass(frozen=True)
class MotionSolution:
    """What :func:`prefriction.identify.continuation.fit_motion` returns to :func:`prefriction.identify.fit`."""

    w: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    constraints: np.ndarray | None
    prediction: np.ndarray
    nuisance: dict
    message: str
    success: bool = True
    steps: tuple[str, ...] = ()
    n_sub: int = 0
    widen: dict | None = None
    """``{name: factor}``: standard errors the statistics widen (:func:`prefriction.identify.polish.valley_secant`)."""
    chain: np.ndarray | None = None
    """Of a fit that did not converge: the position residuals [m] of the single-shooting chain
    from the first node at ``w`` (each piece of the chain from its own start), for the route
    check of :func:`prefriction.identify.fit`."""
    problem: Any = dataclasses.field(default=None, repr=False, compare=False)
    """The :class:`_Problem` the solution was solved on (its layout, node scales, sub-steps and
    first flags): ``w``'s nodes are in its scales."""
    data: Motion | None = dataclasses.field(default=None, repr=False, compare=False)
    """The record the residuals and prediction are of when it is not the one given: its moves,
    every rest left out (:func:`prefriction.identify.layouts.solve_layouts`)."""
    moves_converged: bool = False
    """The fit of the record's moves converged, whether or not it became the solution (a misfit
    above :data:`prefriction.identify.layouts.MISFIT` keeps the chain's): the next stage of a
    continuation fits the moves first."""


@dataclass(frozen=True)
class _Layout:
    """Segments of a record: node samples, padded inputs, directions, scales."""

    K: int
    nodes: np.ndarray
    U0: np.ndarray
    U1: np.ndarray
    DT: np.ndarray
    s: np.ndarray
    scl: np.ndarray
    n: int
    free: np.ndarray
    s_to: np.ndarray
    """Direction of each segment's end state: the next node's, at a junction of pieces the
    segment's own."""
    breaks: int = 0
    """Junctions of a :class:`prefriction.identify.pieces.Pieces` record among the chain's starts."""

    @property
    def J(self) -> int:
        return int(self.nodes.size)

    @property
    def starts(self) -> np.ndarray:
        """Nodes that start a piece of the chain (the first node and every node after a hovering segment)."""
        return np.flatnonzero(self.free)

    def samples(self) -> np.ndarray:
        """Index of the data sample of every output column (``-1``: the end of a segment or padding)."""
        idx = self.nodes[:, None] + np.arange(self.K + 1)[None, :]
        idx[:, -1] = -1
        idx[-1, -1] = self.nodes[-1] + self.K if self.nodes[-1] + self.K == self.n - 1 else -1
        idx[idx >= self.n] = -1
        return idx.ravel()


def node_starts(n: int, K: int) -> np.ndarray:
    """First sample of each shooting segment of ``K`` samples over a record of ``n`` samples (the
    last segment padded past the record's end)."""
    return np.arange(max(1, math.ceil((n - 1) / K))) * K


def _layout(data: Motion, K: int, directions: np.ndarray, scl: np.ndarray, speed: np.ndarray | None = None) -> _Layout:
    """Segments of ``K`` samples; with the smoothed speed of the data, the nodes after hovering
    segments (:func:`prefriction.identify.hovers.hover_nodes`) start pieces of the chain. The
    first node of every piece of a :class:`prefriction.identify.pieces.Pieces` record starts a
    piece of the chain too, and the step into it from the sample before (the junction) has a zero
    time step: not simulated."""
    n = len(data)
    nodes = node_starts(n, K)
    J = nodes.size
    total = J * K
    dt = np.zeros(total)
    dt[: n - 1] = np.diff(data.t)
    u0 = np.zeros(total)
    u0[: n - 1] = data.u[:-1]
    u1 = u0.copy() if data.hold == "zoh" else np.zeros(total)
    if data.hold == "linear":
        u1[: n - 1] = data.u[1:]
    free = hover_nodes(speed, nodes, K) if speed is not None else np.zeros(J, dtype=bool)
    free[0] = True
    breaks = breaks_of(data)
    if np.any(breaks % K):
        raise ValueError(f"the pieces of a record start at samples {breaks.tolist()}: each must be a multiple of "
                         f"the segment's {K} samples")
    dt[breaks - 1] = 0.0
    free[breaks // K] = True
    s = directions[nodes]
    s_to = np.r_[s[1:], s[-1]]
    s_to[breaks // K - 1] = directions[breaks - 1]
    return _Layout(K, nodes, u0, u1, dt, s, scl, n, free, s_to, int(breaks.size))


def native_steps(n: int) -> bool:
    """Whether a fit of ``n`` samples runs the compiled steps (:func:`segment_functions`)."""
    return n >= NATIVE_FROM


def _mapped(model: FrictionModel, space: ParameterSpace, K: int, n_sub: int, mass_free: bool,
            J: int, native: bool = False) -> tuple[ca.Function, ca.Function]:
    key = (type(model), model.structure_key(), tuple(space.free), tuple(space.fixed), K, n_sub, mass_free, J, native)
    if key not in _MAPPED:
        plain, sens = segment_functions(model, space, K, n_sub, mass_free, native)
        _MAPPED.clear()
        _MAPPED[key] = (plain.map(J), sens.map(J))
    return _MAPPED[key]


class _Problem:
    """Residuals, constraints and their sparse Jacobians of one record, layout and parameter set.

    A model with flags gets them at each node as inputs, like the direction: at the first node
    those of its start state, at the others none set, so that the node's state decides (an event
    indicator not positive fires at once: a saturated Dahl or a slipping Maxwell-slip element sits
    on its limit). Flags inherited from the segment before would jump with the defects of a
    multiple-shooting iterate and make the residuals discontinuous."""

    def __init__(self, model: FrictionModel, space: ParameterSpace, data: Motion, lay: _Layout, n_sub: int,
                 mass_free: bool, mass: float, xs: float, native: bool | None = None) -> None:
        self.lay, self.nth, self.ny = lay, space.n_free, 2 + model.n_states
        self.native = native_steps(len(data)) if native is None else native
        self.plain, self.sens = _mapped(model, space, lay.K, n_sub, mass_free, lay.J, self.native)
        self.fixed, self.mass, self.xs = space.fixed_values(), mass, xs
        self.samples = lay.samples()
        self.rows = np.flatnonzero(self.samples >= 0)
        self.x = data.x[self.samples[self.rows]]
        self.keep = np.repeat(~lay.free[1:], self.ny)   # continuity rows (none into a piece's start)
        self.gw = np.ones(int(self.keep.sum()))
        s = lay.s
        self.args = dict(s0=s, s_to=lay.s_to, scale=space.scale, fixed=self.fixed, mass=mass,
                         U0=lay.U0[None, :], U1=lay.U1[None, :], DT=lay.DT[None, :], scl=lay.scl,
                         m0=np.zeros((model.n_flags, lay.J)))
        self.first_flags: list[float] = [0.0] * model.n_flags

    def carry_states(self, w: np.ndarray, single: ca.Function, everything: bool = False) -> np.ndarray:
        """``w`` with every node's model state after the first replaced by the end state of the
        segment before it (simulated from the start values): states consistent with the history.
        ``everything``: the positions and velocities too, no state capped, and the flags of each
        node those the segment before ends with (single shooting from the first node: the chain is
        continuous to rounding, the in-branch events' modes included); otherwise the flags after
        the first node are cleared (the multiple-shooting convention of the class)."""
        w = w.copy()
        th, nodes = self.split(w)
        a, K = self.args, self.lay.K
        if a["m0"].size:
            a["m0"][:, 0] = self.first_flags
            a["m0"][:, 1:] = 0.0
        for j in range(self.lay.J - 1):
            cols = slice(j * K, (j + 1) * K)
            out = single(node=nodes[:, j], m0=a["m0"][:, j], theta=th, s0=a["s0"][j], s_to=a["s_to"][j],
                         scale=a["scale"], fixed=a["fixed"], mass=a["mass"], U0=a["U0"][:, cols],
                         U1=a["U1"][:, cols], DT=a["DT"][:, cols], scl=a["scl"])
            ye = np.asarray(out["Ye"]).ravel()
            if np.all(np.isfinite(ye)) and not self.lay.free[j + 1]:
                nodes[:, j + 1] = ye if everything else np.r_[nodes[:2, j + 1], np.clip(ye[2:], -STATE_CAP, STATE_CAP)]
            if everything and a["m0"].size and not self.lay.free[j + 1]:   # a piece's start: its own state
                a["m0"][:, j + 1] = np.asarray(out["Me"]).ravel()
        w[self.nth:] = nodes.T.ravel()
        return w

    def chain_eval(self, w: np.ndarray, single: ca.Function) -> tuple[np.ndarray, np.ndarray] | None:
        """The single-shooting chain from the first node at ``w`` (:meth:`carry_states` with
        ``everything``) and its scaled position residuals, or ``None`` where the residuals or the
        continuity defects are not finite."""
        wc = self.carry_states(w, single, everything=True)
        r, g = self.plain_eval(wc)
        return (wc, r) if np.all(np.isfinite(r)) and np.all(np.isfinite(g)) else None

    def clear_flags(self) -> None:
        """Back to the multiple-shooting convention: no flag set at the nodes after the first."""
        self.args["m0"][:, 1:] = 0.0

    def weigh(self, w: np.ndarray) -> None:
        """Scale each state row of the continuity constraints by ``1 / max(1, |z|)`` at ``w``: a
        state that grows without bound in sliding (Dahl's log-gap) then counts by its relative
        mismatch in the merit function (the solution is the same: ``g = 0`` either way)."""
        _th, nodes = self.split(w)
        wt = 1.0 / np.maximum(1.0, np.abs(nodes[:, 1:]))
        wt[:2] = 1.0
        self.gw = wt.T.ravel()[self.keep]

    def split(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return w[: self.nth], w[self.nth:].reshape(self.lay.J, self.ny).T

    def _call(self, fn: ca.Function, w: np.ndarray) -> dict:
        th, nodes = self.split(w)
        out = fn(node=nodes, theta=th, **self.args)
        return {k: np.asarray(v) for k, v in out.items()}

    def residuals(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        out = self._call(self.plain, w)
        X = out["X"][0, self.rows]
        _th, nodes = self.split(w)
        g = (out["Ye"][:, :-1] - nodes[:, 1:]).T.ravel()[self.keep] * self.gw
        return (X - self.x) / self.xs, g, out

    def plain_eval(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r, g, _ = self.residuals(w)
        return r, g

    def full_eval(self, w: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix, np.ndarray, sp.csr_matrix]:
        out = self._call(self.sens, w)
        lay, nth, ny = self.lay, self.nth, self.ny
        ncol = nth + ny
        _th, nodes = self.split(w)
        X = out["X"][0, self.rows]
        dX = out["dX"][:, self.rows].T / self.xs                      # rows: residuals, cols: [theta, node]
        seg = self.rows // (lay.K + 1)
        colmap = np.concatenate([np.broadcast_to(np.arange(nth), (seg.size, nth)),
                                 nth + ny * seg[:, None] + np.arange(ny)[None, :]], axis=1)
        nw = nth + ny * lay.J
        Jr = sp.csr_matrix((dX.ravel(), (np.repeat(np.arange(seg.size), ncol), colmap.ravel())),
                           shape=(seg.size, nw))
        g = (out["Ye"][:, :-1] - nodes[:, 1:]).T.ravel()[self.keep]
        dYe = out["dYe"].reshape(ny, lay.J, ncol)[:, :-1, :].transpose(1, 0, 2)   # (J-1, ny, ncol)
        rows_g = np.arange((lay.J - 1) * ny)
        jj = rows_g // ny
        cols_g = np.concatenate([np.broadcast_to(np.arange(nth), (rows_g.size, nth)),
                                 nth + ny * jj[:, None] + np.arange(ny)[None, :]], axis=1)
        A = sp.csr_matrix((dYe.reshape(-1, ncol).ravel(), (np.repeat(rows_g, ncol), cols_g.ravel())),
                          shape=(rows_g.size, nw))
        A = A - sp.csr_matrix((np.ones(rows_g.size), (rows_g, nth + ny * (jj + 1) + rows_g % ny)),
                              shape=(rows_g.size, nw))
        A = A.tocsr()[self.keep]
        return (X - self.x) / self.xs, Jr, g * self.gw, (sp.diags(self.gw) @ A).tocsr()

    def columns(self) -> np.ndarray:
        """Index in ``w`` of every column of :meth:`reduced_jacobian`: the parameters, then the
        state of each piece's first node."""
        starts = self.lay.starts
        return np.r_[np.arange(self.nth), (self.nth + self.ny * starts[:, None] + np.arange(self.ny)).ravel()]

    def reduced_jacobian(self, w: np.ndarray) -> np.ndarray:
        """``dr/d(theta, start nodes)`` along the constraints (the single-shooting Jacobian of each
        piece of the chain), dense ``n x (nth + ny pieces)``."""
        out = self._call(self.sens, w)
        lay, nth, ny = self.lay, self.nth, self.ny
        ncol = nth + ny
        starts = lay.starts
        wide = nth + ny * starts.size
        dX = out["dX"].reshape(ncol, lay.J, lay.K + 1)
        dYe = out["dYe"].reshape(ny, lay.J, ncol)
        M = np.zeros((ny, wide))
        full = np.zeros((lay.J * (lay.K + 1), wide))
        piece = -1
        for j in range(lay.J):
            if lay.free[j]:                                           # d node_j / d(theta, its own state)
                piece += 1
                M = np.zeros((ny, wide))
                M[:, nth + ny * piece: nth + ny * (piece + 1)] = np.eye(ny)
            chain = np.zeros((ncol, wide))
            chain[:nth, :nth] = np.eye(nth)
            chain[nth:, :] = M
            full[j * (lay.K + 1):(j + 1) * (lay.K + 1)] = dX[:, j, :].T @ chain
            M = dYe[:, j, :] @ chain
        return full[self.rows] / self.xs


def _substeps(model: FrictionModel, data: Motion, mass: float, v: np.ndarray, requested: int | None) -> int:
    """RK4 sub-steps per sample (1 to 64), at the start values: a normalised sub-step of at most
    ``0.1`` of the period's ``1 / (2 pi)`` and at most ``0.5 / lambda``, ``lambda`` the largest
    decay rate of the model's state and force.

    A model with a Dahl term of ``gamma > 1`` (:func:`prefriction.identify.substep_rule.follows_data`)
    takes both from its run along the record's velocity ``v`` [m/s] (the local oscillation
    ``omega`` and decay per sample, :func:`~prefriction.identify.substep_rule.rates_along`): at most
    ``0.1 / omega`` and ``0.5 / lambda`` at every sample. Any other model: ``0.1`` (the stuck mass
    swings with period ``2 pi``) and ``lambda`` the largest rate at the record's top speed over a
    grid of states (LuGre's bristle relaxes at ``~ |v~|``, Dahl's log-gap at ``gamma <= 1`` not at all)."""
    if requested is not None:
        return requested
    T = math.sqrt(mass / model.sigma)
    dt = np.diff(data.t) / T
    if follows_data(model):
        omega, lam = rates_along(model, data.t, v, mass)
        need = np.maximum(np.maximum(omega[:-1], omega[1:]) / 0.1, np.maximum(lam[:-1], lam[1:]) / 0.5)
        return int(min(64, max(1, math.ceil(float(np.max(dt * np.maximum(need, 1.0 / 0.1)))))))
    h = float(np.max(dt))
    v_max = float(np.max(np.abs(v)))
    lam = _stiffness(model, v_max / (model.Fc / math.sqrt(mass * model.sigma)), mass)
    return int(min(64, max(1, math.ceil(h / min(0.1, 0.5 / max(lam, 1e-300))))))


def _stiffness(model: FrictionModel, v: float, mass: float) -> float:
    """Largest ``|d rate / d z|`` and ``|d F~ / d v~|`` of the start model at speeds up to ``v`` (normalised)."""
    from prefriction.units import Scales

    sc = Scales(x=model.Fc / model.sigma, F=model.Fc, t=math.sqrt(mass / model.sigma),
                v=model.Fc / math.sqrt(mass * model.sigma), E=model.Fc**2 / model.sigma)
    q = [float(c) for c in model.runtime_params_for(sc)]
    lam = 0.0
    for vv in (v, 0.1 * v, 0.01 * v):
        for f in (-0.5, 0.0, 0.5):
            z0, m0 = model.initial_state(f, 1.0)
            z = [float(c) for c in z0]
            for m in ([float(c) for c in m0], [1.0] * model.n_flags):  # flags: as loaded, and every mode on
                r0 = model.rate(z, m, vv, 1.0, q)
                for i in range(len(z)):
                    dz = 1e-6 * max(1.0, abs(z[i]))
                    zp = list(z)
                    zp[i] += dz
                    lam = max(lam, max(abs(float(a) - float(b)) / dz for a, b in zip(model.rate(zp, m, vv, 1.0, q), r0)))
                dv = 1e-6 * max(1.0, vv)
                lam = max(lam, abs(float(model.force(z, m, vv + dv, 1.0, q)) - float(model.force(z, m, vv, 1.0, q))) / dv)
    return lam


def _progress(line: str) -> None:
    print(f"motion fit: {line}", file=sys.stderr, flush=True)


def _tag(progress: Any, name: str, t0: float) -> Any:
    """``progress`` (or ``None``) with each line prefixed by the stage ``name`` and the wall-clock
    seconds since ``t0`` (:func:`time.perf_counter`)."""
    if progress is None:
        return None
    return lambda line: progress(f"{name}, {time.perf_counter() - t0:.0f} s: {line}")


def start_error(model: FrictionModel, data: Motion, space: ParameterSpace, theta: np.ndarray | None = None) -> float:
    """Mean square position error [m^2] of the shooting segments at ``space``'s start values (or
    at the scaled free entries ``theta``; ``model`` holds the same values).

    Each segment of :data:`SEGMENT` samples starts at the smoothed data (position, velocity) with
    the model state carried from the segment before (as the fit's first iterate) and runs open
    loop: how closely the start model follows the record, in the record's units whatever the
    model (interpreted steps: no compilation). ``inf`` if the motion is not finite.
    """
    theta0 = space.theta0 if theta is None else theta
    vals = space.values(theta0)
    mass_free = "mass" in space.start and "mass" in space.free
    mass = vals["mass"] if mass_free else float(data.mass)
    xsm, v, a = derivatives_of(data, _NODE_WINDOW)
    n_sub = _substeps(model, data, mass, v, None)
    lay = _layout(data, min(SEGMENT, len(data) - 1), _directions(data.t, data.x, v, None),
                  np.array([model.Fc / model.sigma, model.Fc / math.sqrt(mass * model.sigma)]))
    prob = _Problem(model, space, data, lay, n_sub, mass_free, mass, 1.0, native=False)
    single = segment_functions(model, space, lay.K, n_sub, mass_free, False)[0]
    w0, prob.first_flags = _start(model, data, theta0, lay, xsm, v, a, mass, vals.get("offset", 0.0), 0.5)
    r, _g = prob.plain_eval(prob.carry_states(w0, single))
    return float(np.mean(r * r)) if np.all(np.isfinite(r)) else math.inf


def _solve_record(model: FrictionModel, data: Motion, space: ParameterSpace, theta0: np.ndarray,
                  n_sub: int | None, max_iter: int, tol: float, reversals: Any, progress: Any,
                  weight: float, pieces: bool = False, least_sub: int = 1) -> MotionSolution:
    """One multiple-shooting fit of ``data`` from the scaled parameters ``theta0``; ``model``
    (values at ``theta0``) sets the node scales and the sub-steps (at least ``least_sub``). With
    the sub-steps chosen automatically, a converged fit is solved again with twice as many while
    doubling them moves an estimate by more than :data:`prefriction.identify.substep_check.STEP_SHIFT`
    of its standard error (:func:`_refine_substeps`)."""
    mass_free = "mass" in space.start and "mass" in space.free
    mass = space.values(theta0)["mass"] if mass_free else float(data.mass)
    xsm, v, a = derivatives_of(data, _NODE_WINDOW)
    directions = _directions(data.t, data.x, v, reversals)
    requested = n_sub
    n_sub = max(_substeps(model, data, mass, v, n_sub), 1 if requested else least_sub)
    X, V = model.Fc / model.sigma, model.Fc / math.sqrt(mass * model.sigma)
    offset0 = space.values(theta0).get("offset", 0.0)
    lay = _layout(data, min(SEGMENT, len(data) - 1), directions, np.array([X, V]),
                  np.abs(v) if pieces else None)
    xs = max(float(np.ptp(data.x)) * 1e-3, 1e-300)
    prob = _Problem(model, space, data, lay, n_sub, mass_free, mass, xs)
    single = segment_functions(model, space, lay.K, n_sub, mass_free, prob.native)[0]
    for level in (0.5, 0.0):  # node states of the force balance, else of zero force (see _start)
        w0, prob.first_flags = _start(model, data, theta0, lay, xsm, v, a, mass, offset0, level)
        w0 = prob.carry_states(w0, single)
        prob.weigh(w0)
        r0, g0 = prob.plain_eval(w0)
        if np.all(np.isfinite(r0)) and np.all(np.isfinite(g0)):
            break
    else:
        raise SolverError(f"the model's motion is not finite at the start values ({_at(space, w0)}); give start "
                          f"values closer to the data or bounds")
    lo, hi = space.theta_bounds()

    def restart(w: np.ndarray) -> np.ndarray:
        th = w[: space.n_free]
        at = space.values(th)
        fresh, prob.first_flags = _start(space.build(at), data, th, lay, xsm, v, a, at.get("mass", mass),
                                         at.get("offset", 0.0), 0.5)
        return prob.carry_states(fresh, single)

    out = solve(prob.full_eval, prob.plain_eval, w0, lo, hi, max_iter=max_iter, tol=tol, gtol=GTOL,
                weight=weight, restart=restart, progress=progress,
                inner_tol=INNER_TOL_EVENTS if model.n_events else 1e-8,
                final_tol=FINAL_TOL_EVENTS if model.n_events else 0.0)
    w = out.w
    polished = ""
    if out.success:
        w, polished = polish(prob, w, single, lo, hi, valley=bool(held_first(model, space)))
        if requested is None and not model.n_events:   # (events: piecewise smooth, see _refine_substeps)
            prob, single, out, w, n_sub, refined = _refine_substeps(prob, single, out, w, n_sub, lo, hi,
                                                                    lambda p, s, w_: solve(
                                                                        p.full_eval, p.plain_eval, w_, lo, hi,
                                                                        max_iter=max_iter, tol=tol, gtol=GTOL,
                                                                        weight=weight, progress=progress,
                                                                        inner_tol=INNER_TOL_EVENTS if model.n_events
                                                                        else 1e-8,
                                                                        final_tol=FINAL_TOL_EVENTS if model.n_events
                                                                        else 0.0),
                                                                    (model, space, data, mass_free, mass, xs))
            polished += refined
    r, _g, res = prob.residuals(w)
    Jred = prob.reduced_jacobian(w)
    Xv = res["X"]
    pred = Xv[0, prob.rows]
    vel = Xv[1, prob.rows]
    nuisance = _nuisance(model, space, w, prob, data, vel, mass_free, mass)
    return MotionSolution(w, r * xs, Jred * xs, None, pred, nuisance,
                          f"multiple shooting, {lay.J} segments of {lay.K} samples, {n_sub} RK4 sub-steps per "
                          f"sample{_pieces(lay)}, scipy least_squares in an augmented Lagrangian: "
                          f"{out.message}{polished}",
                          out.success, n_sub=n_sub, chain=None if out.success else _chain(prob, w, single) * xs,
                          problem=prob)


def _chain(prob: _Problem, w: np.ndarray, single: ca.Function) -> np.ndarray:
    """Scaled position residuals of the single-shooting chain from the first node at ``w`` (the
    nodes' flags restored after)."""
    saved = prob.args["m0"].copy()
    r, _g = prob.plain_eval(prob.carry_states(w, single, everything=True))
    prob.args["m0"][...] = saved
    return r


def _refine_substeps(prob: _Problem, single: ca.Function, out: Any, w: np.ndarray, n_sub: int, lo: np.ndarray,
                     hi: np.ndarray, resolve: Any, setup: tuple) -> tuple:
    """Refine the RK4 sub-steps while doubling them moves an estimate by more than
    :data:`prefriction.identify.substep_check.STEP_SHIFT` standard errors
    (:func:`prefriction.identify.substep_check.step_shift`, measured on the single-shooting chain
    from the first node at ``w``): the shift ``d`` of ``n_sub`` asks for ``n_sub`` times the power of
    2 at or above ``(d / STEP_SHIFT)^(1/4)`` (RK4's bias falls as ``n_sub^-4``), at least twice as many,
    at most 64; each refinement solves the fit again from ``w`` (``resolve``), polishes it and is checked again.
    Not for models with in-branch events: their residual moves in kinks as an event crosses from one
    sub-step to the next, which the comparison of two sub-step counts can take for a bias (checked,
    the Maxwell-slip(3) fit of ``tests/test_identify_motion_events.py`` took 107 s instead of 1.5 s). The doubled steps of
    the measurement run as the fit's own (compiled or interpreted: :func:`native_steps`).

    Returns
    -------
    tuple
        ``(prob, single, out, w, n_sub, note)``: the problem, chain function, solver result,
        solution and sub-steps kept, and a note for the solver message (``""`` if unchanged).
    """
    from prefriction.identify.substep_check import STEP_SHIFT, step_shift

    model, space, data, mass_free, mass, xs = setup
    lay, nth = prob.lay, prob.nth
    note = ""
    while n_sub < 64:
        saved = prob.args["m0"].copy()
        wc = prob.carry_states(w, single, everything=True)
        r, _g = prob.plain_eval(wc)
        J = prob.reduced_jacobian(wc)
        fine = _Problem(model, space, data, lay, 2 * n_sub, mass_free, mass, xs, prob.native)
        fine.first_flags = list(prob.first_flags)
        fine_single = segment_functions(model, space, lay.K, 2 * n_sub, mass_free, prob.native)[0]
        rf, _gf = fine.plain_eval(fine.carry_states(w, fine_single, everything=True))
        prob.args["m0"][...] = saved
        with np.errstate(invalid="ignore"):
            margin = 1e-9 * np.maximum(1.0, np.abs(w[:nth]))
        params = np.flatnonzero((w[:nth] - lo > margin) & (hi - w[:nth] > margin))
        shift = step_shift(J, r, rf, params, w[:nth])
        if shift <= STEP_SHIFT:
            break
        # RK4: the bias falls as n_sub^-4; jump to the power-of-2 multiple that brings it below the limit
        before, n_sub = n_sub, min(64, n_sub * 2 ** max(1, math.ceil(math.log2((shift / STEP_SHIFT) ** 0.25))))
        nxt = _Problem(model, space, data, lay, n_sub, mass_free, mass, xs, prob.native)
        nxt.first_flags, nxt.gw = list(prob.first_flags), prob.gw.copy()
        nxt_single = segment_functions(model, space, lay.K, n_sub, mass_free, nxt.native)[0]
        again = resolve(nxt, nxt_single, nxt.carry_states(w, nxt_single))
        if not again.success:
            note += (f"; doubling the RK4 sub-steps moved an estimate by {shift:.2g} standard errors, but the fit "
                     f"with {n_sub} did not converge ({again.message[-120:]}): kept {before}")
            n_sub = before
            break
        prob, single, out = nxt, nxt_single, again
        w, _note = polish(prob, again.w, single, lo, hi)
        note += (f"; {n_sub} RK4 sub-steps per sample (doubling {before} moved an estimate by {shift:.2g} standard "
                 f"errors)")
    return prob, single, out, w, n_sub, note


def _pieces(lay: _Layout) -> str:
    cut = int(lay.starts.size) - 1 - lay.breaks
    joins = f" ({lay.breaks} junctions of the record's pieces start pieces of the chain)" if lay.breaks else ""
    return joins + (f" ({cut} nodes after hovering segments start pieces of the chain)" if cut else "")


def _at(space: ParameterSpace, w: np.ndarray) -> str:
    vals = space.values(w[: space.n_free])
    return ", ".join(f"{n} = {vals[n]:.6g}" for n in space.free)


def _directions(t: np.ndarray, x: np.ndarray, v: np.ndarray, given: Any) -> np.ndarray:
    """Direction of motion at every sample: from the given reversal times (checked by
    :func:`locate_reversals`), else the sign of the smoothed velocity."""
    if given is not None:
        rev = locate_reversals(t, x, given)
        flips = np.searchsorted(rev.time, t, side="right")
        return rev.s0 * np.where(flips % 2 == 0, 1.0, -1.0)
    s = np.sign(v)
    s[s == 0.0] = 1.0
    return s


def _start(model: FrictionModel, data: Motion, theta: np.ndarray, lay: _Layout, xsm: np.ndarray,
           v: np.ndarray, a: np.ndarray, mass: float, offset0: float, level: float) -> tuple[np.ndarray, list[float]]:
    """Start vector: scaled parameters, then each node's ``[x / X, v / V, z]`` from the smoothed
    data, ``z`` the state of the force balance's friction ``u - m a - F_off`` clipped to
    ``+-level Fc``; and the flags of that state at the first node."""
    X, V = lay.scl
    nodes: list[float] = []
    first: list[float] = []
    for k, s in zip(lay.nodes, lay.s):
        f = float(np.clip((data.u[k] - mass * a[k] - offset0) / model.Fc, -level, level))
        z, m = model.initial_state(f, s)
        nodes += [xsm[k] / X, v[k] / V, *z]
        first = first or [float(c) for c in m]
    return np.concatenate([theta, nodes]), first


def _nuisance(model: FrictionModel, space: ParameterSpace, w: np.ndarray, prob: _Problem, data: Motion,
              vel: np.ndarray, mass_free: bool, mass: float) -> dict:
    """Initial velocity and force, and the reversal times of the fitted motion."""
    fitted = space.build(space.values(w[: space.n_free]))
    m = space.values(w[: space.n_free])["mass"] if mass_free else mass
    from prefriction.units import Scales

    V = fitted.Fc / math.sqrt(m * fitted.sigma)
    sc = Scales(x=fitted.Fc / fitted.sigma, F=fitted.Fc, t=math.sqrt(m / fitted.sigma), v=V,
                E=fitted.Fc**2 / fitted.sigma)
    q = [float(c) for c in fitted.runtime_params_for(sc)]
    node0 = w[space.n_free: space.n_free + prob.ny]
    v0 = float(node0[1] * prob.lay.scl[1])
    F0 = float(model.force(list(node0[2:]), list(prob.args["m0"][:, 0]), v0 / V, float(prob.lay.s[0]), q)) * fitted.Fc
    t = data.t[prob.samples[prob.rows]]
    k = np.flatnonzero(np.sign(vel[1:]) * np.sign(vel[:-1]) < 0)
    tau = t[k] + (t[k + 1] - t[k]) * vel[k] / (vel[k] - vel[k + 1])
    return {"initial velocity v0 [m/s]": v0, "initial force F0 [N]": F0, "reversal times [s]": tau}

