"""The exported controller and the exported plant in one closed loop, compiled with gcc.

The loop of a hardware-in-the-loop test bench, all in C: at each sample the controller
(:func:`prefriction.export.controller_source`) reads the plant's position and returns the
force, which the plant (:func:`prefriction.export.plant_source`) holds over the period.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_count, check_real_array

from .run import c_driver, compile_and_run
from .source import CSource

__all__ = ["LoopRun", "run_loop_c"]

MAX_SAMPLES = 10_000_000
"""Largest number of samples :func:`run_loop_c` takes."""

_DRIVER = c_driver(["CTRL.h", "PLANT.h"], "  double u;\n  CTRL_state c;\n  PLANT_state p;", "(atol(argv[3]) - 5) / 3",
                   "3 * n + 5", "5 * n", """\
    CTRL_reset(&c);
    PLANT_reset(&p, in[0], 0.0);
    for (i = 0; i < n; ++i) {
      out[5 * i] = p.x;
      out[5 * i + 1] = p.v;
      out[5 * i + 2] = p.F;
      u = CTRL_update(&c, p.x, in[2 + 3 * i], in[2 + 3 * i + 3], in[3 + 3 * i], in[3 + 3 * i + 3]);
      out[5 * i + 3] = u;
      out[5 * i + 4] = i + 1 < n ? PLANT_step(&p, u) : 0;
    }""")


@dataclass(frozen=True)
class LoopRun:
    """The closed loop of an exported controller and plant, one row per sample instant ``k Ts``.

    Attributes
    ----------
    x, v, F : numpy.ndarray
        Position [m], velocity [m/s] and friction force [N] at ``t_k``.
    u : numpy.ndarray
        Force [N] the controller applied from ``t_k`` on.
    status : numpy.ndarray
        The plant's status of the period after ``t_k`` (0: complete; see :func:`prefriction.export.plant_source`).
    ns_per_sample : float
        Least CPU time of the process per sample (controller and plant) over the rounds [ns].
    """

    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    u: np.ndarray
    status: np.ndarray
    ns_per_sample: float

    def __repr__(self) -> str:
        return f"LoopRun({self.x.size} samples, {int(np.count_nonzero(self.status))} incomplete periods, {self.ns_per_sample:.4g} ns per sample)"

    def summary(self) -> str:
        """One line: samples, incomplete periods, time per sample, largest force."""
        return (f"{self.x.size} samples in C ({int(np.count_nonzero(self.status))} incomplete periods), "
                f"{self.ns_per_sample:.4g} ns per sample, max |u| = {np.max(np.abs(self.u)):.6g} N")


def run_loop_c(controller: CSource, plant: CSource, r: Any, v_ref: Any = None, x0: float = 0.0, *,
               rounds: int = 1, optimize: bool = True) -> LoopRun:
    """Compile the exported controller and plant with a loop driver and run them over the reference.

    Parameters
    ----------
    controller : CSource
        What :func:`prefriction.export.controller_source` wrote.
    plant : CSource
        What :func:`prefriction.export.plant_source` wrote (same ``Ts``).
    r : array_like
        Reference position [m] at the sample instants ``k Ts``, ``k = 0 .. n-1``.
    v_ref : array_like, optional
        Reference velocity [m/s] at the same instants (zeros if ``None``).
    x0 : float, default 0.0
        Initial position [m] of the stage (at rest).
    rounds : int, default 1
        Passes (1 to 1000); the time per sample is the least over them.
    optimize : bool, default True
        Compile with ``-O2`` (``False``: ``-O0``, faster to compile, the same numbers).

    Returns
    -------
    LoopRun
        The samples and the time per sample.

    Raises
    ------
    FileNotFoundError
        If there is no ``gcc`` on the ``PATH``.
    ValueError
        If the sample times differ or the reference arrays are malformed.
    """
    if not (isinstance(controller, CSource) and controller.kind == "controller"):
        raise TypeError(f"controller must be the CSource of prefriction.export.controller_source, got {controller!r}")
    if not (isinstance(plant, CSource) and plant.kind == "plant"):
        raise TypeError(f"plant must be the CSource of prefriction.export.plant_source, got {plant!r}")
    if controller.options["Ts"] != plant.options["Ts"]:
        raise ValueError(f"the controller's Ts = {controller.options['Ts']!r} s differs from the plant's "
                         f"Ts = {plant.options['Ts']!r} s")
    r = check_real_array("r", r, "m")
    if r.ndim != 1 or not 2 <= r.size <= MAX_SAMPLES:
        raise ValueError(f"r must be a 1-d array of 2 to {MAX_SAMPLES} reference positions [m], got shape {r.shape}")
    vr = np.zeros(r.size) if v_ref is None else check_real_array("v_ref", v_ref, "m/s")
    if vr.shape != r.shape:
        raise ValueError(f"v_ref must have the shape of r {r.shape}, got {vr.shape}")
    rounds = check_count("rounds", rounds, 1, 1000)
    n = r.size
    rows = np.zeros((n + 1, 3))
    rows[:n, 0], rows[:n, 1] = r, vr
    rows[n, :2] = r[-1], vr[-1]
    data = np.concatenate([[float(x0), 0.0], rows.ravel()])  # r, v_ref, unused; the last row repeats
    driver = _DRIVER.replace("CTRL", controller.name).replace("PLANT", plant.name)
    out, ns = compile_and_run([controller, plant], driver, data, 5 * n, rounds, optimize)
    out = out.reshape(-1, 5)
    return LoopRun(out[:, 0], out[:, 1], out[:, 2], out[:, 3], out[:, 4].astype(int), ns)
