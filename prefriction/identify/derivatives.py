"""Velocity and acceleration from sampled positions, as inverse-model identification needs them.

The recipe of the EMPS reference scripts (Janot, Gautier and Brunot, *Data set and reference
models of EMPS*, 2019, ``Script_IDIM_LS.m``; ``docs/identify.md#inverse-model``):

1. a zero-phase low-pass: a Butterworth filter of order 4 and cut-off ``fc`` run forwards and
   backwards (``scipy.signal.filtfilt``, odd extension of ``3 (order)`` samples as MATLAB pads),
   ``x_f = filtfilt(x)``;
2. central differences ``v_k = (x_f[k+1] - x_f[k-1]) / (2 dt)`` and ``a_k`` the same of ``v``
   (one-sided at the ends);
3. the first ``border`` samples dropped (the filter's start transient; ``tail`` at the end);
4. decimation of every column of the regression and of the force by ``step``: a Chebyshev type I
   low-pass of order 8 at ``0.8 / step`` of the Nyquist frequency, run forwards and backwards,
   then every ``step``-th sample ending at the last one (MATLAB's ``decimate``). The decimation
   removes what the model does not describe above the fitted band and thins the samples, so that
   the residuals are closer to independent.

Defaults from the sample rate ``fs = 1 / dt`` and the noise: ``fc = fs / 10`` (EMPS: 100 Hz at
1 kHz), lowered if the position noise ``s_x`` (the standard deviation of ``x - x_f`` at
``fs / 4``) would give an acceleration noise above 1 % of the acceleration's RMS: white noise
through an ideal low-pass at ``fc`` and two derivatives has the standard deviation
``s_a = (2 pi)^2 s_x sqrt(2 fc^5 / (5 fs))``; ``step = round(fs / fc)`` (EMPS: 10, the
scripts' ``round(0.8 fnyq / (0.4 fc))``); ``border = 5 fs / fc - 1`` (EMPS: 49); no
``tail`` (as the scripts; give ``tail = border`` for a record that ends in a fast move).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import signal

from prefriction._validation import check_count, check_positive

__all__ = ["Derivatives", "decimate", "derivatives", "filtfilt"]


def filtfilt(b: np.ndarray, a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Zero-phase filtering as MATLAB's ``filtfilt`` (odd extension of ``3 (max(len) - 1)`` samples)."""
    return signal.filtfilt(b, a, x, padtype="odd", padlen=3 * (max(len(a), len(b)) - 1))


@functools.lru_cache(maxsize=16)
def _cheby(step: int) -> tuple[np.ndarray, np.ndarray]:
    return signal.cheby1(8, 0.05, 0.8 / step)


def decimate(x: np.ndarray, step: int) -> np.ndarray:
    """``x`` low-passed (Chebyshev I, order 8, ripple 0.05 dB, cut-off ``0.8 / step`` of Nyquist,
    zero phase) and every ``step``-th sample kept, ending at the last (MATLAB's ``decimate``);
    along the first axis of a 2-D ``x`` (columns)."""
    x = np.asarray(x, dtype=float)
    if step == 1:
        return x.copy()
    b, a = _cheby(step)
    y = signal.filtfilt(b, a, x, axis=0, padtype="odd", padlen=3 * (max(len(a), len(b)) - 1))
    n = x.shape[0]
    n_out = -(-n // step)
    return y[step - (step * n_out - n) - 1::step]


def _central(y: np.ndarray, dt: float) -> np.ndarray:
    """Central differences, one-sided at the ends (the scripts' ``diffcent``)."""
    return np.concatenate(([y[1] - y[0]], 0.5 * (y[2:] - y[:-2]), [y[-1] - y[-2]])) / dt


@dataclass(frozen=True, eq=False)
class Derivatives:
    """Filtered position, velocity and acceleration of a record and how they were made.

    Attributes
    ----------
    t, x, v, a : numpy.ndarray
        Times [s], filtered positions [m], velocities [m/s] and accelerations [m/s^2] at every
        sample (the border included: :attr:`keep` selects the samples the fit uses).
    cutoff : float
        Cut-off frequency [Hz] of the Butterworth filter.
    order : int
        Its order.
    step : int
        Decimation factor.
    border : int
        Samples dropped at the start.
    tail : int
        Samples dropped at the end.
    noise : float
        Estimated position noise [m] (standard deviation of ``x - x_f`` at ``fs / 4``).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    cutoff: float
    order: int
    step: int
    border: int
    noise: float
    tail: int = 0

    @property
    def keep(self) -> slice:
        """The samples after the border and before the tail."""
        return slice(self.border, self.t.size - self.tail)

    def regress(self, column: np.ndarray) -> np.ndarray:
        """A signal at every sample (or columns of them), border dropped and decimated."""
        return decimate(np.asarray(column, dtype=float)[self.keep], self.step)

    def summary(self) -> str:
        """One line: the filter and decimation used."""
        return (f"Butterworth order {self.order} at {self.cutoff:.4g} Hz (zero phase), central differences, "
                f"first {self.border}{f' and last {self.tail}' if self.tail else ''} samples dropped, decimation by "
                f"{self.step}; position noise {self.noise:.3g} m")


def derivatives(t: Any, x: Any, *, cutoff: float | None = None, order: int = 4, step: int | None = None,
                border: int | None = None, tail: int = 0) -> Derivatives:
    """Velocity and acceleration of sampled positions by the inverse-model recipe (module docstring).

    Parameters
    ----------
    t : array_like
        Sample times [s], uniformly spaced (relative spread of the intervals below 1e-3).
    x : array_like
        Positions [m].
    cutoff : float, optional
        Butterworth cut-off [Hz], ``0 < cutoff < fs / 2``; default from the sample rate and noise.
    order : int, default 4
        Butterworth order, 1 to 8.
    step : int, optional
        Decimation factor, 1 to 100; default ``round(fs / cutoff)``.
    border : int, optional
        Samples dropped at the start; default ``5 fs / cutoff - 1``.
    tail : int, default 0
        Samples dropped at the end (the reference scripts keep them; a record that ends in a fast
        move is better cut by ``border``: the filter's end transient).

    Returns
    -------
    Derivatives

    Raises
    ------
    ValueError
        If the samples are not uniform, fewer than ``border + 10 step``, or an option is out of range.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or x.shape != t.shape or t.size < 20:
        raise ValueError(f"t and x must be 1-D of the same length, at least 20 samples, got shapes {t.shape} and "
                         f"{x.shape}")
    dts = np.diff(t)
    dt = float(np.mean(dts))
    if not dt > 0 or np.ptp(dts) > 1e-3 * dt:
        raise ValueError(f"t must be uniformly spaced (intervals within 1e-3 of their mean), got intervals from "
                         f"{dts.min()!r} to {dts.max()!r} s")
    fs = 1.0 / dt
    order = check_count("order", order, 1, 8, "filter order")
    b4, a4 = signal.butter(order, 0.5)
    noise = float(np.std(x - filtfilt(b4, a4, x)))
    if cutoff is None:
        cutoff = fs / 10.0
        xf = filtfilt(*signal.butter(order, 2.0 * cutoff / fs), x)
        a_rms = float(np.sqrt(np.mean(_central(_central(xf, dt), dt) ** 2)))
        if noise > 0.0 and a_rms > 0.0:
            limit = (0.01 * a_rms / ((2.0 * np.pi) ** 2 * noise)) ** 2 * 5.0 * fs / 2.0
            cutoff = float(min(cutoff, max(limit ** 0.2, fs / 200.0)))
    cutoff = check_positive("cutoff", cutoff)
    if not cutoff < fs / 2.0:
        raise ValueError(f"cutoff must be below the Nyquist frequency {fs / 2.0:.6g} Hz, got {cutoff!r}")
    step = int(max(1, round(fs / cutoff))) if step is None else check_count("step", step, 1, 100, "decimation factor")
    border = int(round(5.0 * fs / cutoff)) - 1 if border is None else check_count("border", border, 0)
    tail = check_count("tail", tail, 0)
    if x.size < border + tail + 10 * step:
        raise ValueError(f"the record has {x.size} samples: at least border + tail + 10 step = "
                         f"{border + tail + 10 * step} are needed (lower border, tail or step)")
    b, a = signal.butter(order, 2.0 * cutoff / fs)
    xf = filtfilt(b, a, x)
    v = _central(xf, dt)
    return Derivatives(t, xf, v, _central(v, dt), float(cutoff), order, step, border, noise, tail)
