"""Stability of a harmonic-balance solution over all modes of the quasi-linear loop.

With the block replaced by its describing function ``N(A, omega)``, the loop ``x = -H(s) N x``
(``H = num / den``) has the modes ``s`` with ``den(s) + N num(s) = 0``. ``N`` is the gain for
``exp(i omega t)`` with ``omega > 0``; a mode and its conjugate make one real motion, so the
modes are the roots in the upper half plane (a root in the lower half plane would apply ``N``
at a negative frequency, where the gain is ``conj(N)``: its conjugate belongs to the
conjugate polynomial and is not a mode).

A cycle ``(A0, omega0)`` puts one mode on the imaginary axis, at ``i omega0``. It is stable
when a slightly larger amplitude decays and a slightly smaller one grows, and every other mode
decays:

- the critical mode: perturbing ``A`` moves it by ``ds = -i (D_A / D_omega) dA`` with
  ``D = 1 / H(i omega) + N(A, omega)``; it moves into the left half plane for ``dA > 0`` iff
  ``R_A X_omega - X_A R_omega > 0`` (``D = R + i X``; Loeb's condition, which holds the
  amplitude derivative ``N_A`` and for a rate-dependent block also ``N_omega``);
- the other modes: the upper-half-plane roots of ``den + N(A0 (1 + delta), omega0) num`` other
  than the critical one must all have ``Re s < 0`` (``N`` frozen at ``omega0``: exact for a
  rate-independent block, the quasi-linear estimate for a rate-dependent one).

Loeb's condition alone checks the critical pair only: on python-control's ``H_multiple`` loop
with Dahl friction it calls the cycle at ``A = 1.16`` stable while a mode near 0.5 rad/s grows
until ``A = 4.74`` (``docs/describing.md#stability``).
"""

from __future__ import annotations

import math
from typing import Callable

import control
import numpy as np

__all__ = ["cycle_stability"]

_DELTA = 1e-4  # relative amplitude step (also of the central differences in ln A, ln omega)


def cycle_stability(H: control.TransferFunction, N: Callable[[float, float], complex], A0: float,
                    omega0: float) -> tuple[bool, tuple[complex, ...]]:
    """Whether the cycle ``(A0, omega0)`` of ``x = -H N x`` is stable, and the other modes that grow.

    Parameters
    ----------
    H : control.TransferFunction
        SISO linear part.
    N : callable
        ``N(A, omega)``, the describing function.
    A0, omega0 : float
        Amplitude and angular frequency [rad/s] of the cycle (``1 + H N = 0`` there).

    Returns
    -------
    (bool, tuple of complex)
        Stability, and the growing modes ``s`` [1/s] other than the critical one (empty if none).
    """
    def D(lnA: float, lnw: float) -> complex:
        return 1.0 / complex(H(1j * math.exp(lnw))) + N(math.exp(lnA), math.exp(lnw))

    a, w, h = math.log(A0), math.log(omega0), _DELTA
    dA = (D(a + h, w) - D(a - h, w)) / (2.0 * h)
    dw = (D(a, w + h) - D(a, w - h)) / (2.0 * h)
    critical_decays = dA.real * dw.imag - dA.imag * dw.real > 0.0
    growing = _other_growing_modes(H, N(A0 * (1.0 + _DELTA), omega0), omega0)
    return bool(critical_decays and not growing), growing


def _other_growing_modes(H: control.TransferFunction, N: complex, omega0: float) -> tuple[complex, ...]:
    """Upper-half-plane roots of ``den + N num`` with ``Re s > 0``, less the one nearest ``i omega0``."""
    num, den = (np.atleast_1d(np.asarray(c[0][0], dtype=float)) for c in (H.num, H.den))
    roots = np.roots(np.polyadd(den.astype(complex), N * num))
    scale = max(float(np.max(np.abs(roots))) if roots.size else 1.0, omega0)
    tiny = 1e-9 * scale
    modes = roots[roots.imag > tiny]
    if modes.size:
        modes = np.delete(modes, int(np.argmin(np.abs(modes - 1j * omega0))))
    return tuple(complex(s) for s in sorted(modes[modes.real > tiny], key=lambda s: -s.real))
