"""Beyond the paper: the non-local memory of generalised Maxwell-slip (GMS) friction.

A mass of 25 g on GMS friction (:class:`prefriction.GMS`: six elements of equal stiffness with
slip deflections from 0.5 to 16 um, Stribeck curve from ``Fs = 1.2 N`` to ``Fc = 1 N``) is
driven by a slow piecewise-linear force ``u(t)`` (:class:`prefriction.signals.Samples`,
``|u'| = 2.5 N/s``). Two runs:

- *outer*: ``0 -> +A -> -A -> +A -> -A`` with ``A = 1 N``: the virgin curve and the outer loop;
- *nested*: ``0 -> +A -> -A``, then on the way back up reversals of decreasing amplitude
  ``0.8 A -> -0.6 A -> 0.5 A -> -0.3 A -> 0.3 A -> -0.1 A``, and finally ``-> +A -> -A``.

``gms_memory.png`` shows the friction force over the displacement: every inner loop closes at
the point where it began (*return-point memory*), and the path then continues on the branch it
had left, as if the inner loop had never happened; after ``+A`` the descending branch is the
outer one (*wiping-out*): the model remembers the reversal points, not the time history, and
forgets those that a larger excursion has erased. A second panel shows the input force.

The force is quasi-static but not rate-free: a micro-damping ``sigma_i = tau k_i``
(``tau = 2 sqrt(m / sigma)``, critical damping of the sticking mass, so every turn of the input
is one velocity reversal) adds ``sum_i sigma_i d_i' = tau (sum_i F_i)' = tau u'`` on every
branch (quasi-statically), a constant ``tau |u'|`` = 1.65 mN; inertia adds ``m x''`` at every
slip (at most 0.9 mN). The closure is measured at each re-entry point: the force there minus
the force at the reversal where the inner loop began, less the damping force ``tau |u'|``
(``closure`` in the returned dict: -0.74, -0.0001, -0.23 mN, against loop widths of 380, 143
and 37 mN). Run: ``python examples/gms_memory.py [outdir]`` (about 4 s once compiled).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import prefriction as pf
from prefriction.plotting import COLORS, add_note, new_figure, save

MASS = 0.025  # [kg]
N = 6
FC, FS, VS, C = 1.0, 1.2, 1e-2, 2e3  # [N], [N], [m/s], [N/s]
SLIP_DEFLECTIONS = 0.5e-6 * 2.0 ** np.arange(N)  # alpha_i Fs / k_i [m]: 0.5 .. 16 um
ALPHA = 2.0 ** np.arange(N) / (2.0**N - 1.0)  # 1/63 .. 32/63: equal stiffnesses k_i
K = ALPHA * FS / SLIP_DEFLECTIONS  # [N/m]
SIGMA = float(K.sum())
TAU = 2.0 * math.sqrt(MASS / SIGMA)  # [s]: critical damping of the sticking mass
RATE = 2.5  # |u'| [N/s]
A = 1.0  # outer amplitude [N]
OUTER = (0.0, A, -A, A, -A)
NESTED = (0.0, A, -A, 0.8 * A, -0.6 * A, 0.5 * A, -0.3 * A, 0.3 * A, -0.1 * A, A, -A)
INNER = (3, 5, 7)  # indices in NESTED of the turns where the inner loops begin (closing there)
LAST_ASCENT = 8  # index in NESTED of the turn that starts the final ascent to +A


def model() -> pf.GMS:
    """The GMS model of the figure."""
    return pf.GMS(K, ALPHA, Fc=FC, Fs=FS, vs=VS, C=C, damping=TAU * K)


def force_input(levels: tuple) -> pf.signals.Samples:
    """Piecewise-linear force through ``levels`` [N] at the constant rate ``RATE``."""
    lv = np.asarray(levels, dtype=float)
    t = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(lv)) / RATE)))
    return pf.signals.Samples(t, lv, name="u", unit="N")


def _run(levels: tuple, extra: np.ndarray = np.zeros(0), rtol: float = 1e-9) -> pf.SimulationResult:
    u = force_input(levels)
    times = np.union1d(np.linspace(0.0, u.t[-1], 6001), extra)
    return pf.simulate(pf.Oscillator(model(), mass=MASS, u=u), 0.0, t_end=float(u.t[-1]), rtol=rtol, dense=times)


def _crossing_times(res: pf.SimulationResult, t0: float, t1: float, x_levels: np.ndarray) -> np.ndarray:
    """Times in ``[t0, t1]`` (an ascending branch) where ``res.x`` first reaches each level."""
    on = (res.t >= t0) & (res.t <= t1)
    t, x = res.t[on], res.x[on]
    out = []
    for xl in x_levels:
        j = int(np.argmax(x >= xl))
        if x[j] < xl or j == 0:
            raise RuntimeError(f"the branch does not reach x = {xl!r} m between t = {t0!r} and {t1!r} s")
        out.append(t[j - 1] + (xl - x[j - 1]) / (x[j] - x[j - 1]) * (t[j] - t[j - 1]))
    return np.array(out)


def _force_at(res: pf.SimulationResult, t0: float, t1: float, x_level: float) -> float:
    """Force where the ascending branch in ``[t0, t1]`` passes ``x_level`` (linear in x between
    the fine samples around it)."""
    on = (res.t >= t0) & (res.t <= t1)
    x, F = res.x[on], res.F[on]
    j = int(np.argmax(x >= x_level))
    return float(F[j - 1] + (x_level - x[j - 1]) / (x[j] - x[j - 1]) * (F[j] - F[j - 1]))


def main(outdir: str | Path = ".", *, quick: bool = False) -> dict:
    """Draw ``outdir/gms_memory.png`` and measure how the inner loops close.

    Parameters
    ----------
    outdir : str or Path
        Output directory (created if needed).
    quick : bool, default False
        Accepted for the figure runner; the runs are short either way.

    Returns
    -------
    dict
        ``png`` (path); ``outer`` and ``nested`` (:class:`prefriction.SimulationResult`, SI);
        ``reentry``: per inner loop (beginning at the turns ``NESTED[3]``, ``[5]``, ``[7]``) the
        reversal ``x_r`` [m], ``F_r`` [N] where it began and the force ``F_back`` [N] where the
        final ascent passes ``x_r`` again; ``closure`` [N]: ``F_back - F_r - tau |u'|`` (the
        damping force removed, module notes); ``outer_gap``: the largest differences ``x`` [m]
        and ``F`` [N] between the nested and the outer run at equal input force, on the final
        ascent beyond the outermost re-entry point and on the descent from ``+A`` after it;
        ``damping_force`` ``tau |u'|`` [N]; ``inertia`` [N]: the largest ``|u - F| = m |x''|``
        on the final ascent (after its first 10 ms); ``loop_width`` [N]: per inner loop, the
        largest force difference between its ascending and descending branch at equal
        displacement (the size of the loop: what a loop that did not close would leave behind).
    """
    u_nested, u_outer = force_input(NESTED), force_input(OUTER)
    tk, to = u_nested.t, u_outer.t
    coarse = _run(NESTED)
    tab = coarse.reversals
    if len(tab.t) != len(NESTED) - 2:  # one velocity reversal per turn of the input
        raise RuntimeError(f"expected {len(NESTED) - 2} reversals, got {len(tab.t)}")
    # the reversal of input turn i (i >= 1) is row i - 1 of the table
    rev_x = np.array([tab.x[i - 1] for i in INNER])
    rev_F = np.array([tab.F[i - 1] for i in INNER])
    t_a, t_b = tk[LAST_ASCENT], tk[LAST_ASCENT + 1]
    t_back = _crossing_times(coarse, t_a + 1e-3, t_b, rev_x)
    # equal input levels on the final ascent beyond the outermost re-entry point and on the
    # descent from +A after it, in both runs
    lo = float(u_nested(t_back[0])) + 0.02 * A
    up = np.linspace(lo, 0.98 * A, 200)
    down = np.linspace(0.98 * A, -0.98 * A, 400)
    t_n = np.concatenate((t_a + (up - NESTED[LAST_ASCENT]) / RATE, t_b + (A - down) / RATE))
    t_o = np.concatenate((to[2] + (up + A) / RATE, to[3] + (A - down) / RATE))
    # the nested run again, sampled finely (1 us) around the re-entry points
    fine = np.concatenate([tb + np.linspace(-1e-3, 1e-3, 2001) for tb in t_back])
    nested = _run(NESTED, np.concatenate((fine, t_n)))
    outer = _run(OUTER, t_o)
    F_back = np.array([_force_at(nested, tb - 1e-3, tb + 1e-3, xr) for tb, xr in zip(t_back, rev_x)])
    damping_force = TAU * RATE
    closure = F_back - rev_F - damping_force
    i_n, i_o = np.searchsorted(nested.t, t_n), np.searchsorted(outer.t, t_o)
    assert np.allclose(nested.t[i_n], t_n, rtol=1e-14) and np.allclose(outer.t[i_o], t_o, rtol=1e-14)
    outer_gap = {"x": float(np.max(np.abs(nested.x[i_n] - outer.x[i_o]))),
                 "F": float(np.max(np.abs(nested.F[i_n] - outer.F[i_o])))}
    last = (nested.t > t_a + 1e-2) & (nested.t < t_b)
    inertia = float(np.max(np.abs(u_nested(nested.t[last]) - nested.F[last])))
    loop_width = []
    for j, i in enumerate(INNER):  # ascending branch of the loop above its descending branch
        down_j = (coarse.t > tab.t[i - 1] + 1e-3) & (coarse.t < tab.t[i])
        up_j = (coarse.t > tab.t[i] + 1e-3) & (coarse.t < (tab.t[i + 1] if j < 2 else t_back[j]))
        xd, Fd = coarse.x[down_j][::-1], coarse.F[down_j][::-1]
        loop_width.append(float(np.max(coarse.F[up_j] - np.interp(coarse.x[up_j], xd, Fd))))

    # ------------------------------------------------------------------ figure
    fig, axes = new_figure(1, 2, size=(12.5, 5.2))
    fig.get_layout_engine().set(w_pad=0.15)
    ax = axes[0, 0]
    um = 1e6
    ax.plot(outer.x * um, outer.F, color="0.72", lw=4.0, solid_capstyle="round",
            label=r"outer run: $u$ = 0 $\to +A \to -A \to +A \to -A$ ($A$ = 1 N)")
    # the nested run coloured by the innermost inner loop open at each time: each inner loop
    # is one closed curve, from its reversal back to the same point
    t_open = np.array([tab.t[i - 1] for i in INNER])
    bounds = [0.0, *t_open, *t_back[::-1], math.inf]
    which = [None, 0, 1, 2, 1, 0, None]
    labels = {None: "nested run", 0: "inner loop 1: turns at 0.8 A, -0.6 A",
              1: "inner loop 2: turns at 0.5 A, -0.3 A", 2: "inner loop 3: turns at 0.3 A, -0.1 A"}
    colors = {None: COLORS[0], 0: COLORS[1], 1: COLORS[2], 2: COLORS[3]}
    seen = set()
    for lo, hi, w in zip(bounds[:-1], bounds[1:], which):
        on = (nested.t >= lo) & (nested.t <= hi)
        lab = None if w in seen else labels[w]
        seen.add(w)
        ax.plot(nested.x[on] * um, nested.F[on], color=colors[w], lw=1.4, label=lab)
    ax.plot(rev_x * um, rev_F, "o", ms=8, mfc="none", mec="k", mew=1.3,
            label="where each inner loop begins and closes")
    ax.set_xlabel(r"displacement $x$ [$\mu$m]")
    ax.set_ylabel("friction force $F$ [N]")
    ax.set_title("GMS friction: nested inner loops close on the loop they left", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.95)
    xmax = float(np.max(np.abs(outer.x))) * um
    ax.set_xlim(-1.08 * xmax, 1.08 * xmax)
    ax.set_ylim(-1.12 * A, 1.6 * A)  # room for the legend above the loops

    ax = axes[0, 1]
    ts = np.linspace(0.0, tk[-1], 2001)
    ax.plot(ts, u_nested(ts), color=COLORS[0], lw=1.4, label="input force $u(t)$ of the nested run")
    ax.plot(tab.t, u_nested(tab.t), "o", color="k", ms=4, label="velocity reversals")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel("input force $u$ [N]")
    ax.set_title(r"input: reversals of decreasing amplitude, $|u'|$ = " + f"{RATE:g} N/s", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.set_ylim(-1.12 * A, 1.6 * A)
    ax.legend(loc="upper center", fontsize=8, framealpha=0.95, ncols=2)
    add_note(fig, (f"GMS: m = {MASS:g} kg, N = {N} elements of equal stiffness, alpha_i = 2^(i-1)/63, slip deflections "
                   f"alpha_i Fs / k_i = 0.5, 1, ..., 16 um (sigma = {SIGMA:.4g} N/m),\n"
                   f"Fc = {FC:g} N, Fs = {FS:g} N, vs = {VS:g} m/s, C = {C:g} N/s, micro-damping sigma_i = tau k_i "
                   f"(tau = {TAU * 1e3:.3g} ms, critical damping while all elements stick), u(0) = 0, x(0) = 0.\n"
                   f"Closure at the re-entry points (force there - force at the reversal - tau |u'|): "
                   + ", ".join(f"{c * 1e3:+.3f}" for c in closure) + " mN; "
                   f"largest inertial force m|x''| on the final ascent {inertia * 1e3:.2f} mN."), lines=3)
    png = save(fig, outdir, "gms_memory.png")
    return {"png": png, "outer": outer, "nested": nested, "reentry": {"x_r": rev_x, "F_r": rev_F, "F_back": F_back},
            "closure": closure, "outer_gap": outer_gap, "damping_force": damping_force, "inertia": inertia,
            "loop_width": np.array(loop_width)}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, quick = script_args(sys.argv[1:])
    out = main(outdir, quick=quick)
    join = ", ".join
    print(f"wrote {out['png']}")
    print(f"inner loops: closure {join(f'{c * 1e3:+.3g}' for c in out['closure'])} mN "
          f"(loop widths {join(f'{w * 1e3:.3g}' for w in out['loop_width'])} mN)")
    print(f"damping force tau|u'| {out['damping_force'] * 1e3:.3g} mN, largest inertial force "
          f"{out['inertia'] * 1e3:.3g} mN; nested vs outer run: {out['outer_gap']['F'] * 1e3:.3g} mN, "
          f"{out['outer_gap']['x'] * 1e9:.3g} nm")
