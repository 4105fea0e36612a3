"""Describing functions against simulated limit cycles: Dahl and LuGre under PID control.

Mass 1 kg, ``LuGre(1e5, 1e5**0.5, 0.4, 1, 1.5, 1e-3)`` and ``Dahl(1e5, 1)``
(``docs/describing.md#hunting``, ``#unstable-loop``). Friction is treated as a nonlinearity of the
velocity: ``v = -G(s) F`` with ``G(s) = s / (m s^2 + C(s))``. Figure ``hunting_df.png``:

(a) the hunting PID ``(kp, ki, kd) = (100, 300, 5)`` (linear loop stable), step to 10 mm: Dahl
    converges, LuGre hunts (stick-slip);
(b) its Nyquist plane: ``G(i omega)`` never meets ``-1/N_v`` of the LuGre friction, and the
    simulated hunting cycle sits at ``G(i omega_h)`` (its first harmonics obey the linear part),
    a point that needs negative equivalent stiffness, which friction under a sinusoidal
    velocity never has;
(c) the PID ``(100, 300, 1)`` (linear loop unstable): ``-1/N_v`` of LuGre at the balance
    frequency crosses ``G(i omega)``; the predicted (unstable) cycle and the simulated one
    (bisection between decaying and growing runs) are marked;
(d) runs started 1e-4 either side of the boundary ``lambda*`` found by bisection: they linger
    on the cycle for about 15 periods, then one decays into stick-slip and the other grows.

Run from the repository root: ``python examples/hunting.py [outdir]``.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from prefriction import controllers  # noqa: E402
import prefriction as pf  # noqa: E402
from prefriction.describing import (  # noqa: E402
    VelocityDescribingFunction,
    measure_limit_cycle,
    predict_limit_cycle,
    simulate_from_cycle,
    trace_unstable_cycle,
    velocity_loop,
)

HUNTING = controllers.PID(kp=100.0, ki=300.0, kd=5.0)
UNSTABLE = controllers.PID(kp=100.0, ki=300.0, kd=1.0)
LUGRE = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
DAHL = pf.Oscillator(pf.Dahl(1e5, 1.0), mass=1.0)
R = 0.01
DF = {"method": "LSODA", "rtol": 1e-8, "tol": 1e-6}


def _harmonic(t: np.ndarray, y: np.ndarray, a: float, b: float) -> complex:
    sel = (t >= a) & (t <= b)
    w = 2.0 * math.pi / (b - a)
    ts, ys = t[sel], y[sel]
    return 2.0 / (b - a) * complex(np.trapezoid(ys * np.sin(w * ts), ts), np.trapezoid(ys * np.cos(w * ts), ts))


def _nyquist(ax: plt.Axes, G, lim: tuple) -> None:
    om = np.logspace(-2, 4, 4000)
    Gw = np.array([complex(G(1j * v)) for v in om])
    ax.plot(Gw.real, Gw.imag, color="C0", label=r"$G(i\omega) = i\omega\,/\,(m (i\omega)^2 + C(i\omega))$")
    ax.axhline(0, color="k", lw=0.4)
    ax.axvline(0, color="k", lw=0.4)
    ax.set(xlabel="Re [m/(N s)]", ylabel="Im [m/(N s)]", xlim=lim[:2], ylim=lim[2:])


def main(outdir: str | Path = ".", *, t_end: float = 24.0, steps: int = 30) -> dict:
    """Simulate, predict, trace; draw ``hunting_df.png``; return the numbers."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t = np.linspace(0.0, t_end, int(1000 * t_end) + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lug = controllers.simulate_loop(LUGRE, HUNTING, R, t_end, t_out=t)
        dah = controllers.simulate_loop(DAHL, HUNTING, R, t_end, t_out=t)
    hunt = measure_limit_cycle(lug.t, lug.x, t_start=t_end / 4)
    wh = 2.0 * math.pi / hunt.period
    up = np.nonzero((lug.x[:-1] < hunt.mean) & (lug.x[1:] >= hunt.mean) & (lug.t[1:] > t_end / 4))[0]
    a, b = lug.t[up[-2]], lug.t[up[-1]]
    N_eff = _harmonic(lug.t, lug.F, a, b) / _harmonic(lug.t, lug.v, a, b)
    print(hunt.summary(), file=sys.stderr)

    G_u = velocity_loop(LUGRE, UNSTABLE)
    cyc = predict_limit_cycle(G_u, VelocityDescribingFunction(LUGRE, 10.0, **DF), np.logspace(-1.5, 1, 11), omega=10.0)
    print(cyc.summary(), file=sys.stderr)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = trace_unstable_cycle(LUGRE, UNSTABLE, cyc, steps=steps, periods=40)
    print(tr.summary(), file=sys.stderr)

    fig, ax = plt.subplots(2, 2, figsize=(13, 9.5))
    ax[0, 0].plot(dah.t, 1e3 * dah.x, label="Dahl: converges")
    ax[0, 0].plot(lug.t, 1e3 * lug.x, label=f"LuGre: hunts, period {hunt.period:.3f} s")
    ax[0, 0].axhline(1e3 * R, color="k", lw=0.6, ls=":")
    ax[0, 0].set(xlabel="time t [s]", ylabel="position x [mm]",
                 title="(a) PID (100, 300, 5), linear loop stable: step to 10 mm")
    ax[0, 0].legend(loc="lower right")

    G_h = velocity_loop(LUGRE, HUNTING)
    _nyquist(ax[0, 1], G_h, (-0.035, 0.035, -0.035, 0.035))
    Av = np.logspace(-4, 0, 9)
    Nh = np.array([VelocityDescribingFunction(LUGRE, wh, **DF).describing_function(v) for v in Av])
    ax[0, 1].plot((-1 / Nh).real, (-1 / Nh).imag, "o-", ms=3, color="C1",
                  label=rf"$-1/N_v(A_v)$, LuGre at {wh:.2f} rad/s, $A_v$ = 0.1 mm/s ... 1 m/s")
    Gh = complex(G_h(1j * wh))
    ax[0, 1].plot(Gh.real, Gh.imag, "*", ms=13, color="C3",
                  label=rf"simulated hunting: $-V_1/F_1 = G(i\,{wh:.2f})$, stiffness {-wh * N_eff.imag:.0f} N/m")
    ax[0, 1].set_title("(b) hunting: no intersection (friction would need k < 0)")
    ax[0, 1].legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8)  # below: the curve fills the axes

    _nyquist(ax[1, 0], G_u, (-0.9, 0.3, -0.6, 0.6))
    Au = np.logspace(-1, 0.7, 12)
    Nu = np.array([VelocityDescribingFunction(LUGRE, cyc.omega, **DF).describing_function(v) for v in Au])
    ax[1, 0].plot((-1 / Nu).real, (-1 / Nu).imag, "o-", ms=3, color="C1",
                  label=rf"$-1/N_v(A_v)$, LuGre at {cyc.omega:.3f} rad/s, $A_v$ = 0.1 ... 5 m/s (left: larger)")
    p = -1 / cyc.N
    ax[1, 0].plot(p.real, p.imag, "s", ms=14, mfc="none", mew=1.5, color="C3",
                  label=rf"predicted (unstable): $A_v$ = {cyc.amplitude:.4f} m/s, $T$ = {cyc.period:.4f} s")
    Ns = VelocityDescribingFunction(LUGRE, 2 * math.pi / tr.period, **DF).describing_function(tr.amplitude)
    q = -1 / Ns
    ax[1, 0].plot(q.real, q.imag, "x", ms=10, mew=2, color="k",
                  label=rf"simulated: $A_v$ = {tr.amplitude:.4f} m/s, $T$ = {tr.period:.4f} s ($-1/N_v$ there)")
    ax[1, 0].set_title("(c) PID (100, 300, 1), linear loop unstable")
    ax[1, 0].legend(loc="upper left", fontsize=8)

    for lam, color, what in ((tr.scale * (1 - 1e-4), "C2", "decays (stick-slip)"),
                             (tr.scale * (1 + 1e-4), "C3", "grows")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = simulate_from_cycle(LUGRE, UNSTABLE, cyc, lam, periods=22)
        ax[1, 1].plot(r.t, r.v, lw=0.6, color=color, label=rf"$\lambda^* {'-' if color == 'C2' else '+'} 10^{{-4}}$: {what}")
    for s in (1, -1):
        ax[1, 1].axhline(s * tr.amplitude, color="k", ls="--", lw=0.8,
                         label=r"simulated cycle: $\pm V_1$" if s == 1 else None)
        ax[1, 1].axhline(s * cyc.amplitude, color="C1", ls=":", lw=1.2,
                         label=r"predicted: $\pm A_v$" if s == 1 else None)
    ax[1, 1].set(xlabel="time $t$ [s]", ylabel="velocity $v$ [m/s]", ylim=(-3.0, 4.6),
                 title=rf"(d) runs from $\lambda\,\times$ predicted sinusoid, $\lambda^*$ = {tr.scale:.8f}")
    ax[1, 1].legend(loc="upper center", fontsize=8, ncol=2)
    fig.tight_layout()
    png = outdir / "hunting_df.png"
    fig.savefig(png, dpi=100)
    plt.close(fig)
    e_amp, e_T = tr.errors()
    return {"hunting": hunt, "N_eff": N_eff, "predicted": cyc, "traced": tr, "amplitude_error": e_amp,
            "period_error": e_T, "pngs": [png]}


if __name__ == "__main__":
    from prefriction.plotting import script_args

    outdir, _ = script_args(sys.argv[1:], allow_quick=False)
    out = main(outdir)
    print(out["hunting"].summary())
    print(f"hunting cycle's F1/V1 = {out['N_eff']:.4g} N s/m (damping {out['N_eff'].real:.4g} N s/m, "
          f"stiffness {-2 * math.pi / out['hunting'].period * out['N_eff'].imag:.4g} N/m)")
    print(out["predicted"].summary())
    print(out["traced"].summary())
    print(f"prediction errors: amplitude {100 * out['amplitude_error']:+.2f} %, period {100 * out['period_error']:+.2f} %")
