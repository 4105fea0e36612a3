"""The friction stage of ``examples/stage_*.py`` and of the benchmark, and its step-response runs (SI).

Stage values: m = 1 kg, sigma = 1e6 N/m, Fc = 1 N, Dahl gamma = 1. They are round numbers of
the order found for small ball-screw / linear-guide stages in the pre-sliding literature: a
moving mass of about a kilogram, a Coulomb force of about a newton, and a pre-sliding range
Fc/sigma = 1 um (rolling contacts show micrometre-scale pre-sliding displacements, see e.g. the
survey of Armstrong-Helouvry, Dupont and Canudas de Wit, Automatica 30 (1994) 1083-1138).
They are chosen, not fitted to a particular machine. The examples sample at 10 kHz.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import prefriction

from ._margins import margins
from ._loop import simulate_loop
from ._pid import PID
from .plotting import plot_steps

M, SIGMA, FC = 1.0, 1e6, 1.0  # kg, N/m, N
TS = 1e-4  # s (10 kHz)
STEPS = ((1e-6, "1 µm"), (1e-8, "10 nm"))  # m: one pre-sliding range, and 1 % of it


def stage() -> prefriction.Oscillator:
    """The example stage: ``m = 1 kg``, Dahl friction ``sigma = 1e6 N/m``, ``Fc = 1 N``, gamma = 1."""
    return prefriction.Oscillator(prefriction.Dahl(sigma=SIGMA, Fc=FC), mass=M)


def title(controller: PID, note: str = "") -> str:
    """Figure title: the controller, the sample time (and ``note``), the stage values."""
    return f"{controller}, Ts = {TS:g} s{note}; stage m = {M:g} kg, sigma = {SIGMA:g} N/m, Fc = {FC:g} N (Dahl)"


def step_responses(design: PID, t_end: float, path: "str | Path", *, bound: Optional[float] = None) -> dict[str, Any]:
    """Run the :data:`STEPS` with ``design`` discretised (ZOH, :data:`TS`), plot them, return the numbers.

    Parameters
    ----------
    design : controllers.PID
        Continuous controller for the example stage (without a force limit).
    t_end : float
        Length of each run [s].
    path : str or Path
        PNG file written by :func:`controllers.plotting.plot_steps`.
    bound : float, optional
        Error level [m] drawn in the error panels (default each loop's ``Fc/kp``, PD only).

    Returns
    -------
    dict
        ``path``, ``Ts`` [s], ``m`` [kg], ``sigma`` [N/m], ``Fc`` [N], ``phase_margin`` [deg],
        ``gain_margin`` and ``steps``: per step label the samples ``t, reference, x, u, F, error``
        (SI), ``step``, ``residual_error``, ``bound`` (``Fc/kp`` of a PD loop, else ``None``),
        ``settling_time``, ``reversals`` and the reversal positions and forces.
    """
    system = stage()
    Cd = design.c2d(TS)
    mg = margins(system, Cd)
    results = {f"step {label}": simulate_loop(system, Cd, r, t_end) for r, label in STEPS}
    path = plot_steps(results, path, bound=bound, title=title(design))
    steps = {}
    for (r, label), res in zip(STEPS, results.values()):
        steps[label] = {
            "step": r, "t": res.t, "reference": res.reference, "x": res.x, "u": res.u, "F": res.F,
            "error": res.error, "residual_error": res.residual_error, "bound": res.error_bound,
            "settling_time": res.settling_time, "reversals": len(res.reversals),
            "reversal_x": res.reversals.x, "reversal_F": res.reversals.F,
        }
    return {
        "path": path, "Ts": TS, "m": M, "sigma": SIGMA, "Fc": FC, "phase_margin": mg.phase_margin,
        "gain_margin": mg.gain_margin, "steps": steps,
    }


def report(out: dict[str, Any]) -> str:
    """Readable lines for the result of an example's ``main``: gains, margins, each step's residual error."""
    kp = out["kp"]
    gains = f"kp = {kp:.4g} N/m" + (f", ki = {out['ki']:.4g} N/(m s)" if "ki" in out else "")
    lines = [f"wrote {out['path']}; {gains}, Fc/kp = {FC / kp:.4g} m, phase margin {out['phase_margin']:.3g} deg, "
             f"gain margin {out['gain_margin']:.3g}"]
    for label, s in out["steps"].items():
        lines.append(f"  step {label}: residual error {s['residual_error']:.4g} m (|e| kp/Fc = "
                     f"{abs(s['residual_error']) * kp / FC:.3g}), settling {s['settling_time'] * 1e3:.3g} ms, "
                     f"{s['reversals']} reversals")
    return "\n".join(lines)
