"""Gain and phase margins of the positioning loop, read off the exact crossovers.

``control.stability_margins`` evaluates the loop gain on a frequency grid and reports spurious
crossovers on the pre-sliding plant ``1/(m s^2 + sigma)``: the undamped resonance at
``sqrt(sigma/m)`` (a gain margin of about 1e-12, i.e. "marginal at zero gain") and round-off
far above the bandwidth (a gain margin of 1e15 at 1e11 rad/s). :func:`margins` finds the
crossovers as roots instead:

- continuous loop ``L(s) = N(s)/D(s)``: with ``N(jw) = Nr + j Ni`` and ``D(jw) = Dr + j Di``
  (real polynomials in ``w``), the phase crossovers are the positive roots of
  ``Ni Dr - Nr Di`` (``L`` real) where ``L < 0``, the gain crossovers the positive roots of
  ``Nr^2 + Ni^2 - Dr^2 - Di^2`` (``|L| = 1``);
- discrete loop (``z = exp(j w Ts)``, ``0 < w <= pi/Ts``): the same two functions, bracketed
  on a grid of 20,000 frequencies and refined with ``scipy.optimize.brentq``.

Frequencies where ``D(jw) = 0`` (a pole on the imaginary axis, the undamped resonance) are not
crossovers: ``|L|`` is infinite there. The gain margin is the factor by which the gain may grow
before the loop is marginal, ``1/|L|`` at the phase crossover with ``|L| < 1`` (``inf`` if there
is none); the phase margin is ``180 deg + arg L`` at the gain crossover with the smallest
margin (``inf`` if ``|L|`` never crosses 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import control
import numpy as np
from scipy.optimize import brentq

from prefriction.models import Oscillator

from ._linear import _sample_time, as_lti, linear_plant
from ._pid import PID

__all__ = ["Margins", "margins"]


@dataclass(frozen=True)
class Margins:
    """Stability margins of the loop gain ``L = C P``.

    Attributes
    ----------
    gain_margin : float
        Factor [-] by which the loop gain may grow before the loop is marginal: ``1/|L|`` at the
        phase crossover (``L`` real and negative) with ``|L| < 1``; ``inf`` if there is none.
    phase_margin : float
        ``180 + arg L(j w)`` [deg] at the gain crossover ``|L| = 1`` with the smallest margin;
        ``inf`` if ``|L|`` never crosses 1.
    stability_margin : float
        Smallest distance of the Nyquist curve from -1 [-] (``control.stability_margins``).
    w_phase_crossover : float
        Frequency [rad/s] of the gain margin; ``nan`` if there is no such crossover.
    w_gain_crossover : float
        Frequency [rad/s] of the phase margin; ``nan`` if there is no gain crossover.
    phase_crossovers, gain_crossovers : tuple of float
        Every phase crossover (``L < 0`` real) and gain crossover frequency [rad/s], ascending.
    lower_gain_margin : float
        Factor [-] below 1 to which the gain may shrink before the loop is marginal: ``1/|L|``
        at the phase crossover with ``|L| > 1`` (a conditionally stable loop, e.g. a PID on the
        sliding plant ``1/(m s^2)``); 0 if there is none.
    """

    gain_margin: float
    phase_margin: float
    stability_margin: float
    w_phase_crossover: float
    w_gain_crossover: float
    lower_gain_margin: float = 0.0
    phase_crossovers: tuple = ()
    gain_crossovers: tuple = ()

    def __str__(self) -> str:
        if math.isinf(self.gain_margin):
            gm = "gain margin inf (no phase crossover with |L| < 1)"
        else:
            gm = (f"gain margin {self.gain_margin:.4g} ({20 * math.log10(self.gain_margin):.3g} dB) at "
                  f"{self.w_phase_crossover:.5g} rad/s")
        if math.isinf(self.phase_margin):
            pm = "phase margin inf (|L| never crosses 1)"
        else:
            pm = f"phase margin {self.phase_margin:.4g} deg at {self.w_gain_crossover:.5g} rad/s"
        low = f", lower gain margin {self.lower_gain_margin:.4g}" if self.lower_gain_margin > 0 else ""
        return f"{gm}{low}, {pm}, stability margin {self.stability_margin:.4g}"


def _roots_continuous(f: np.ndarray) -> np.ndarray:
    """Positive real roots of the real polynomial ``f`` (coefficients, highest power first)."""
    f = np.trim_zeros(np.asarray(f, dtype=float), "f")
    if f.size < 2:
        return np.zeros(0)
    r = np.roots(f)
    r = r[(np.abs(r.imag) <= 1e-7 * np.abs(r)) & (r.real > 0)].real
    out = []
    for w in np.unique(r):  # refine: np.roots loses digits on coefficients spanning many decades
        a, b = w * (1 - 1e-6), w * (1 + 1e-6)
        fa, fb = np.polyval(f, a), np.polyval(f, b)
        out.append(brentq(lambda x: np.polyval(f, x), a, b, xtol=1e-14 * w) if fa * fb < 0 else w)
    return np.array(sorted(out))


def _cancelled(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a - b`` with the coefficients that cancel to round-off set to zero (they would put
    spurious roots far above the bandwidth, e.g. at 1e11 rad/s)."""
    diff = np.polysub(a, b)
    size = np.polyadd(np.abs(a), np.abs(b))
    return np.where(np.abs(diff) <= 1e-12 * size, 0.0, diff)


def _roots_grid(fun: Callable[[np.ndarray], np.ndarray], w: np.ndarray) -> np.ndarray:
    """Roots of ``fun`` bracketed by sign changes on the grid ``w``, refined with brentq."""
    y = fun(w)
    k = np.nonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)[0]
    return np.array([brentq(lambda x: float(fun(np.array([x]))[0]), w[i], w[i + 1], xtol=1e-14 * w[i]) for i in k])


def _polynomials(sys: "PID | control.LTI") -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator coefficients of a SISO system; a :class:`PID` from its formula,
    other systems from ``control.tf`` with leading coefficients at round-off (below 1e-12 of
    the largest, left by the state-space conversion) dropped."""
    tf = sys.tf() if isinstance(sys, PID) else control.tf(sys)
    out = []
    for p in (tf.num[0][0], tf.den[0][0]):
        p = np.atleast_1d(np.squeeze(p)).astype(float)
        big = np.max(np.abs(p))
        while p.size > 1 and abs(p[0]) <= 1e-12 * big:
            p = p[1:]
        out.append(p)
    return out[0], out[1]


def _loop_polynomials(P: control.StateSpace, C: "PID | control.LTI") -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of ``L = P C`` as products of the factors' polynomials."""
    (pn, pd), (cn, cd) = _polynomials(P), _polynomials(C)
    return np.polymul(pn, cn), np.polymul(pd, cd)


def _axis_values(L: tuple[np.ndarray, np.ndarray], Ts: float | None) -> tuple[Callable, Callable, np.ndarray, np.ndarray]:
    """``N`` and ``D`` of ``L = N/D`` on the frequency axis as functions of ``w`` [rad/s], and the
    phase and gain crossover candidates [rad/s]."""
    num, den = L
    if Ts is None:
        jpow = lambda p: np.array([1j ** k for k in range(len(p) - 1, -1, -1)]) * p  # noqa: E731
        Nj, Dj = jpow(num), jpow(den)  # N(jw) as a polynomial in w (complex coefficients)
        Nr, Ni, Dr, Di = Nj.real, Nj.imag, Dj.real, Dj.imag
        im = _cancelled(np.polymul(Ni, Dr), np.polymul(Nr, Di))
        gain = _cancelled(np.polyadd(np.polymul(Nr, Nr), np.polymul(Ni, Ni)),
                          np.polyadd(np.polymul(Dr, Dr), np.polymul(Di, Di)))
        N = lambda w: np.polyval(Nj, w)  # noqa: E731
        D = lambda w: np.polyval(Dj, w)  # noqa: E731
        return N, D, _roots_continuous(im), _roots_continuous(gain)
    N = lambda w: np.polyval(num, np.exp(1j * w * Ts))  # noqa: E731
    D = lambda w: np.polyval(den, np.exp(1j * w * Ts))  # noqa: E731
    wn = math.pi / Ts
    grid = np.unique(np.concatenate((np.geomspace(1e-6 * wn, wn, 10_000), np.linspace(1e-6 * wn, wn, 10_000))))
    im = _roots_grid(lambda w: (N(w) * np.conj(D(w))).imag, grid)
    gain = _roots_grid(lambda w: np.abs(N(w)) ** 2 - np.abs(D(w)) ** 2, grid)
    return N, D, np.append(im, wn), gain  # at the Nyquist frequency L is real


def margins(system: Oscillator, controller: "PID | control.LTI", *, regime: str = "presliding") -> Margins:
    """Gain, phase and stability margins of ``L = C P`` at the exact crossovers (module notes).

    A discrete controller is evaluated with the ZOH-discretised plant, up to the Nyquist
    frequency ``pi/Ts``.

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage: mass [kg] and friction model (rest stiffness sigma [N/m]).
    controller : PID or control.LTI
        Controller from the error ``e = r - x`` [m] to the force ``u`` [N].
    regime : {"presliding", "sliding"}, default "presliding"
        Linearisation of the plant: ``1/(m s^2 + sigma)`` or ``1/(m s^2)``.

    Returns
    -------
    Margins
        Gain margin [-] (``inf`` without a phase crossover), phase margin [deg] (``inf``
        without a gain crossover), stability margin [-], their frequencies [rad/s] and every
        crossover frequency.
    """
    C = as_lti(controller)
    Ts = _sample_time(C)
    P = linear_plant(system, regime, Ts)
    N, D, w_im, w_gain = _axis_values(_loop_polynomials(P, controller if Ts is None else C), Ts)
    phase_x, gms = [], []
    for w in w_im:
        n, d = N(w), D(w)
        if abs(d) <= 1e-9 * abs(n):  # a pole on the axis: |L| infinite, not a crossover
            continue
        val = n / d
        if val.real < 0:
            phase_x.append(float(w))
            gms.append(1.0 / abs(val))
    upper = [(g, w) for g, w in zip(gms, phase_x) if g > 1.0]
    gm, wpc = min(upper) if upper else (math.inf, math.nan)
    lower = max((g for g in gms if g < 1.0), default=0.0)
    pms = [(float(180.0 + np.degrees(np.angle(N(w) / D(w)))), float(w)) for w in w_gain]
    pms = [((pm + 180.0) % 360.0 - 180.0, w) for pm, w in pms]
    pm, wgc = min(pms, key=lambda p: abs(p[0])) if pms else (math.inf, math.nan)
    _, _, sm, _, _, _ = control.stability_margins(P * C)
    return Margins(gm, pm, float(sm), wpc, wgc, lower, tuple(phase_x), tuple(float(w) for w in w_gain))
