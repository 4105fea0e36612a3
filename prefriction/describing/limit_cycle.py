"""Limit cycles of friction loops: the describing-function prediction and the simulated cycle.

A limit cycle of the loop ``x = -H(s) N(A) x`` (python-control's convention) has
``1 + H(i omega) N(A, omega) = 0``. :func:`predict_limit_cycles` finds every intersection with
``control.describing_function_response`` at a fixed frequency, moves the frequency of each to
the intersection found and repeats (needed when ``N`` depends on ``omega``), solves the two real
equations for ``(A, omega)`` with scipy, and decides each cycle's stability over all modes of
the quasi-linear loop (:mod:`prefriction.describing.stability`). :func:`predict_limit_cycle`
returns the cycle a motion settles on. :func:`measure_limit_cycle` reads amplitude and period
from simulated samples, for the comparison.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable, Optional

import control
import numpy as np
from scipy.optimize import root

from prefriction._progress import ProgressLine
from prefriction._validation import check_count, check_interval, check_positive, check_real_array
from prefriction.describing.stability import cycle_stability
from prefriction.describing.velocity import controller_tf
from prefriction.models import Oscillator, check_oscillator

_PROGRESS_AFTER = 1.0  # progress lines once a rate-dependent search has run this long [s]

__all__ = ["LimitCycle", "MeasuredCycle", "friction_loop", "measure_limit_cycle", "predict_limit_cycle",
           "predict_limit_cycles"]


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
        The cycle attracts nearby motions: a larger amplitude decays, a smaller one grows
        (Loeb's condition ``R_A X_omega - X_A R_omega > 0`` on ``D = 1/H(i omega) + N(A, omega)
        = R + i X``) and every other mode of the quasi-linear loop decays
        (:func:`prefriction.describing.stability.cycle_stability`, ``docs/describing.md#stability``).
    growing : tuple of complex
        Other modes ``s`` [1/s] of the quasi-linear loop that grow at this amplitude (empty if none).
    """

    amplitude: float
    omega: float
    N: complex
    iterations: int
    stable: bool
    growing: tuple = ()

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
        other = (f"; {len(self.growing)} other mode(s) grow, fastest at {self.growing[0].imag:.4g} rad/s"
                 if self.growing else "")
        return (f"predicted {kind} limit cycle: input amplitude {self.amplitude:.6g}, omega {self.omega:.6g} rad/s, "
                f"period {self.period:.6g} s, output amplitude {self.output_amplitude():.6g}{other}")

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


def _linear_part(H: Any) -> control.TransferFunction:
    """``H`` as a SISO continuous-time transfer function; TypeError/ValueError naming ``H`` otherwise."""
    if not isinstance(H, control.LTI):
        raise TypeError(f"H must be a python-control LTI system (control.tf or control.ss), got {type(H).__name__} "
                        f"{H!r:.60}")
    if (H.ninputs, H.noutputs) != (1, 1):
        raise ValueError(f"H must be SISO (one input, one output), got {H.ninputs} inputs and {H.noutputs} outputs")
    if H.dt not in (0, None):
        raise ValueError(f"H must be continuous-time (dt = 0), got dt = {H.dt!r}")
    return control.tf(H)


def _check_block(block: Any) -> None:
    if not callable(getattr(block, "describing_function", None)):
        raise TypeError(f"block must be a describing-function nonlinearity (an object with describing_function(A), "
                        f"e.g. DahlDescribingFunction), got {type(block).__name__}")


def _grid(omega_grid: Any) -> np.ndarray:
    if omega_grid is None:
        return np.logspace(-2, 4, 600)
    grid = np.asarray(omega_grid, dtype=float)
    if grid.ndim != 1 or grid.size < 2 or not np.all(np.isfinite(grid)) or np.any(grid <= 0) \
            or np.any(np.diff(grid) <= 0):
        raise ValueError(f"omega_grid must be a 1-D increasing array of >= 2 finite positive frequencies [rad/s], "
                         f"got {np.array2string(grid.ravel()[:6], precision=4)}{' ...' if grid.size > 6 else ''}")
    return grid


def predict_limit_cycles(H: Any, block: Any, amplitudes: Any, *, omega: Optional[float] = None,
                         omega_grid: Any = None, iterations: int = 8, rtol: float = 1e-6) -> tuple[LimitCycle, ...]:
    """Every limit cycle of ``x = -H N x`` predicted by the describing function, by amplitude.

    Parameters
    ----------
    H : control.LTI
        SISO continuous-time linear part (e.g. :func:`friction_loop`, or the controller for a
        plant block).
    block : control.DescribingFunctionNonlinearity
        The nonlinearity: :class:`prefriction.describing.DahlDescribingFunction`,
        :class:`FrictionDescribingFunction` or :class:`PlantDescribingFunction`. If it has an
        attribute ``rate_independent`` that is False, its ``at(omega)`` is used to iterate
        on the frequency of each intersection.
    amplitudes : array_like
        Amplitudes where python-control looks for intersections of ``-1 / N`` with
        ``H(i omega)``, increasing, positive.
    omega : float, optional
        First frequency [rad/s] of a rate-dependent block (default: the block's own).
    omega_grid : array_like, optional
        Frequencies [rad/s] of the Nyquist curve of ``H`` (default ``logspace(-2, 4, 600)``),
        increasing, finite, positive.
    iterations : int, default 8
        Frequency iterations per intersection at most (``1..50``).
    rtol : float, default 1e-6
        Tolerance on the frequency between iterations and of the final solve.

    Returns
    -------
    tuple of LimitCycle
        The cycles by increasing amplitude, each with its stability over all modes
        (``LimitCycle.stable``, ``LimitCycle.growing``); empty if the curves do not intersect
        over ``amplitudes``.

    Raises
    ------
    TypeError
        ``H`` is not a python-control LTI system, or ``block`` has no ``describing_function``.
    ValueError
        Bad arguments (a MIMO or discrete-time ``H``, bad amplitudes or frequencies), or a final
        solve that does not converge (the message gives the last iterate).
    """
    Hs = _linear_part(H)
    _check_block(block)
    A = np.asarray(amplitudes, dtype=float)
    if A.ndim != 1 or A.size < 2 or np.any(~np.isfinite(A)) or np.any(A <= 0) or np.any(np.diff(A) <= 0):
        raise ValueError(f"amplitudes must be a 1-D increasing array of >= 2 positive numbers, got {amplitudes!r}")
    iterations = check_count("iterations", iterations, maximum=50)
    rtol = check_interval("rtol", rtol, 1e-12, 1e-1)
    grid = _grid(omega_grid)
    if getattr(block, "rate_independent", True):
        found = [(a, w, 0) for a, w in _intersections(Hs, block, A, grid)]
        N = lambda amp, om: block.describing_function(amp)  # noqa: E731
    else:
        w0 = check_positive("omega", omega if omega is not None else block.omega)
        first = _intersections(Hs, block.at(w0), A, grid)
        line, start = ProgressLine(), time.perf_counter()

        def progress(text: str) -> None:  # each N is a simulation: report once the search takes a while
            if time.perf_counter() - start > _PROGRESS_AFTER:
                line.show(f"predict_limit_cycles: {text}, {time.perf_counter() - start:.1f} s")

        found = [_iterate(Hs, block, A, grid, w, iterations, rtol,
                          lambda k, om, i=i: progress(f"intersection {i + 1}/{len(first)}, iteration {k}: "
                                                      f"omega {om:.6g} rad/s"))
                 for i, (_, w) in enumerate(first)]
        line.close()
        found = [f for f in found if f is not None]
        N = lambda amp, om: block.at(om).describing_function(amp)  # noqa: E731
    cycles: list[LimitCycle] = []
    for a, w, its in found:
        cyc = _solve(Hs, N, a, w, its, rtol)
        if not any(abs(math.log(c.amplitude / cyc.amplitude)) < 1e-4 and abs(math.log(c.omega / cyc.omega)) < 1e-4
                   for c in cycles):
            cycles.append(cyc)
    return tuple(sorted(cycles, key=lambda c: c.amplitude))


def _iterate(H: Any, block: Any, A: np.ndarray, grid: np.ndarray, w: float, iterations: int,
             rtol: float, progress: Callable[[int, float], None]) -> Optional[tuple[float, float, int]]:
    """Follow one intersection of a rate-dependent block in frequency until it settles."""
    a = math.nan
    for k in range(1, iterations + 1):
        progress(k, w)
        found = _intersections(H, block.at(w), A, grid)
        if not found:
            return None
        a, w_new = min(found, key=lambda aw: abs(math.log(aw[1] / w)))
        done = abs(w_new - w) <= rtol * w
        w = w_new
        if done:
            break
    return a, w, k


def predict_limit_cycle(H: Any, block: Any, amplitudes: Any, *, omega: Optional[float] = None,
                        omega_grid: Any = None, iterations: int = 8, rtol: float = 1e-6) -> Optional[LimitCycle]:
    """The limit cycle of ``x = -H N x`` that motions settle on, or ``None``.

    Of the cycles of :func:`predict_limit_cycles` (same arguments), the stable one of least
    amplitude; if none is stable, the unstable one of least amplitude (the boundary between
    motions that decay and motions that grow); ``None`` if there is no cycle over
    ``amplitudes``. Use :func:`predict_limit_cycles` to see them all.

    Parameters
    ----------
    H, block, amplitudes, omega, omega_grid, iterations, rtol
        As for :func:`predict_limit_cycles`.

    Returns
    -------
    LimitCycle or None
    """
    cycles = predict_limit_cycles(H, block, amplitudes, omega=omega, omega_grid=omega_grid,
                                  iterations=iterations, rtol=rtol)
    stable = [c for c in cycles if c.stable]
    return (stable or list(cycles) or [None])[0]


def _solve(H: Any, N: Any, a: float, w: float, its: int, rtol: float) -> LimitCycle:
    """``1 + H(i w) N(a, w) = 0`` in ``(ln a, ln w)`` from python-control's estimate, and its stability."""
    def eq(p: np.ndarray) -> list:
        amp, om = math.exp(p[0]), math.exp(p[1])
        r = 1.0 + complex(H(1j * om)) * N(amp, om)
        return [r.real, r.imag]

    # forward differences of 1e-5 in (ln A, ln omega): a simulated N carries errors near 1e-6
    sol = root(eq, [math.log(a), math.log(w)], method="hybr", options={"xtol": rtol, "eps": 1e-10})
    if not sol.success or max(abs(v) for v in sol.fun) > 1e-6:
        raise ValueError(
            f"predict_limit_cycle: 1 + H N = 0 not solved from A = {a:.6g}, omega = {w:.6g} rad/s ({sol.message}; "
            f"residual {max(abs(v) for v in sol.fun):.3g}); try other amplitudes or a finer omega_grid"
        )
    amp, om = math.exp(sol.x[0]), math.exp(sol.x[1])
    stable, growing = cycle_stability(H, N, amp, om)
    return LimitCycle(amplitude=amp, omega=om, N=complex(N(amp, om)), iterations=its, stable=stable, growing=growing)


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
    t = check_real_array("t", t, "s")
    y = check_real_array("y", y)
    if t.ndim != 1 or y.shape != t.shape:
        raise ValueError(f"t and y must be 1-D arrays of the same length, got shapes {t.shape} and {y.shape}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must be strictly increasing [s]")
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
