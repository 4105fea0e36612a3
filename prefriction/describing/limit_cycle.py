"""Limit cycles of friction loops: the describing-function prediction and the simulated cycle.

A limit cycle of the loop ``x = -H(s) N(A) x`` (python-control's convention) has
``1 + H(i omega) N(A, omega) = 0``. :func:`predict_limit_cycle` finds it with
``control.describing_function_response`` at a fixed frequency, moves the frequency to the
intersection found and repeats (needed when ``N`` depends on ``omega``), then solves the two
real equations for ``(A, omega)`` with scipy. :func:`measure_limit_cycle` reads amplitude and
period from simulated samples, for the comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import control
import numpy as np
from scipy.optimize import root

from prefriction._validation import check_count, check_interval, check_positive
from prefriction.describing.velocity import controller_tf
from prefriction.models import Oscillator, check_oscillator

__all__ = ["LimitCycle", "MeasuredCycle", "friction_loop", "measure_limit_cycle", "predict_limit_cycle"]


@dataclass(frozen=True)
class LimitCycle:
    """A limit cycle predicted by the describing function.

    Attributes
    ----------
    amplitude : float
        Amplitude of the first harmonic at the nonlinearity's input (its unit: [m] for a
        friction block, [N] for a plant block).
    omega : float
        Angular frequency [rad/s].
    N : complex
        Describing function there.
    iterations : int
        Frequency iterations with python-control before the final solve.
    stable : bool
        Loeb's criterion (quasi-static amplitude dynamics): with ``D = 1/H(i omega) + N(A, omega)
        = R + i X``, the cycle attracts nearby amplitudes if ``R_A X_omega - X_A R_omega > 0``
        (partial derivatives by central differences). An unstable cycle separates motions that
        decay from motions that grow (``docs/describing.md#stability``).
    """

    amplitude: float
    omega: float
    N: complex
    iterations: int
    stable: bool

    @property
    def period(self) -> float:
        """``2 pi / omega`` [s]."""
        return 2.0 * math.pi / self.omega

    def output_amplitude(self) -> float:
        """First-harmonic amplitude at the block's output, ``|N| amplitude``."""
        return abs(self.N) * self.amplitude

    def summary(self) -> str:
        """One line: stability, amplitude, frequency, period, output amplitude."""
        kind = "stable" if self.stable else "unstable"
        return (f"predicted {kind} limit cycle: input amplitude {self.amplitude:.6g}, omega {self.omega:.6g} rad/s, "
                f"period {self.period:.6g} s, output amplitude {self.output_amplitude():.6g}")

    def __repr__(self) -> str:
        return (f"LimitCycle(amplitude={self.amplitude:.6g}, omega={self.omega:.6g}, period={self.period:.6g}, "
                f"stable={self.stable})")


@dataclass(frozen=True)
class MeasuredCycle:
    """A periodic motion read from samples (:func:`measure_limit_cycle`).

    Attributes
    ----------
    period : float
        Mean period [s] over the analysed window.
    amplitude : float
        First-harmonic amplitude over the last period (signal units).
    half_range : float
        Half the peak-to-peak range over the last period.
    mean : float
        Mean over the last period.
    periods : int
        Full periods found in the window.
    """

    period: float
    amplitude: float
    half_range: float
    mean: float
    periods: int

    def summary(self) -> str:
        """One line."""
        return (f"simulated cycle: period {self.period:.6g} s, first harmonic {self.amplitude:.6g}, "
                f"half range {self.half_range:.6g}, mean {self.mean:.6g} ({self.periods} periods)")


def friction_loop(system: Oscillator, controller: Any) -> control.TransferFunction:
    """``H(s) = 1 / (m s^2 + C(s))``: what the friction force sees in the loop ``u = -C x``.

    With ``m x'' = u - F`` and ``u = C(s)(r - x)``, a deviation ``x`` about the set point obeys
    ``x = -H(s) F``: the friction block is in negative feedback around ``H``.

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model.
    controller : controllers.PID or control.LTI
        Continuous SISO controller from the error [m] to the force [N] (anything with
        ``.tf()`` or a python-control LTI object).

    Returns
    -------
    control.TransferFunction
        ``H`` [m/N].
    """
    check_oscillator(system, "friction_loop")
    C = controller_tf(controller)
    num, den = np.asarray(C.num[0][0], float), np.asarray(C.den[0][0], float)
    m = np.polymul([system.mass, 0.0, 0.0], den)
    return control.tf(den, np.polyadd(m, num), inputs="F", outputs="x", name="H")


def _intersections(H: Any, nl: Any, amplitudes: np.ndarray, omega_grid: np.ndarray) -> list:
    resp = control.describing_function_response(H, nl, amplitudes, omega=omega_grid, refine=False,
                                                warn_nyquist=False)
    return [(float(a), float(w)) for a, w in resp.intersections]


def predict_limit_cycle(H: Any, block: Any, amplitudes: Any, *, omega: Optional[float] = None,
                        omega_grid: Any = None, iterations: int = 8, rtol: float = 1e-6) -> Optional[LimitCycle]:
    """Limit cycle of ``x = -H N x`` predicted by the describing function, or ``None``.

    Parameters
    ----------
    H : control.LTI
        Linear part (e.g. :func:`friction_loop`, or the controller for a plant block).
    block : control.DescribingFunctionNonlinearity
        The nonlinearity: :class:`prefriction.describing.DahlDescribingFunction`,
        :class:`FrictionDescribingFunction` or :class:`PlantDescribingFunction`. If it has an
        attribute ``rate_independent`` that is False, its ``at(omega)`` is used to iterate
        on the frequency.
    amplitudes : array_like
        Amplitudes where python-control looks for an intersection of ``-1 / N`` with
        ``H(i omega)``, increasing, positive.
    omega : float, optional
        First frequency [rad/s] of a rate-dependent block (default: the block's own).
    omega_grid : array_like, optional
        Frequencies [rad/s] of the Nyquist curve of ``H`` (default ``logspace(-2, 4, 600)``).
    iterations : int, default 8
        Frequency iterations at most (``1..50``).
    rtol : float, default 1e-6
        Tolerance on the frequency between iterations and of the final solve.

    Returns
    -------
    LimitCycle or None
        The cycle (the one nearest in frequency if there are several), or ``None`` if the
        curves do not intersect over ``amplitudes``: no limit cycle is predicted there.

    Raises
    ------
    ValueError
        Bad arguments, or the final solve does not converge (the message gives the last
        iterate).
    """
    A = np.asarray(amplitudes, dtype=float)
    if A.ndim != 1 or A.size < 2 or np.any(~np.isfinite(A)) or np.any(A <= 0) or np.any(np.diff(A) <= 0):
        raise ValueError(f"amplitudes must be a 1-D increasing array of >= 2 positive numbers, got {amplitudes!r}")
    iterations = check_count("iterations", iterations)
    if iterations > 50:
        raise ValueError(f"iterations must be <= 50, got {iterations}")
    rtol = check_interval("rtol", rtol, 1e-12, 1e-1)
    grid = np.logspace(-2, 4, 600) if omega_grid is None else np.asarray(omega_grid, dtype=float)
    dependent = not getattr(block, "rate_independent", True)
    if not dependent:
        found = _intersections(H, block, A, grid)
        if not found:
            return None
        a, w = found[0]
        return _solve(H, lambda amp, om: block.describing_function(amp), a, w, 0, rtol)
    w = check_positive("omega", omega if omega is not None else block.omega)
    for k in range(1, iterations + 1):
        found = _intersections(H, block.at(w), A, grid)
        if not found:
            return None
        a, w_new = min(found, key=lambda aw: abs(math.log(aw[1] / w)))
        done = abs(w_new - w) <= rtol * w
        w = w_new
        if done:
            break
    return _solve(H, lambda amp, om: block.at(om).describing_function(amp), a, w, k, rtol)


def _solve(H: Any, N: Any, a: float, w: float, its: int, rtol: float) -> LimitCycle:
    """``1 + H(i w) N(a, w) = 0`` in ``(ln a, ln w)`` from python-control's estimate, and Loeb's test."""
    def D(p: np.ndarray) -> complex:  # 1/H + N: zero on the cycle, analytic in the frequency
        amp, om = math.exp(p[0]), math.exp(p[1])
        return 1.0 / complex(H(1j * om)) + N(amp, om)

    def eq(p: np.ndarray) -> list:
        r = D(p) * complex(H(1j * math.exp(p[1])))
        return [r.real, r.imag]

    sol = root(eq, [math.log(a), math.log(w)], method="hybr", options={"xtol": rtol})
    if not sol.success or max(abs(v) for v in sol.fun) > 1e-6:
        raise ValueError(
            f"predict_limit_cycle: 1 + H N = 0 not solved from A = {a!r}, omega = {w!r} rad/s ({sol.message}; "
            f"residual {sol.fun!r}); try other amplitudes or a finer omega_grid"
        )
    h = 1e-4  # central differences in ln A and ln omega (the criterion's sign is scale-free)
    dA = (D(sol.x + [h, 0.0]) - D(sol.x - [h, 0.0])) / (2.0 * h)
    dw = (D(sol.x + [0.0, h]) - D(sol.x - [0.0, h])) / (2.0 * h)
    amp, om = math.exp(sol.x[0]), math.exp(sol.x[1])
    return LimitCycle(amplitude=amp, omega=om, N=complex(N(amp, om)), iterations=its,
                      stable=bool(dA.real * dw.imag - dA.imag * dw.real > 0.0))


def measure_limit_cycle(t: Any, y: Any, *, t_start: float) -> MeasuredCycle:
    """Period and amplitude of a periodic signal sampled at ``t`` [s], from ``t_start`` on.

    Periods are the spacings of the upward crossings of the window's mean (linear
    interpolation between samples); the first harmonic is taken over the last full period
    (trapezoidal rule on the samples, which should be dense).

    Raises
    ------
    ValueError
        Fewer than two full periods in the window (no limit cycle there).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    t_start = check_positive("t_start", t_start)
    keep = t >= t_start
    t, y = t[keep], y[keep]
    mean = 0.5 * (y.max() + y.min()) if y.size else math.nan
    up = np.nonzero((y[:-1] < mean) & (y[1:] >= mean))[0]
    if up.size < 3:
        raise ValueError(
            f"measure_limit_cycle: fewer than two full periods after t_start = {t_start!r} s "
            f"({max(up.size - 1, 0)} found): no periodic motion there"
        )
    tc = t[up] + (mean - y[up]) * (t[up + 1] - t[up]) / (y[up + 1] - y[up])
    T = float(np.mean(np.diff(tc)))
    sel = (t >= tc[-2]) & (t <= tc[-1])
    ts, ys = t[sel], y[sel]
    w = 2.0 * math.pi / (tc[-1] - tc[-2])
    b = 2.0 * np.trapezoid(ys * np.sin(w * ts), ts) / (tc[-1] - tc[-2])
    a = 2.0 * np.trapezoid(ys * np.cos(w * ts), ts) / (tc[-1] - tc[-2])
    return MeasuredCycle(period=T, amplitude=float(math.hypot(a, b)), half_range=float(0.5 * (ys.max() - ys.min())),
                         mean=float(np.trapezoid(ys, ts) / (tc[-1] - tc[-2])), periods=int(up.size - 1))
