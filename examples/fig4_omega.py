"""Figure 4 of the paper: the exponential term Omega (3.10) and its secant Omega* (3.11).

``Omega(x) = exp(-sigma x / Fc)`` with ``x`` the distance travelled from the force zero
crossing, and ``Omega*(x) = 1 - K x`` with ``K = (sigma/Fc) (Fc/(Fc - F_i))^0.6``, for
``F_i = -Fc x {0.2, 0.4, 0.6, 0.8, 1}``; ``Fc = 1 N`` (the paper does not state it).

The paper draws three panels, ``sigma/Fc`` in {1, 2, 8} 1/m, which differ only by the scale of
``x``: both terms depend on ``sigma x/Fc`` alone. This figure therefore draws one of them and
uses the other two panels for what the paper's figure cannot show:

(a) Omega and Omega* against ``x`` for ``sigma/Fc = 1`` 1/m (top axis: ``x`` for 8 1/m), with
    the exact next reversal (Lambert-W map, on Omega) and the next reversal from the corrected
    (3.13) (on Omega*).
(b) The gap ``Omega* - Omega`` against the normalised distance ``sigma x/Fc``: the paper requires
    Omega* to meet Omega at the next reversal; the gap vanishes at the secant crossing instead,
    which is the next reversal only for ``F_i`` near ``-Fc``.
(c) The error of both stand-ins for the next reversal (the secant crossing and the corrected
    (3.13)) against the exact map, for every ``|F_i|/Fc`` in (0, 1].
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from prefriction import dahl
from prefriction.plotting import COLORS, add_note, new_figure, save

FC = 1.0  # Coulomb force [N]; not stated in the paper
RATIOS = (1.0, 2.0, 8.0)  # sigma/Fc [1/m], as in the paper
AMPLITUDES = (0.2, 0.4, 0.6, 0.8, 1.0)  # |F_i|/Fc, F_i = -Fc * a
TOP_RATIO = 8.0  # sigma/Fc [1/m] of the top axis of panel (a)


def secant_crossing(k: float) -> float:
    """Normalised abscissa ``y > 0`` where ``exp(-y) = 1 - k y`` (``0 < k < 1``)."""
    return brentq(lambda y: (np.expm1(-y) + k * y) / y, 1e-12, 1.0 / k, xtol=1e-15, rtol=1e-14)


def normalised_reversals(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normalised distances ``sigma x/Fc`` of the next reversal from ``|F_i|/Fc = a``.

    Returns the exact map's, the corrected (3.13)'s and the secant crossing's.
    """
    y_exact = -np.log1p(-np.asarray(dahl.next_amplitude(a), dtype=float))
    y_approx = -np.log1p(-np.asarray(dahl.next_amplitude_paper(a), dtype=float))
    y_cross = np.array([secant_crossing(k) for k in (1.0 + np.asarray(a)) ** -0.6])  # K Fc/sigma (3.11)
    return y_exact, y_approx, y_cross


def panel(ratio: float, y_max: float, points: int) -> dict:
    """Omega, Omega* and the three next-reversal abscissae [m] for ``sigma/Fc = ratio``, up to ``sigma x/Fc = y_max``."""
    sigma = ratio * FC
    y_exact, y_approx, y_cross = normalised_reversals(np.asarray(AMPLITUDES))
    x = np.linspace(0.0, y_max * FC / sigma, points)
    stars = {a: np.asarray(dahl.omega_star(x, -a * FC, sigma, FC), dtype=float) for a in AMPLITUDES}
    slopes = {a: float((s[0] - s[1]) / (x[1] - x[0])) for a, s in stars.items()}
    return {
        "x": x, "omega": np.asarray(dahl.omega(x, sigma, FC), dtype=float), "omega_star": stars,
        "K": slopes,
        "x_exact": dict(zip(AMPLITUDES, y_exact * FC / sigma)),
        "x_approx": dict(zip(AMPLITUDES, y_approx * FC / sigma)),
        "x_cross": {a: secant_crossing(slopes[a] * FC / sigma) * FC / sigma for a in AMPLITUDES},
    }


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw Figure 4 into ``outdir/fig4_omega.png``.

    Returns
    -------
    dict
        ``amplitudes``; per ratio in ``panels[ratio]``: ``x`` [m], ``omega`` (Omega on x),
        ``omega_star`` (dict a -> Omega* on x), ``x_exact``, ``x_approx``, ``x_cross``
        (dict a -> abscissa [m] of the exact next reversal, of the corrected (3.13), and of the
        second intersection of Omega and Omega*), ``K`` (dict a -> slope [1/m]); ``error``
        (``a`` on a fine grid and the relative errors ``approx`` and ``cross`` of the corrected
        (3.13) and of the secant crossing against the exact next reversal); ``png``.
    """
    points = 60 if quick else 300
    a = np.asarray(AMPLITUDES)
    y_exact, y_approx, y_cross = normalised_reversals(a)
    y_max = 1.15 * float(np.max(y_exact))  # normalised x range of (a) and (b)
    panels = {ratio: panel(ratio, y_max, points) for ratio in RATIOS}

    fig, axes = new_figure(1, 3, size=(13.5, 4.8))
    ax = axes[0, 0]
    p = panels[1.0]  # sigma = 1 1/m * Fc
    ax.plot(p["x"], p["omega"], "k--", lw=1.8, label=r"$\Omega(x)$ (3.10)", zorder=3)
    for color, ai in zip(COLORS, AMPLITUDES):
        xe, xa = p["x_exact"][ai], p["x_approx"][ai]
        ax.plot(p["x"], p["omega_star"][ai], color=color, lw=1.3, label=rf"$\Omega^*$, $F_i = -{ai:g}\,F_c$")
        ax.plot(xe, dahl.omega(xe, FC, FC), "o", color=color, ms=6, mfc="none", zorder=4)
        ax.plot(xa, 1.0 - p["K"][ai] * xa, "x", color=color, ms=6, zorder=4)
    ax.plot([], [], "ko", ms=6, mfc="none", label=r"exact $x_{i+1}$ (on $\Omega$)")
    ax.plot([], [], "kx", ms=6, label=r"$x_{i+1}$ from corrected (3.13)")
    ax.set_xlim(0.0, p["x"][-1])
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"distance from the force zero crossing $x$ [m], $\sigma/F_c$ = 1 m$^{-1}$")
    ax.set_ylabel(r"$\Omega$, $\Omega^*$ [-]")
    top = ax.secondary_xaxis("top", functions=(lambda x: x / TOP_RATIO, lambda x: x * TOP_RATIO))
    top.set_xlabel(rf"$x$ [m] for $\sigma/F_c$ = {TOP_RATIO:g} m$^{{-1}}$", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title(r"(a) as in the paper: $\Omega$ and $\Omega^*$", fontsize=11)

    ax = axes[0, 1]
    for color, ai, ye, ya, yc in zip(COLORS, AMPLITUDES, y_exact, y_approx, y_cross):
        k = (1.0 + ai) ** -0.6  # K Fc/sigma (3.11)
        y = np.linspace(0.0, 1.25 * max(ye, yc), points)  # up to just past the next reversal
        ax.plot(y, 1.0 - k * y - np.exp(-y), color=color, lw=1.3, label=rf"$F_i = -{ai:g}\,F_c$")
        ax.plot(ye, 1.0 - k * ye - np.exp(-ye), "o", color=color, ms=6, mfc="none", zorder=4)
        ax.plot(ya, 1.0 - k * ya - np.exp(-ya), "x", color=color, ms=6, zorder=4)
        ax.plot(yc, 0.0, "D", color=color, ms=4, zorder=4)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.plot([], [], "ko", ms=6, mfc="none", label=r"exact $x_{i+1}$")
    ax.plot([], [], "kx", ms=6, label="corrected (3.13)")
    ax.plot([], [], "kD", ms=4, label=r"crossing $\Omega^* = \Omega$")
    ax.set_xlim(0.0, y_max)
    ax.set_xlabel(r"normalised distance $\sigma x/F_c$ [-] (every $\sigma/F_c$)")
    ax.set_ylabel(r"gap $\Omega^* - \Omega$ [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left", fontsize=8, ncol=2)
    ax.set_title(r"(b) where $\Omega^*$ meets $\Omega$", fontsize=11)

    ax = axes[0, 2]
    grid = np.linspace(0.01, 1.0, 50 if quick else 200)
    g_exact, g_approx, g_cross = normalised_reversals(grid)
    err_approx, err_cross = g_approx / g_exact - 1.0, g_cross / g_exact - 1.0
    ax.plot(grid, 100.0 * err_cross, color="0.3", lw=1.5, label=r"crossing $\Omega^* = \Omega$")
    ax.plot(grid, 100.0 * err_approx, color="0.3", lw=1.5, ls="--", label="corrected (3.13)")
    for color, ai, ye, ya, yc in zip(COLORS, AMPLITUDES, y_exact, y_approx, y_cross):
        ax.plot(ai, 100.0 * (yc / ye - 1.0), "D", color=color, ms=5, zorder=4)
        ax.plot(ai, 100.0 * (ya / ye - 1.0), "x", color=color, ms=7, mew=1.5, zorder=4)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlim(0.0, 1.03)
    ax.set_xlabel(r"reversal amplitude $|F_i|/F_c$ [-]")
    ax.set_ylabel(r"error of $x_{i+1}$ against the exact map [%]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("(c) error of the two stand-ins for $x_{i+1}$", fontsize=11)

    fig.suptitle(r"Fig. 4: $\Omega$ (3.10) and its linear approximation $\Omega^*$ (3.11)")
    add_note(fig, f"Fc = {FC:g} N (not stated in the paper). Omega and Omega* depend on sigma x/Fc only: "
                  "the paper's panels for sigma/Fc = 1, 2, 8 1/m are (a) with x scaled by 1, 1/2, 1/8.")
    png = save(fig, outdir, "fig4_omega.png")
    return {"amplitudes": AMPLITUDES, "panels": panels, "Fc": FC,
            "error": {"a": grid, "approx": err_approx, "cross": err_cross}, "png": png}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
