"""Run an exported plant (:func:`prefriction.export.plant_source`) under a sequence of held forces:
compiled with gcc, or its period Function in Python."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from prefriction._validation import check_count, check_finite, check_real_array
from prefriction.simulation.simulate import MAX_AMPLITUDE
from prefriction.units import Scales

from .plant import plant_initial_state
from .run import c_driver, compile_and_run
from .source import CSource

__all__ = ["PlantRun", "evaluate_plant", "run_plant_c"]

MAX_PERIODS = 10_000_000
"""Largest number of periods :func:`run_plant_c` and :func:`evaluate_plant` take."""

_DRIVER = c_driver(["NAME.h"], "  NAME_state s;", "atol(argv[3]) - 2", "n + 2", "4 * n", """\
    NAME_reset(&s, in[0], in[1]);
    for (i = 0; i < n; ++i) {
      out[4 * i + 3] = NAME_step(&s, in[2 + i]);
      out[4 * i] = s.x;
      out[4 * i + 1] = s.v;
      out[4 * i + 2] = s.F;
    }""")


@dataclass(frozen=True)
class PlantRun:
    """The stage under held forces, one row per period (the state at the period's end).

    Attributes
    ----------
    x, v, F : numpy.ndarray
        Position [m], velocity [m/s] and friction force [N] after each period.
    status : numpy.ndarray
        0 (integrated to the period's end), 1 (stopped after two reversals) or 2 (failed), per period.
    ns_per_step : float
        Least CPU time of the process per period over the rounds [ns] (NaN for :func:`evaluate_plant`).
    """

    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    status: np.ndarray
    ns_per_step: float

    def __repr__(self) -> str:
        return f"PlantRun({self.x.size} periods, {int(np.count_nonzero(self.status))} not completed, {self.ns_per_step:.4g} ns per period)"

    def summary(self) -> str:
        """One line: periods, incomplete ones, time per period, range of the position."""
        return (f"{self.x.size} periods ({int(np.count_nonzero(self.status))} not completed), {self.ns_per_step:.4g} ns "
                f"per period; x from {self.x.min():.6g} to {self.x.max():.6g} m")


def _args(source: Any, u: Any) -> tuple[CSource, np.ndarray]:
    if not isinstance(source, CSource) or source.kind != "plant":
        raise TypeError(f"source must be the CSource of prefriction.export.plant_source (kind 'plant'), got {source!r}")
    u = check_real_array("u", u, "N")
    if u.ndim != 1 or not 1 <= u.size <= MAX_PERIODS:
        raise ValueError(f"u must be a 1-d array of 1 to {MAX_PERIODS} forces [N], got shape {u.shape}")
    return source, u


def _start(source: CSource, x0: Any, v0: Any) -> tuple[float, float]:
    """``x0`` [m] and ``v0`` [m/s] checked: finite, at most :data:`~prefriction.simulation.simulate.MAX_AMPLITUDE`
    in the stage's units (``ValueError`` naming the argument)."""
    sc = Scales.of(source.model)
    out = []
    for name, value, unit, scale in (("x0", x0, "m", sc.x), ("v0", v0, "m/s", sc.v)):
        value = check_finite(name, value)
        if not abs(value) <= MAX_AMPLITUDE * scale:
            raise ValueError(f"{name} must satisfy |{name}| <= {MAX_AMPLITUDE * scale:.3g} {unit} ({MAX_AMPLITUDE:g} "
                             f"of the stage's units: its states stay in the double-precision range), got {value!r}")
        out.append(value)
    return out[0], out[1]


def run_plant_c(source: CSource, u: Any, x0: float = 0.0, v0: float = 0.0, *, rounds: int = 1,
                optimize: bool = True) -> PlantRun:
    """Compile the exported plant with a driver and hold each force ``u[k]`` [N] over period ``k``.

    Parameters
    ----------
    source : CSource
        What :func:`prefriction.export.plant_source` wrote.
    u : array_like
        Force [N] per period.
    x0, v0 : float, default 0.0
        Initial position [m] and velocity [m/s] (``<name>_reset``).
    rounds : int, default 1
        Passes (1 to 1000); the time per period is the least over them.
    optimize : bool, default True
        Compile with ``-O2`` (``False``: ``-O0``, faster to compile, the same numbers).

    Returns
    -------
    PlantRun
        The state after each period and the time per period.

    Raises
    ------
    FileNotFoundError
        If there is no ``gcc`` on the ``PATH``.
    RuntimeError
        If the code does not compile or the program fails.
    """
    source, u = _args(source, u)
    x0, v0 = _start(source, x0, v0)
    rounds = check_count("rounds", rounds, 1, 1000)
    data = np.concatenate([[x0, v0], u])
    out, ns = compile_and_run(source, _DRIVER, data, 4 * u.size, rounds, optimize)
    out = out.reshape(-1, 4)
    return PlantRun(out[:, 0], out[:, 1], out[:, 2], out[:, 3].astype(int), ns)


def evaluate_plant(source: CSource, u: Any, x0: float = 0.0, v0: float = 0.0) -> PlantRun:
    """The same as :func:`run_plant_c` from the period Function in Python (CasADi, ``mapaccum``).

    Parameters
    ----------
    source : CSource
        What :func:`prefriction.export.plant_source` wrote (its ``function`` and system).
    u : array_like
        Force [N] per period.
    x0, v0 : float, default 0.0
        Initial position [m] and velocity [m/s].

    Returns
    -------
    PlantRun
        The state after each period (``ns_per_step`` NaN).
    """
    source, u = _args(source, u)
    x0, v0 = _start(source, x0, v0)
    fun = source.function
    o = source.options
    w0 = plant_initial_state(source.model, o["Ts"], x0, v0, F0=o["F0"], rtol=o["rtol"], force_scale=o["force_scale"])
    run = fun.mapaccum("periods", u.size)
    _w, Y = run(ca.DM(w0), ca.DM(u).T, ca.DM(np.arange(u.size, dtype=float)).T)
    Y = np.asarray(Y, dtype=float)
    return PlantRun(Y[0], Y[1], Y[2], np.where(Y[4] > 0.5, 0, 1), float("nan"))
