"""Simulated counterpart of an unstable predicted limit cycle: bisection on its stable manifold.

An unstable cycle (:attr:`LimitCycle.stable` False) is not reached by simulating forward: it
separates motions that decay from motions that grow. :func:`trace_unstable_cycle` starts the
closed loop on the predicted sinusoid scaled by ``lambda`` (position ``x = 0`` at the set point,
velocity ``lambda omega X``, controller states of the sinusoidal steady state), classifies each
run as decaying or growing, and bisects on ``lambda``. Near the boundary the motion lingers on
the true cycle for many periods; period and first harmonics are measured there, on the runs
just below and just above the boundary while they still agree (``docs/describing.md#trace``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from prefriction._progress import ProgressLine
from prefriction._validation import check_choice, check_count, check_interval
from prefriction.describing.limit_cycle import LimitCycle
from prefriction.describing.velocity import controller_tf
from prefriction.models import Oscillator, check_oscillator

__all__ = ["TracedCycle", "simulate_from_cycle", "trace_unstable_cycle"]

_SAMPLES = 256  # dense samples per period
_AGREE = 0.01  # the two bracketing runs are on the cycle while their peaks agree to 1 %


@dataclass(frozen=True)
class TracedCycle:
    """The unstable limit cycle as found in simulation (:func:`trace_unstable_cycle`).

    Attributes
    ----------
    predicted : LimitCycle
        The describing-function prediction that was traced.
    variable : str
        ``"velocity"`` or ``"position"``: what ``predicted.amplitude`` measures.
    scale : float
        ``lambda`` at the boundary between decaying and growing runs.
    width : float
        Final bracket width in ``lambda``.
    period : float
        Mean period [s] over the lingering periods.
    amplitude : float
        First-harmonic amplitude of the velocity [m/s] (mean over the lingering periods).
    position_amplitude : float
        First-harmonic amplitude of the position [m].
    periods : int
        Full periods on the cycle (both bracketing runs agree to 1 %).
    """

    predicted: LimitCycle
    variable: str
    scale: float
    width: float
    period: float
    amplitude: float
    position_amplitude: float
    periods: int

    def errors(self) -> tuple[float, float]:
        """Relative errors ``(amplitude, period)`` of the prediction: predicted over simulated, minus 1."""
        sim = self.amplitude if self.variable == "velocity" else self.position_amplitude
        return self.predicted.amplitude / sim - 1.0, self.predicted.period / self.period - 1.0

    def summary(self) -> str:
        """One line: the simulated cycle."""
        return (f"simulated unstable cycle (lambda = {self.scale:.8g} +- {self.width:.1g}): period {self.period:.6g} s, "
                f"velocity amplitude {self.amplitude:.6g} m/s, position amplitude {self.position_amplitude:.6g} m "
                f"({self.periods} periods on the cycle)")

    def __repr__(self) -> str:
        return (f"TracedCycle(period={self.period:.6g}, amplitude={self.amplitude:.6g}, "
                f"position_amplitude={self.position_amplitude:.6g}, periods={self.periods})")


def _feedback(controller: Any, X: float, omega: float, scale: float) -> Any:
    """The controller as ``LinearFeedback`` (reference 0) with the cycle's state at ``x = 0``, ``x' > 0``."""
    from prefriction.simulation.feedback import LinearFeedback

    S = control.ss(controller_tf(controller))
    A, B = np.asarray(S.A, float), np.asarray(S.B, float)
    # e = -x = -X sin(omega t): steady state xc = Im((i omega - A)^-1 B (-X) e^{i omega t}), here t = 0
    xc = (np.linalg.solve(1j * omega * np.eye(A.shape[0]) - A, B).ravel() * (-X)).imag if A.size else np.zeros(0)
    return LinearFeedback(A=A, B=B, C=S.C, D=S.D, reference=0.0, xc0=scale * xc)


def _run(system: Oscillator, controller: Any, X: float, omega: float, scale: float, periods: int, rtol: float) -> Any:
    from prefriction.simulation.simulate import simulate

    T = 2.0 * math.pi / omega
    t = T * np.arange(periods * _SAMPLES + 1) / _SAMPLES
    return simulate(system, scale * X * omega, t_end=t[-1], dense=t, rtol=rtol,
                    feedback=_feedback(controller, X, omega, scale))


def simulate_from_cycle(system: Oscillator, controller: Any, cycle: LimitCycle, scale: float, *, periods: int = 12,
                        variable: str = "velocity", rtol: float = 1e-9) -> Any:
    """The loop ``u = C(s)(0 - x)`` started on the predicted sinusoid scaled by ``scale``.

    Start: ``x = 0``, ``v = scale omega X``, ``F = 0``, controller states ``scale`` times those of
    the sinusoidal steady state ``x = X sin(omega t)``, with ``X`` the predicted position amplitude.
    Parameters as in :func:`trace_unstable_cycle`; ``0 <= scale <= 10``.

    Returns
    -------
    prefriction.SimulationResult
        With ``256`` dense samples per predicted period over ``periods`` periods.
    """
    check_oscillator(system, "simulate_from_cycle")
    scale = check_interval("scale", scale, 0.0, 10.0)
    periods = check_count("periods", periods, minimum=1, maximum=200)
    variable = check_choice("variable", variable, ("velocity", "position"))
    rtol = check_interval("rtol", rtol, 1e-13, 1e-6)
    X = cycle.amplitude / cycle.omega if variable == "velocity" else cycle.amplitude
    return _run(system, controller, X, cycle.omega, scale, periods, rtol)


def _peaks(res: Any, periods: int) -> np.ndarray:
    return np.abs(res.v[:-1]).reshape(periods, _SAMPLES).max(axis=1)


def trace_unstable_cycle(system: Oscillator, controller: Any, cycle: LimitCycle, *, variable: str = "velocity",
                         bracket: tuple = (0.8, 1.2), steps: int = 20, periods: int = 12,
                         rtol: float = 1e-9) -> TracedCycle:
    """Find the unstable limit cycle ``cycle`` of the loop ``u = C(s)(0 - x)`` in simulation.

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model; no input force.
    controller : controllers.PID or control.LTI
        Continuous SISO controller from the position error [m] to the force [N].
    cycle : LimitCycle
        Unstable prediction of :func:`prefriction.describing.predict_limit_cycle`.
    variable : {"velocity", "position"}
        What ``cycle.amplitude`` measures: the velocity [m/s] (:class:`VelocityDescribingFunction`)
        or the position [m] (:class:`FrictionDescribingFunction`).
    bracket : (float, float)
        Initial ``lambda`` bracket, the lower end decaying and the upper one growing, ``0 < lo < hi <= 10``.
    steps : int
        Bisection steps, ``1..40``; step ``k`` is one simulation of ``min(periods, 4 + k)`` periods,
        and two more runs at the final bracket are measured.
    periods : int
        Predicted periods simulated per run at most, ``4..200``.
    rtol : float
        Tolerance of :func:`prefriction.simulate`.

    Returns
    -------
    TracedCycle

    Raises
    ------
    ValueError
        Bad arguments, a stable ``cycle``, a bracket whose ends do not decay and grow, or fewer
        than two periods on the cycle (more ``steps`` or ``periods`` needed).
    """
    check_oscillator(system, "trace_unstable_cycle")
    if system.u is not None:
        raise ValueError("trace_unstable_cycle: system must have no input force (system.u is None)")
    if not isinstance(cycle, LimitCycle) or cycle.stable:
        raise ValueError(f"cycle must be an unstable LimitCycle (a stable one is simulated directly and read with "
                         f"measure_limit_cycle), got {cycle!r}")
    variable = check_choice("variable", variable, ("velocity", "position"))
    steps = check_count("steps", steps, maximum=40)
    periods = check_count("periods", periods, minimum=4, maximum=200)
    rtol = check_interval("rtol", rtol, 1e-13, 1e-6)
    lo, hi = (check_interval("bracket", b, 0.0, 10.0) for b in bracket)
    if not 0.0 < lo < hi:
        raise ValueError(f"bracket must be (lo, hi) with 0 < lo < hi <= 10, got {bracket!r}")
    w = cycle.omega
    X = cycle.amplitude / w if variable == "velocity" else cycle.amplitude

    def grows(scale: float, k: int) -> tuple[bool, Any]:
        # horizon 4 + k periods: each step halves the distance to the boundary, so the run lingers
        # about one period longer; a longer horizon lets the growing runs explode
        n = min(periods, 4 + k)
        res = _run(system, controller, X, w, scale, n, rtol)
        p = _peaks(res, n)
        return bool(p[-1] > p[1]), res

    if grows(lo, 0)[0] or not grows(hi, 0)[0]:
        raise ValueError(f"bracket {bracket!r}: lambda = {lo!r} must decay and lambda = {hi!r} grow; widen it")
    line = ProgressLine()
    for k in range(1, steps + 1):
        mid = 0.5 * (lo + hi)
        if grows(mid, k)[0]:
            hi = mid
        else:
            lo = mid
        line.show(f"trace_unstable_cycle: step {k}/{steps}, lambda in [{lo:.10g}, {hi:.10g}]")
    line.close()
    n_run = min(periods, 4 + steps)
    r_lo, r_hi = (_run(system, controller, X, w, b, n_run, rtol) for b in (lo, hi))
    p_lo, p_hi = _peaks(r_lo, n_run), _peaks(r_hi, n_run)
    on = np.abs(p_hi - p_lo) <= _AGREE * p_hi
    n = 1
    while n < n_run and on[n]:  # period 0 holds the start's transient
        n += 1
    if n - 1 < 2:
        raise ValueError(f"trace_unstable_cycle: only {n - 1} periods on the cycle after {steps} steps; "
                         "raise steps (or periods)")
    return _measure(r_hi, r_lo, cycle, variable, 0.5 * (lo + hi), hi - lo, n)


def _measure(r_hi: Any, r_lo: Any, cycle: LimitCycle, variable: str, scale: float, width: float,
             n: int) -> TracedCycle:
    """Period from the upward zero crossings of ``v`` and the mean first harmonics over periods ``1..n-1``."""
    t_end = r_hi.t[n * _SAMPLES]
    amps, xamps, spans = [], [], []
    for res in (r_hi, r_lo):
        t, v, x = res.t, res.v, res.x
        up = np.nonzero((v[:-1] < 0.0) & (v[1:] >= 0.0) & (t[1:] > t[_SAMPLES]) & (t[1:] <= t_end))[0]
        tc = t[up] - v[up] * (t[up + 1] - t[up]) / (v[up + 1] - v[up])
        for a, b in zip(tc[:-1], tc[1:]):
            sel = (t > a) & (t < b)
            ts, T = np.r_[a, t[sel], b], b - a
            om = 2.0 * math.pi / T
            for y, out in ((v, amps), (x, xamps)):
                sig = np.r_[np.interp(a, t, y), y[sel], np.interp(b, t, y)]
                c = np.trapezoid(sig * np.cos(om * ts), ts)
                s = np.trapezoid(sig * np.sin(om * ts), ts)
                out.append(2.0 * math.hypot(c, s) / T)
            spans.append(T)
    if len(spans) < 2:
        raise ValueError("trace_unstable_cycle: fewer than two full periods on the cycle; raise steps")
    return TracedCycle(predicted=cycle, variable=variable, scale=scale, width=width, period=float(np.mean(spans)),
                       amplitude=float(np.mean(amps)), position_amplitude=float(np.mean(xamps)),
                       periods=len(spans) // 2)
