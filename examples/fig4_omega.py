"""Figure 4 of the paper: the exponential term Omega (3.10) and its secant Omega* (3.11).

``Omega(x) = exp(-sigma x / Fc)`` with ``x`` the distance travelled from the force zero
crossing, and ``Omega*(x) = 1 - K x`` with ``K = (sigma/Fc) (Fc/(Fc - F_i))^0.6``, for
``sigma/Fc`` in {1, 2, 8} and ``F_i = -Fc x {0.2, 0.4, 0.6, 0.8, 1}``. ``Fc = 1 N`` (the
paper does not state it). Markers: the exact next reversal (Lambert-W map, on Omega), the
reversal given by the corrected (3.13) (on Omega*), and the second crossing of the two curves.
The paper requires Omega* to meet Omega at the next reversal; it does so only approximately
(see ``x_cross`` against ``x_exact`` in the returned numbers).
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


def secant_crossing(k: float) -> float:
    """Normalised abscissa ``y > 0`` where ``exp(-y) = 1 - k y`` (``0 < k < 1``)."""
    return brentq(lambda y: (np.expm1(-y) + k * y) / y, 1e-12, 1.0 / k, xtol=1e-15, rtol=1e-14)


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw Figure 4 into ``outdir/fig4_omega.png``.

    Returns
    -------
    dict
        ``amplitudes``; per ratio in ``panels[ratio]``: ``x`` [m], ``omega`` (Omega on x),
        ``omega_star`` (dict a -> Omega* on x), ``x_exact``, ``x_approx``, ``x_cross``
        (dict a -> abscissa [m] of the exact next reversal, of the corrected (3.13), and of the
        second intersection of Omega and Omega*), ``K`` (dict a -> slope [1/m]); ``png``.
    """
    fig, axes = new_figure(1, 3, size=(11.0, 4.2), sharey=True)
    panels: dict[float, dict] = {}
    for ax, ratio, tag in zip(axes[0], RATIOS, "abc"):
        sigma = ratio * FC
        a = np.asarray(AMPLITUDES)
        y_exact = -np.log1p(-np.asarray(dahl.next_amplitude(a), dtype=float))
        y_approx = -np.log1p(-np.asarray(dahl.next_amplitude_paper(a), dtype=float))
        x_exact = y_exact * FC / sigma
        x_approx = y_approx * FC / sigma
        x_max = 1.15 * float(np.max(x_exact))
        x = np.linspace(0.0, x_max, 60 if quick else 300)
        omega = np.asarray(dahl.omega(x, sigma, FC), dtype=float)
        ax.plot(x, omega, "k--", lw=1.6, label=r"$\Omega(x)$ (3.10)")
        stars, slopes, cross = {}, {}, {}
        for i, (color, ai) in enumerate(zip(COLORS, AMPLITUDES)):
            star = np.asarray(dahl.omega_star(x, -ai * FC, sigma, FC), dtype=float)
            stars[ai] = star
            slopes[ai] = float((star[0] - star[1]) / (x[1] - x[0]))
            cross[ai] = secant_crossing(slopes[ai] * FC / sigma) * FC / sigma
            ax.plot(x, star, color=color, lw=1.3, label=rf"$\Omega^*$, $F_i = -{ai:g}\,F_c$")
            ax.plot(x_exact[i], np.exp(-y_exact[i]), "o", color=color, ms=5, mfc="none")
            ax.plot(x_approx[i], 1.0 - slopes[ai] * x_approx[i], "x", color=color, ms=5)
        ax.set_title(rf"({tag}) $\sigma/F_c$ = {ratio:g} m$^{{-1}}$")
        ax.set_xlabel(r"distance from the force zero crossing $x$ [m]")
        ax.set_xlim(0.0, x_max)
        ax.grid(True, alpha=0.3)
        panels[ratio] = {
            "x": x, "omega": omega, "omega_star": stars, "K": slopes,
            "x_exact": dict(zip(AMPLITUDES, x_exact)), "x_approx": dict(zip(AMPLITUDES, x_approx)),
            "x_cross": cross,
        }
    axes[0, 0].set_ylabel(r"$\Omega$, $\Omega^*$ [-]")
    axes[0, 0].set_ylim(0.0, 1.02)
    axes[0, 2].legend(loc="upper right", fontsize=8)
    fig.suptitle(r"Fig. 4: $\Omega$ and its linear approximation $\Omega^*$ (3.11)")
    add_note(fig, f"Fc = {FC:g} N (not stated in the paper). o: exact next reversal (on Omega); "
                  "x: next reversal from the corrected (3.13) (on Omega*).")
    png = save(fig, outdir, "fig4_omega.png")
    return {"amplitudes": AMPLITUDES, "panels": panels, "Fc": FC, "png": png}


if __name__ == "__main__":
    print(main(sys.argv[1] if len(sys.argv) > 1 else ".")["png"])
