"""Describing functions against simulated limit cycles: Dahl and LuGre under the same PID.

Loop: mass 1 kg, ``controllers.PID(kp=100, ki=300, kd=5)``, step to 10 mm
(``docs/describing.md#hunting``). Figure ``hunting_df.png``:

(a) position of the Dahl loop (``sigma = 1e5 N/m``, ``Fc = 1 N``; converges) and of the LuGre
    loop (``LuGre(1e5, 1e5**0.5, 0.4, 1, 1.5, 1e-3)``; hunts);
(b) Nyquist plane: ``H(i omega) = 1 / (m (i omega)^2 + C(i omega))`` against ``-1/N(A)`` of the
    Dahl friction (closed form) and of the LuGre friction at the hunting frequency: no
    intersection for either;
(c) the DF of the mass with LuGre friction (force in, position out) at the hunting frequency
    against the force amplitude: it jumps at breakaway over ``1 / |C(i omega)|``; the simulated
    peak control force lies at the jump.
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

import controllers  # noqa: E402
import prefriction as pf  # noqa: E402
from prefriction.describing import (  # noqa: E402
    FrictionDescribingFunction,
    dahl_describing_function,
    friction_loop,
    measure_limit_cycle,
    plant_describing_function,
)

PID = controllers.PID(kp=100.0, ki=300.0, kd=5.0)
LUGRE = pf.Oscillator(pf.LuGre(1e5, 1e5 ** 0.5, 0.4, 1.0, 1.5, 1e-3), mass=1.0)
DAHL = pf.Oscillator(pf.Dahl(1e5, 1.0), mass=1.0)
R = 0.01


def main(outdir: str | Path = ".", *, t_end: float = 24.0) -> dict:
    """Simulate both loops, evaluate the describing functions, draw ``hunting_df.png``."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t = np.linspace(0.0, t_end, int(1000 * t_end) + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lug = controllers.simulate_loop(LUGRE, PID, R, t_end, t_out=t)
        dah = controllers.simulate_loop(DAHL, PID, R, t_end, t_out=t)
    cyc = measure_limit_cycle(lug.t, lug.x, t_start=t_end / 4)
    ucyc = measure_limit_cycle(lug.t, lug.u, t_start=t_end / 4)
    w = 2.0 * math.pi / cyc.period
    print(cyc.summary(), file=sys.stderr)
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    ax[0].plot(dah.t, 1e3 * dah.x, label="Dahl: converges")
    ax[0].plot(lug.t, 1e3 * lug.x, label=f"LuGre: hunts, period {cyc.period:.3f} s")
    ax[0].axhline(1e3 * R, color="k", lw=0.6, ls=":")
    ax[0].set(xlabel="time t [s]", ylabel="position x [mm]", title="(a) PID loops, step to 10 mm")
    ax[0].legend(loc="lower right")
    H = friction_loop(LUGRE, PID)
    om = np.logspace(-2, 4, 2000)
    Hw = np.array([complex(H(1j * v)) for v in om])
    A = np.logspace(-7, -1, 200)
    Nd = dahl_describing_function(A, 1e5, 1.0)
    Al = np.logspace(-5, -2, 7)
    Nl = np.array([FrictionDescribingFunction(LUGRE, w, method="LSODA").describing_function(a) for a in Al])
    ax[1].plot(Hw.real, Hw.imag, label="H(i omega) = 1/(m (i omega)^2 + C(i omega))")
    ax[1].plot((-1 / Nd).real, (-1 / Nd).imag, label="-1/N(A), Dahl (closed form)")
    ax[1].plot((-1 / Nl).real, (-1 / Nl).imag, "o-", ms=3, label=f"-1/N(A), LuGre friction at {w:.2f} rad/s")
    ax[1].set(xlabel="Re [m/N]", ylabel="Im [m/N]", title="(b) friction block: no intersection",
              xlim=(-0.012, 0.012), ylim=(-0.012, 0.012))
    ax[1].axhline(0, color="k", lw=0.4)
    ax[1].axvline(0, color="k", lw=0.4)
    ax[1].legend(loc="lower left", fontsize=8)
    U = np.linspace(1.44, 1.52, 17)  # above ~1.52 N the free slide is too stiff for the explicit plant
    Np = np.array([plant_describing_function(LUGRE, u, w) for u in U])
    C = complex(PID.tf()(1j * w))
    ax[2].semilogy(U, np.abs(Np), "o-", ms=3, label="|N(U)|: mass + LuGre, force in, x out")
    ax[2].axhline(1.0 / abs(C), color="C1", label="1/|C(i omega)| (balance)")
    ax[2].axvline(ucyc.half_range + ucyc.mean, color="C2", ls="--", label=f"simulated peak force {ucyc.half_range + ucyc.mean:.3f} N")
    ax[2].set(xlabel="force amplitude U [N]", ylabel="|N| [m/N]", title=f"(c) plant block at {w:.2f} rad/s")
    ax[2].legend(loc="center right", fontsize=8)
    fig.tight_layout()
    png = outdir / "hunting_df.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    jump = U[np.argmax(np.abs(Np) > 1e-3)]
    return {"cycle": cyc, "force_cycle": ucyc, "breakaway_amplitude": float(jump), "pngs": [png]}


if __name__ == "__main__":
    out = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    print(out["cycle"].summary())
    print(f"plant DF jumps at U = {out['breakaway_amplitude']:.4f} N; simulated peak force "
          f"{out['force_cycle'].half_range + out['force_cycle'].mean:.4f} N")
