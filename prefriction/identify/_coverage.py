"""Coverage of the 95 % intervals of :func:`prefriction.identify.fit` on seeded synthetic records.

Each case generates records from the equations, independently of the fitter, fits them from
start values 1.3 times the truth (the closed-loop case: its own start) and counts how often
each 95 % interval holds the true value:

- ``dahl-clean``: Dahl (3.2) with ``gamma = 2``, whose branch has the closed form
  ``w2 = w1 / (1 + w1 xi)`` in the gap ``w = 1 - s F / Fc`` and the distance
  ``xi = sigma |dx| / Fc`` (from ``dw/dxi = -w^2``), along a sinusoid with a drift, force
  noise 0.5 % of ``Fc``, a force offset, exact positions;
- ``dahl-encoder``: the same with the positions read by an encoder (steps of 10 nm after 3 nm of
  Gaussian noise; the grid shifted at random against the motion), declared as ``x_noise`` and
  ``quantum``; ``dahl-encoder-undeclared``: the same records with the noise not declared (what a
  fit without the errors-in-variables treatment reports);
- ``maxwell-encoder``: Maxwell-slip with two elements (each a stop operator
  ``z <- clip(z + k dx, -W, W)``), 100 nm steps after 30 nm of noise, declared;
- ``closed-loop-encoder``: an EMPS-like stage (95.1 kg, Dahl + viscous + offset, PD loop at
  1 kHz; :func:`prefriction.identify.synthetic_loop.closed_loop_record`, scipy LSODA between the
  samples) read by a 50 nm encoder after 100 nm of noise, a :class:`Motion` fit with the mass
  free (started at the values of ``tests/test_identify_closed_loop.py``);
- ``user-stage-dahl-closed``, ``user-stage-dahl-open``: the 2.5 kg / 5 kHz / 10 nm stage of
  :data:`prefriction.identify._success.GRID` (Dahl + viscous + offset, PID loop or a two-tone
  force), a :class:`Motion` fit with the mass free from 1.3 times the truth;
  ``user-stage-dahl-bare-open``, ``user-stage-lugre-bare-open``: the same stage in open loop
  with Dahl or LuGre (``Fs = Fc``: the fitted excess ``Fs - Fc`` on its bound 0) and neither a
  viscous term nor an offset;
- ``dahl-decay``: the free decay of the Dahl oscillator (2.1) (:func:`prefriction.identify.synthetic.dahl_free_decay`:
  DOP853 between the exact reversals), positions with Gaussian noise, a :class:`Motion` fit.

- ``loop-fit-pid-10nm``, ``loop-fit-pid-50nm``: the stage of ``examples/stage_workflow.py``
  (2.5 kg, Dahl ``sigma = 2e6`` N/m, ``Fc = 3`` N, offset 0.2 N) under a PID at 5 kHz, its
  encoder 10 or 50 nm after 2 nm of noise, declared; scipy DOP853 between the samples
  (:func:`prefriction.identify.synthetic_events.closed_loop_event_record`); the closed-loop
  route :func:`prefriction.identify.fit_closed_loop` from a start within a factor 2, the mass
  known.

``prefriction bench --identify`` prints the table; ``tests/test_identify_coverage.py`` runs a
short version.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["CASES", "CoverageRow", "coverage_table", "dahl2_force", "table_text"]


def dahl2_force(sigma: float, Fc: float, x: np.ndarray) -> np.ndarray:
    """Dahl force [N] with ``gamma = 2`` along ``x`` [m] (linear between samples), from zero force.

    Parameters
    ----------
    sigma : float
        Rest stiffness [N/m].
    Fc : float
        Coulomb force [N].
    x : numpy.ndarray
        Positions [m].
    """
    F = np.zeros(x.size)
    for k in range(1, x.size):
        dx = x[k] - x[k - 1]
        if dx == 0.0:
            F[k] = F[k - 1]
            continue
        s = 1.0 if dx > 0.0 else -1.0
        w1 = 1.0 - s * F[k - 1] / Fc
        w2 = w1 / (1.0 + w1 * sigma * abs(dx) / Fc)
        F[k] = s * Fc * (1.0 - w2)
    return F


def _encoder(x: np.ndarray, noise: float, quantum: float, rng: np.random.Generator) -> np.ndarray:
    shift = rng.uniform(0.0, quantum)
    return np.round((x + shift + noise * rng.standard_normal(x.size)) / quantum) * quantum - shift


def _dahl(encoder: bool, declared: bool = True) -> Callable:
    def make(rng: np.random.Generator, n: int) -> tuple:
        from prefriction.identify.data import ForceDisplacement
        from prefriction.models import Dahl

        t = np.linspace(0.0, 4.0, n)
        x = 3e-6 * np.sin(np.pi * t + 0.3) - 3e-6 * np.sin(0.3) + 0.2e-6 * t
        truth = {"sigma": 2e6, "Fc": 3.0, "offset": 0.2}
        F = dahl2_force(2e6, 3.0, x) + 0.2 + 0.015 * rng.standard_normal(n)
        if encoder:
            noise = {"x_noise": 3e-9, "quantum": 1e-8} if declared else {}
            data = ForceDisplacement(t, _encoder(x, 3e-9, 1e-8, rng), F, **noise)
        else:
            data = ForceDisplacement(t, x, F)
        start = Dahl(sigma=2.6e6, Fc=3.9, gamma=2.0)
        return data, start, truth, {"fixed": ["gamma"], "offset": True}
    return make


def _maxwell(rng: np.random.Generator, n: int) -> tuple:
    from prefriction.identify.data import ForceDisplacement
    from prefriction.identify.synthetic import maxwell_slip_force
    from prefriction.models import MaxwellSlip

    t = np.linspace(0.0, 2.0, n)
    x = 40e-6 * np.sin(2.0 * np.pi * t) * (0.25 + 0.75 * t / 2.0)
    true = MaxwellSlip([6e4, 2e4], [0.4, 0.6])
    F = maxwell_slip_force(true, x) + 0.003 * rng.standard_normal(n)
    data = ForceDisplacement(t, _encoder(x, 3e-8, 1e-7, rng), F, x_noise=3e-8, quantum=1e-7)
    truth = {"stiffness[0]": 6e4, "stiffness[1]": 2e4, "slip_force[0]": 0.4, "slip_force[1]": 0.6}
    return data, MaxwellSlip([7.8e4, 2.6e4], [0.52, 0.78]), truth, {}


def _decay(rng: np.random.Generator, n: int) -> tuple:
    from prefriction.identify.synthetic import dahl_free_decay
    from prefriction.models import Dahl

    true = Dahl(sigma=1.5e4, Fc=1.0, gamma=1.5)
    t = np.linspace(0.0, 0.2, n)
    data = dahl_free_decay(true, 1.0, 0.02, t, 2e-7, rng)
    truth = {"sigma": 1.5e4, "gamma": 1.5}
    return data, Dahl(sigma=1.9e4, Fc=1.0, gamma=1.9), truth, {"fixed": ["Fc"], "structures": "given"}


def _closed_loop(rng: np.random.Generator, n: int) -> tuple:
    from prefriction.identify.data import Motion
    from prefriction.identify.synthetic_loop import ClosedLoop, closed_loop_record
    from prefriction.models import Dahl, Viscous

    loop = ClosedLoop(Dahl(sigma=1.0e6, Fc=20.39), mass=95.1, b=203.5, offset=-3.16, quantum=5e-8, noise=1e-7)
    rec = closed_loop_record(loop, n, rng)
    truth = {"sigma": 1.0e6, "Fc": 20.39, "b": 203.5, "mass": 95.1, "offset": -3.16}
    start = Dahl(sigma=8e5, Fc=10.0) + Viscous(b=100.0)
    return Motion(rec.t, rec.x, rec.u, None), start, truth, {"fixed": ["gamma"], "mass0": 80.0,
                                                                        "offset": True}


def _loop_fit(quantum: float) -> Callable:
    """The 2.5 kg stage of ``examples/stage_workflow.py`` (Dahl, offset 0.2 N) under a PID at
    5 kHz on an encoder of step ``quantum`` after 2 nm of noise, declared
    (:func:`prefriction.identify.synthetic_events.closed_loop_event_record`), fitted by
    :func:`prefriction.identify.fit_closed_loop` from a start within a factor 2, the mass known."""
    def make(rng: np.random.Generator, n: int) -> tuple:
        from prefriction.identify.closed_loop_fit import fit_closed_loop
        from prefriction.identify.data import Motion
        from prefriction.identify.digital_loop import DigitalLoop
        from prefriction.identify.synthetic_events import closed_loop_event_record
        from prefriction.models import Dahl

        dt, gains = 2e-4, {"Kp": 7.5e6, "Ki": 5e9, "Kd": 7.5e3}
        t = np.arange(n) * dt
        r = 6e-6 * np.sin(2 * np.pi * 8 * t) * (0.55 - 0.45 * np.cos(2 * np.pi * t / 0.2))
        rec = closed_loop_event_record(Dahl(sigma=2e6, Fc=3.0), 2.5, dt, r, offset=0.2, quantum=quantum, noise=2e-9,
                                       rng=rng, rtol=1e-11, **gains)
        f = np.exp(rng.uniform(-np.log(2.0), np.log(2.0), 2))
        loop = DigitalLoop(dt, gains["Kp"], gains["Kd"], Ki=gains["Ki"])
        data = Motion(rec.t, rec.x, rec.u, 2.5, x_noise=2e-9, quantum=quantum)
        return data, Dahl(sigma=2e6 * f[0], Fc=3.0 * f[1]), {"sigma": 2e6, "Fc": 3.0, "offset": 0.2}, {
            "fixed": ["gamma"], "fitter": lambda m, d, **kw: fit_closed_loop(m, d, loop, r, **kw)}
    return make


def _stage(index: int) -> Callable:
    """A stage of :data:`prefriction.identify._success.GRID`: a scipy record (LSODA per sample,
    the encoder rounding after noise of a third of a step), a :class:`Motion` fit with the mass
    free from every free parameter 1.3 times the truth (the offset: the truth plus ``0.3 Fc``)."""
    def make(rng: np.random.Generator, n: int) -> tuple:
        from prefriction.identify._success import GRID, stage_record
        from prefriction.identify.parameters import _build, _entries

        stage = GRID[index]
        truth = stage.truth()
        model = stage.model()
        entries = [e for e in _entries(model) if e.field not in ("mass", "offset")]
        start = _build(model, entries, {e.name: e.value * (1.3 if e.name in stage.free else 1.0) for e in entries})
        kw = {"fixed": [e.name for e in entries if e.name not in stage.free], "mass0": 1.3 * stage.mass}
        if stage.fit_offset:
            kw.update(offset=True, offset0=stage.offset + 0.3 * stage.friction.Fc)
        return stage_record(stage, n, rng), start, truth, kw
    return make


CASES: dict[str, tuple[Callable, int]] = {
    "dahl-clean": (_dahl(False), 1200),
    "dahl-encoder": (_dahl(True), 1200),
    "dahl-encoder-undeclared": (_dahl(True, False), 1200),
    "maxwell-encoder": (_maxwell, 401),
    "dahl-decay": (_decay, 400),
    "closed-loop-encoder": (_closed_loop, 800),
    "user-stage-dahl-closed": (_stage(8), 1000),
    "user-stage-dahl-open": (_stage(9), 1000),
    "user-stage-dahl-bare-open": (_stage(11), 1000),
    "user-stage-lugre-bare-open": (_stage(15), 1000),
    "loop-fit-pid-10nm": (_loop_fit(1e-8), 1500),
    "loop-fit-pid-50nm": (_loop_fit(5e-8), 1500),
}
"""Case name: (record maker, samples)."""


@dataclass(frozen=True)
class CoverageRow:
    """One case: how often the 95 % intervals held the truth.

    ``within`` counts the runs whose every estimate lands within 2 % of its true value (the
    offset: within 2 % of the largest true force parameter), ``either`` the runs in which every
    parameter lands within 2 % or has an interval that holds its true value (the done-when of a
    force-displacement fit with quantised noisy positions)."""

    case: str
    runs: int
    samples: int
    held: dict
    z_mean: dict
    z_sd: dict
    median_time: float
    failures: int
    within: int = 0
    either: int = 0

    @property
    def pooled(self) -> float:
        """Fraction of all intervals (every parameter, every run) that held the truth."""
        return sum(self.held.values()) / max(len(self.held) * (self.runs - self.failures), 1)


def coverage_table(cases: tuple[str, ...] = tuple(CASES), runs: int = 40, seed: int = 0,
                   progress: Callable[[str], None] | None = None) -> list[CoverageRow]:
    """Fit ``runs`` seeded records of each case; count the intervals that hold the truth.

    Parameters
    ----------
    cases : tuple of str
        Names from :data:`CASES`.
    runs : int
        Records per case.
    seed : int
        Seed of the records.
    progress : callable, optional
        Called with one line per case.

    Returns
    -------
    list of CoverageRow
    """
    from prefriction.identify.fit import fit

    rows = []
    for name in cases:
        c = list(CASES).index(name)  # a case's records do not depend on which others run with it
        make, n = CASES[name]
        held: dict = {}
        zs: dict = {}
        times, failures, within, either = [], 0, 0, 0
        for j in range(runs):
            data, start, truth, kw = make(np.random.default_rng([seed, c, j]), n)
            fitter = kw.pop("fitter", fit)   # the closed-loop cases bring their route
            t0 = time.perf_counter()
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res = fitter(start, data, **kw)
            except Exception:  # noqa: BLE001 - a failed fit is counted, not raised
                failures += 1
                continue
            times.append(time.perf_counter() - t0)
            close_all = either_all = True
            for p, v in truth.items():
                lo, hi = res.interval(p)
                hit = lo <= v <= hi
                held[p] = held.get(p, 0) + int(hit)
                zs.setdefault(p, []).append((res.estimate(p) - v) / res.stderr[res.names.index(p)])
                close = abs(res.estimate(p) - v) <= 0.02 * (abs(v) if p != "offset" else _force_scale(truth))
                close_all &= close
                either_all &= close or hit
            within += close_all
            either += either_all
        row = CoverageRow(name, runs, n, held, {p: float(np.mean(z)) for p, z in zs.items()},
                          {p: float(np.std(z)) for p, z in zs.items()},
                          float(np.median(times)) if times else float("nan"), failures, within, either)
        rows.append(row)
        if progress is not None:
            progress(f"coverage {name}: {row.pooled:.0%} of the intervals held the truth in {runs} runs")
    return rows


def _force_scale(truth: dict) -> float:
    """The scale of an offset's error: the largest true force parameter [N]."""
    forces = [abs(v) for p, v in truth.items() if p in ("Fc", "Fs") or p.startswith("slip_force")]
    return max(forces) if forces else 1.0


def table_text(rows: list[CoverageRow]) -> str:
    """The rows as a Markdown table: coverage per parameter, with the mean and standard deviation of
    ``z = (estimate - truth) / stderr`` (an honest interval: mean 0, sd 1)."""
    lines = ["| case | samples | runs | coverage per parameter (mean, sd of z) | pooled | all within 2 % | "
             "each within 2 % or held | median fit [s] |",
             "|---|---:|---:|---|---:|---:|---:|---:|"]
    for r in rows:
        done = r.runs - r.failures
        per = ", ".join(f"{p} {r.held[p] / max(done, 1):.0%} ({r.z_mean[p]:+.2f}, {r.z_sd[p]:.2f})" for p in r.held)
        fail = f" ({r.failures} failed)" if r.failures else ""
        lines.append(f"| {r.case} | {r.samples} | {r.runs}{fail} | {per} | {r.pooled:.0%} | {r.within / max(done, 1):.0%} "
                     f"| {r.either / max(done, 1):.0%} | {r.median_time:.2f} |")
    return "\n".join(lines)
