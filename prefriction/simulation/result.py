"""Results of :func:`prefriction.simulate`: run statistics and the simulation result."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from prefriction.reversals import ReversalTable

__all__ = ["RunStats", "SimulationResult"]


@dataclass(frozen=True)
class RunStats:
    """Run statistics of one :func:`simulate` call.

    Attributes
    ----------
    wall_time : float
        Wall time of the integration loop [s], without building or compiling the integrator.
    setup_time : float
        Wall time spent building, compiling or loading the integrator [s] (0 when reused).
    calls : int
        Number of calls into compiled code (the native driver of unforced runs: one per 65,536
        reversals; a CasADi integrator: one per reversal or output interval).
    steps : int or None
        Number of accepted Runge-Kutta steps (None for compiled CasADi integrators, which keep
        no statistics; counted by the native driver and by interpreted integrators).
    jit : str
        ``"compiled"``, ``"cached"`` (compiled code loaded from disk or memory) or ``"interpreted"``.
    events : int or None
        Model events located in the whole run (element slips, Dahl's saturation; see
        :attr:`SimulationResult.events`), including those after the last reversal; None if
        the run does not count them.
    """

    wall_time: float
    setup_time: float
    calls: int
    steps: Optional[int]
    jit: str
    events: Optional[int] = None


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Result of :func:`simulate`, in SI units.

    Attributes
    ----------
    reversals : ReversalTable
        States at the velocity reversals, in the form of :func:`prefriction.exact_reversals`.
        For a forced system ``E_d[k] = E_p[k-1] + W_u[k] - E_p[k]``.
    status : int
        As scipy's ``OdeResult``: ``0`` the run reached ``t_end``, ``1`` a termination event:
        the requested number of reversals. (A failure raises :class:`prefriction.SolverError`.)
    message : str
        What ended the run, in words.
    stats : RunStats
        Wall time, integrator calls and steps.
    work_input : numpy.ndarray
        Work of the external and feedback forces [J] over each half-cycle ending at a reversal
        (zeros for the unforced system).
    t, x, v, F : numpy.ndarray or None
        Samples [s, m, m/s, N] at the requested times (``dense``); None if not requested.
    E_k, E_f : numpy.ndarray or None
        Kinetic energy ``m v^2 / 2`` [J] and the work of the friction force
        ``E_f = int_0^t F v dt`` [J] by integrated power (2.8), at the sample times.
    u : numpy.ndarray or None
        Total applied force (input plus feedback) [N] at the sample times.
    xc : numpy.ndarray or None
        Controller states at the sample times, shape ``(len(t), n)`` (feedback only).
    events : numpy.ndarray or None
        Model events located on the half-cycle that ends at each reversal (int, aligned with
        ``reversals``): each event counts the flags it changes, e.g. the elements of
        Maxwell-slip or GMS that start to slip (two at once count 2), or Dahl's saturation
        for gamma < 1. An element that only touches its limit at a reversal (within ``rtol``,
        the model's ``snap``) may be counted or taken as coinciding with the reversal. The total,
        with the events after the last reversal, is ``stats.events``. None if the run does not
        count them (``docs/simulator.md#event-counts``).
    """

    reversals: ReversalTable
    status: int
    message: str
    stats: RunStats
    work_input: np.ndarray
    t: Optional[np.ndarray] = None
    x: Optional[np.ndarray] = None
    v: Optional[np.ndarray] = None
    F: Optional[np.ndarray] = None
    E_k: Optional[np.ndarray] = None
    E_f: Optional[np.ndarray] = None
    u: Optional[np.ndarray] = None
    xc: Optional[np.ndarray] = None
    events: Optional[np.ndarray] = None

    @property
    def success(self) -> bool:
        """True: a result is only returned for a run that reached its end (as ``OdeResult.success``)."""
        return self.status >= 0

    def summary(self) -> str:
        """A few lines: what ended the run, the reversals, the samples and the run statistics."""
        tab = self.reversals
        lines = [f"simulation: {self.message} (status {self.status})",
                 f"reversals: {len(tab)}" + (f", last at t = {tab.t[-1]:.9g} s, x = {tab.x[-1]:.6g} m, "
                                              f"F = {tab.F[-1]:.6g} N" if len(tab) else "")]
        if self.t is not None:
            lines.append(f"samples: {len(self.t)} in [{self.t[0]:.6g}, {self.t[-1]:.6g}] s")
        st = self.stats
        if st.events:
            lines.append(f"model events: {st.events} (per half-cycle: events)")
        lines.append(f"run: {st.wall_time * 1e3:.3g} ms in {st.calls} integrator calls ({st.jit}), "
                     f"setup {st.setup_time:.3g} s")
        return "\n".join(lines)

    def __repr__(self) -> str:
        samples = "" if self.t is None else f", {len(self.t)} samples"
        return (f"SimulationResult({len(self.reversals)} reversals{samples}, status {self.status}: "
                f"{self.message}, {self.stats.wall_time * 1e3:.3g} ms, jit {self.stats.jit})")

    __str__ = summary

    def plot(self, path: "str | Path" = "simulation.png") -> "Path":
        """The position against time and the friction loop (dense runs), the force at the reversals against their number, saved to ``path``.

        Parameters
        ----------
        path : str or Path, default "simulation.png"
            Image file to write (the format from the suffix).

        Returns
        -------
        Path
            The file written.
        """
        from prefriction._result_plots import plot_simulation

        return plot_simulation(self, path)
