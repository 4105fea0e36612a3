"""Figure 2 of the paper drawn from a simulation: energy-balanced reversal points, (2.9).

The unforced oscillator (2.1) with Dahl friction (gamma = 1) starts at ``x = 0``, ``F = 0`` with
``v(0) < 0`` (as in the paper's sketch). Between its first reversal ``x_i`` (force ``F_i < 0``)
and its second ``x_{i+1}`` the restoring force first returns the stored energy as kinetic
energy (area ``Delta_1`` between the branch and ``f = 0`` from ``x_i`` to the force zero
crossing ``x_0``), then takes it back (area ``Delta_2`` from ``x_0`` to ``x_{i+1}``). (2.9) says
``Delta_1 = Delta_2``; both equal ``E_p(F_i)`` of (3.9). The grey dotted line is the linear
spring ``f = sigma (x - x_0)`` clipped at ``+-Fc`` (the stop operator, gamma = 0), which stores
without loss. The sketch in the paper has no numbers; we take ``m = 1 kg``, ``sigma = 1 N/m``,
``Fc = 1 N`` and ``v(0) = -0.8 m/s``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prefriction import Dahl, Oscillator, dahl, simulate
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 1.0  # [kg]
SIGMA = 1.0  # [N/m]
FC = 1.0  # [N]
V0 = -0.8  # [m/s], negative as in the paper's sketch
N_REVERSALS = 4


def split_areas(x: np.ndarray, F: np.ndarray) -> tuple[float, float, float]:
    """Zero crossing ``x_0`` and the areas ``Delta_1``, ``Delta_2`` of a monotone branch sample.

    ``Delta_1 = |int_{x_start}^{x_0} F dx|`` and ``Delta_2 = |int_{x_0}^{x_end} F dx|``
    (trapezoidal rule, with ``x_0`` found by linear interpolation and inserted as a node).
    """
    k = int(np.flatnonzero(np.sign(F[:-1]) != np.sign(F[1:]))[0])
    x0 = x[k] - F[k] * (x[k + 1] - x[k]) / (F[k + 1] - F[k])
    left_x, left_F = np.append(x[: k + 1], x0), np.append(F[: k + 1], 0.0)
    right_x, right_F = np.insert(x[k + 1 :], 0, x0), np.insert(F[k + 1 :], 0, 0.0)
    return float(x0), abs(float(np.trapezoid(left_F, left_x))), abs(float(np.trapezoid(right_F, right_x)))


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Simulate and draw Figure 2 into ``outdir/fig2_energy_balance.png``.

    Returns
    -------
    dict
        ``x``, ``F`` (the branch from reversal i to i+1, [m], [N]), ``x_i``, ``F_i``, ``x_next``,
        ``F_next``, ``x_0`` (force zero crossing [m]), ``delta_1``, ``delta_2`` (areas [J] from
        the sampled branch), ``work_1``, ``work_2`` (the two integrals of (2.9) from the
        integrated power [J]), ``E_p`` ((3.9) at ``F_i`` [J]); ``png``.
    """
    system = Oscillator(Dahl(sigma=SIGMA, Fc=FC), mass=MASS)
    rev = simulate(system, V0, reversals=N_REVERSALS).reversals
    grid = np.union1d(np.linspace(0.0, rev.t[-1], 800 if quick else 4000), rev.t)
    res = simulate(system, V0, reversals=N_REVERSALS, dense=grid)
    t, x, F, E_f = res.t, res.x, res.F, res.E_f
    t_i, t_next = rev.t[0], rev.t[1]
    sel = (t >= t_i) & (t <= t_next)
    xb = np.concatenate([[rev.x[0]], x[sel], [rev.x[1]]])
    Fb = np.concatenate([[rev.F[0]], F[sel], [rev.F[1]]])
    x_0, delta_1, delta_2 = split_areas(xb, Fb)
    t_0 = float(np.interp(0.0, F[sel], t[sel]))  # F increases monotonically on this branch
    work_1 = float(np.interp(t_0, t, E_f) - np.interp(t_i, t, E_f))
    work_2 = float(np.interp(t_next, t, E_f) - np.interp(t_0, t, E_f))
    E_p = float(dahl.potential_energy(rev.F[0], SIGMA, FC))

    fig, axes = new_figure(size=(7.0, 5.2))
    ax = axes[0, 0]
    ax.plot(x, F, color="0.75", lw=1.0, label=f"simulated trajectory, {N_REVERSALS} reversals")
    left = xb <= x_0
    ax.fill_between(np.append(xb[left], x_0), np.append(Fb[left], 0.0), 0.0, color=COLORS[0], alpha=0.35,
                    label=rf"$\Delta_1$ = {delta_1:.5f} J (returned as $E_k$)")
    right = xb >= x_0
    ax.fill_between(np.insert(xb[right], 0, x_0), np.insert(Fb[right], 0, 0.0), 0.0, color=COLORS[1],
                    alpha=0.35, label=rf"$\Delta_2$ = {delta_2:.5f} J (taken from $E_k$)")
    ax.plot(xb, Fb, "k-", lw=2.0, label=r"branch from $x_i$ to $x_{i+1}$")
    xs = np.linspace(x.min(), x.max(), 200)
    ax.plot(xs, np.clip(SIGMA * (xs - x_0), -FC, FC), ":", color="0.45", lw=1.5,
            label=r"linear spring $\sigma(x - x_0)$, clipped at $\pm F_c$")
    labels = ((rev.x[0], rev.F[0], "$x_i$", (8, -4)), (rev.x[1], rev.F[1], "$x_{i+1}$", (-24, -20)),
              (x_0, 0.0, "$x_0$", (6, -14)))
    for xx, ff, name, offset in labels:
        ax.plot(xx, ff, "ko", ms=5)
        ax.annotate(name, xy=(xx, ff), xytext=offset, textcoords="offset points")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("displacement $x$ [m]")
    ax.set_ylabel("restoring force $f[x]$ [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(rf"Fig. 2: energy-balanced reversal points, $E_p(F_i)$ (3.9) = {E_p:.5f} J")
    add_note(fig, f"Simulated, gamma = 1: m = {MASS:g} kg, sigma = {SIGMA:g} N/m, Fc = {FC:g} N, x(0) = 0, "
                  f"F(0) = 0, v(0) = {V0:g} m/s\n(the paper's sketch has no numbers). Areas by the trapezoidal "
                  "rule on the simulated samples.", lines=2)
    png = save(fig, outdir, "fig2_energy_balance.png")
    return {
        "x": xb, "F": Fb, "x_i": float(rev.x[0]), "F_i": float(rev.F[0]), "x_next": float(rev.x[1]),
        "F_next": float(rev.F[1]), "x_0": x_0, "delta_1": delta_1, "delta_2": delta_2,
        "work_1": work_1, "work_2": work_2, "E_p": E_p, "sigma": SIGMA, "Fc": FC, "png": png,
    }


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    print(main(outdir, quick=quick)["png"])
