"""The Maxwell-slip stage both friction_along C-pass test files use: three elements, the stop
operator written from its definition (closed form for a piecewise-linear motion), and the uneven
sampling of a two-tone motion."""

from __future__ import annotations

import numpy as np

K, W = np.array([6e4, 3e4, 1e4]), np.array([0.3, 0.4, 0.3])  # N/m, N


def element_forces(x: np.ndarray) -> np.ndarray:
    """Element forces [N] from the relaxed state, ``n x 3``: element i carries ``k_i (x - a_i)``
    clipped to ``+-W_i``, its anchor ``a_i`` dragged along while it slips."""
    a = np.full(K.size, x[0])
    out = np.empty((x.size, K.size))
    for j, xj in enumerate(x):
        out[j] = np.clip(K * (xj - a), -W, W)
        a = xj - out[j] / K
    return out


def two_tone(seed: int, n: int, amp: tuple[float, float], freq: tuple[float, float]
             ) -> tuple[np.ndarray, np.ndarray]:
    """``n`` sample times 0.5 to 1.5 ms apart (drawn with ``seed``) [s] and the positions
    ``amp[0] sin(2 pi freq[0] t) + amp[1] sin(2 pi freq[1] t)`` [m] at them."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, n))
    return t, amp[0] * np.sin(2 * np.pi * freq[0] * t) + amp[1] * np.sin(2 * np.pi * freq[1] * t)
