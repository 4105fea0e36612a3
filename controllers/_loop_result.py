"""The result of :func:`controllers.simulate_loop`: samples, reversals, settling and the friction curve."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import control
import numpy as np

from prefriction._validation import check_count
from prefriction.models import Oscillator
from prefriction.reversals import ReversalTable
from prefriction.simulation.loops import LoopStats
from prefriction.simulation.simulate import SimulationResult

from ._friction_loop import friction_curve
from ._loop_settling import LoopSettling

MAX_CURVE_POINTS = 10_000_000
"""Most points of :meth:`LoopResult.friction_loop` (160 MB of positions and forces)."""


@dataclass(frozen=True, eq=False)
class LoopResult(LoopSettling):
    """Result of :func:`simulate_loop`, SI units.

    The energy balance of the run, with the work of the controller's force counted, is
    ``prefriction.energy.analyze_result(loop)`` (potential energy at the reversals,
    dissipation per half-cycle, the input's work ``int u v dt``; a sampled controller's force
    held between the samples).

    Attributes
    ----------
    t : numpy.ndarray
        Output times [s]: the sample instants ``k Ts`` (sampled controller) or the requested
        output times (continuous controller).
    reference : numpy.ndarray
        Reference ``r(t)`` [m].
    x, v, F : numpy.ndarray
        Position [m], velocity [m/s], friction force [N].
    u : numpy.ndarray
        Total force applied to the stage [N]: the controller's plus the compensator's (after
        the force limit), for a sampled controller the value held from ``t[k]`` on (a
        zero-order hold: anyone can replay the plant from it).
    error : numpy.ndarray
        ``r - x`` [m].
    xc : numpy.ndarray
        Controller states, shape ``(len(t), n)``.
    reversals : prefriction.ReversalTable
        Every velocity reversal, located by the simulator (times, positions, forces, energies).
    Ts : float or None
        Sample time of the controller [s]; ``None`` for a continuous controller.
    controller : control.StateSpace
        The controller that ran (after ``c2d`` if the loop discretised it).
    system : prefriction.Oscillator
        The stage that was simulated.
    kp : float or None
        Static gain of the controller at ``s = 0`` (or ``z = 1``) if it is finite and
        positive (PD), ``None`` otherwise: then :attr:`error_bound` bounds the residual error.
    simulation : prefriction.simulation.simulate.SimulationResult
        The raw simulation result (run statistics, work of the input): of
        :func:`prefriction.simulate` for a continuous loop or a loop with a disturbance input,
        of the compiled loop :func:`prefriction.simulation.loops.run_sampled` otherwise.
    loop_stats : prefriction.simulation.loops.LoopStats or None
        Blocks, integrated and resting periods of the compiled sampled loop; ``None`` for the
        other paths.
    compensator : controllers.compensators.Compensator or None
        The compensator that ran (with the mismatched model if ``mismatch`` was given).
    measured : numpy.ndarray or None
        Position the controller saw at each sample [m] (noise, encoder step, delay); ``None``
        outside the compiled sampled loop.
    compensation : numpy.ndarray or None
        Compensation force at each sample [N] (0 without a compensator); ``None`` outside the
        compiled sampled loop.
    """

    t: np.ndarray
    reference: np.ndarray
    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    u: np.ndarray
    error: np.ndarray
    xc: np.ndarray
    reversals: ReversalTable
    Ts: Optional[float]
    controller: control.StateSpace
    system: Oscillator
    kp: Optional[float]
    simulation: SimulationResult
    loop_stats: Optional[LoopStats] = None
    compensator: Optional[object] = None
    measured: Optional[np.ndarray] = None
    compensation: Optional[np.ndarray] = None

    @property
    def Fc(self) -> float:
        """Reference force of the stage's friction model [N] (Dahl, LuGre: the Coulomb force;
        Maxwell-slip: the sum of the slip forces)."""
        return self.system.friction.Fc

    def friction_loop(self, points_per_branch: int = 200) -> tuple[np.ndarray, np.ndarray]:
        """Friction force-displacement curve ``F(x)`` [m, N] from the first output sample through
        every reversal to the last one.

        Dahl and Maxwell-slip are rate-independent with closed-form branches: between two
        reversals ``F`` is a function of ``x`` alone (Dahl: the branch (3.4)/(3.5) through the
        previous reversal; Maxwell-slip: every element a stop operator ``clip(F_i + k_i dx,
        -W_i, W_i)`` from the virgin state of the initial force), so the curve is exact however
        coarse the output samples are (e.g. 10 kHz samples of a stage whose half-cycles last a
        fraction of a millisecond). For the other models (LuGre, GMS, any other model of the
        protocol) the force depends on the velocity too: the curve is the output samples with
        the reversals inserted in time order, exact at the reversals only.

        Parameters
        ----------
        points_per_branch : int, default 200
            Points on each branch between two reversals (Dahl and Maxwell-slip), ``>= 2``; at
            most :data:`MAX_CURVE_POINTS` points in all.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            Positions ``x`` [m] and friction forces ``F`` [N] along the curve.

        Raises
        ------
        TypeError, ValueError
            ``points_per_branch`` not an integer ``>= 2``, or more than
            :data:`MAX_CURVE_POINTS` points in all.
        """
        branches = len(self.reversals) + 1
        points_per_branch = check_count("points_per_branch", points_per_branch, 2,
                                        max(MAX_CURVE_POINTS // branches, 2), why=f"memory: {branches} branches")
        return friction_curve(self.system, self.t, self.x, self.F, self.reversals, points_per_branch)

    def plot(self, path: "str | Path" = "loop.png") -> Path:
        """Reference and position, the tracking error and the forces against time, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "loop.png"
            Image file to write (the format from the suffix).

        Returns
        -------
        Path
            The file written.
        """
        from prefriction._result_plots import plot_loop

        return plot_loop(self, path)

    def __reduce__(self) -> tuple:
        """Pickle the controller as its matrices (python-control's StateSpace holds a lambda)."""
        fields = dict(vars(self))
        C = fields.pop("controller")
        if isinstance(C, control.StateSpace):
            C = (C.A, C.B, C.C, C.D, C.dt)
        return _unpickle, (fields, C)

    def __repr__(self) -> str:
        kind = f"sampled, Ts = {self.Ts:.4g} s" if self.Ts is not None else "continuous"
        return (f"LoopResult({kind}, {len(self.t)} samples to t = {self.t[-1]:.6g} s, residual error "
                f"{self.residual_error:.4e} m, {len(self.reversals)} reversals)")

    def summary(self) -> str:
        """A few readable lines: controller, settling, residual error (against the PD bound
        :attr:`error_bound`), reversals."""
        kind = f"sampled, Ts = {self.Ts:.4g} s" if self.Ts is not None else "continuous"
        lines = [
            f"closed loop ({kind}), t_end = {self.t[-1]:.6g} s, {len(self.t)} output samples",
            f"  reference at t_end      {self.reference[-1]: .6e} m",
            f"  position at t_end       {self.x[-1]: .6e} m",
            f"  settling time (2 %)     {self.settling_time:.6g} s  (|r - x| within 2 % of the reference's travel)",
            f"  residual error r - x    {self.residual_error: .6e} m",
        ]
        if self.error_bound is not None:
            ratio = abs(self.residual_error) / self.error_bound
            name = "Fc/kp" if self.system.friction.max_hysteretic_force == self.Fc else "F_max/kp"
            lines.append(f"  {'PD bound ' + name:<24}{self.error_bound: .6e} m  (|e| / bound = {ratio:.4f})")
        lines += [
            f"  friction force at t_end {self.F[-1]: .6e} N  (|F|/Fc = {abs(self.F[-1]) / self.Fc:.4f})",
            f"  peak control force      {np.max(np.abs(self.u)): .6e} N",
        ]
        if self.compensator is not None and self.compensation is not None:
            lines.append(f"  compensator             {self.compensator}, peak force {np.max(np.abs(self.compensation)):.6e} N")
        lines += [
            f"  velocity reversals      {len(self.reversals)}",
        ]
        return "\n".join(lines)


def _unpickle(fields: dict, C: object) -> LoopResult:
    """A :class:`LoopResult` from :meth:`LoopResult.__reduce__`'s parts."""
    if isinstance(C, tuple):
        C = control.ss(*C[:4], dt=C[4])
    return LoopResult(controller=C, **fields)
