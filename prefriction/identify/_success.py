"""Success rate of :class:`Motion` fits against the start distance, on synthetic stages.

The records come from scipy (:mod:`prefriction.identify.synthetic_loop`: LSODA on each sample
interval, restarted at every velocity reversal), independent of the fitter: a digital PD loop
following point-to-point moves (closed loop), or a multi-sine force applied to the free stage
(open loop), the encoder rounding the position (plus Gaussian noise before the rounding). Each
fit starts every free parameter (mass and offset included) at the truth times a factor drawn
log-uniformly in ``[1 / d, d]`` (the offset: the truth plus a uniform fraction ``ln d`` of the
Coulomb force), and succeeds when every estimate lands within 5 % of its true value (the
offset within 5 % of the Coulomb force). ``prefriction bench --identify`` and
``tests/test_identify_success.py`` call :func:`success_table`.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from prefriction.identify.data import Motion
from prefriction.identify.synthetic_loop import ClosedLoop, _interval, _rhs, replay
from prefriction.models.base import FrictionModel
from prefriction.models.dahl import Dahl
from prefriction.models.lugre import LuGre
from prefriction.models.viscous import Viscous

__all__ = ["GRID", "STAGES", "Stage", "SuccessRow", "coverage_text", "distance_text", "pooled_text", "row_from_dict",
           "stage_record", "start_model", "success_table", "table_text"]

TOLERANCE = 0.05
"""Largest relative error of every estimate for a fit to count as a success."""
RTOL = 1e-12
"""Relative tolerance of scipy's LSODA in the records. The 95.1 kg stages pin their parameters to
parts per million: a record at ``1e-10`` moved the estimates of a Dahl + viscous + offset record
by 1.3 of their standard errors against one at ``1e-12``."""


@dataclass(frozen=True)
class Stage:
    """A synthetic stage: friction, mass, loop, sample rate and encoder.

    Attributes
    ----------
    name : str
        Short label of the table.
    friction : LuGre or Dahl
        The true friction (Dahl with any ``gamma``).
    mass : float
        Moving mass [kg].
    b : float
        Viscous coefficient [N s/m] of a Dahl stage (fitted as a :class:`prefriction.Viscous` term).
    offset : float
        Force offset [N].
    rate : float
        Sample rate [Hz].
    quantum : float
        Encoder step [m].
    stroke : float
        Largest move [m] (closed loop) or the force amplitude in units of ``Fc`` (open loop).
    closed : bool
        Closed loop (PD at a bandwidth of ``rate / 50``) or open loop (multi-sine force).
    free : tuple of str
        The fitted parameters besides ``mass`` and ``offset``.
    fit_offset : bool
        Fit a force offset (``offset=True``); without it the stage has none.
    pid : bool
        Closed loop: PID (integral gain ``Kp wn / 5``) instead of PD.
    """

    name: str
    friction: FrictionModel
    mass: float
    b: float
    offset: float
    rate: float
    quantum: float
    stroke: float
    closed: bool
    free: tuple = field(default=())
    fit_offset: bool = True
    pid: bool = False

    @property
    def label(self) -> str:
        """The model column of the pooled table: friction, with ``+b`` for a fitted viscous term
        (Dahl's :class:`prefriction.Viscous`, LuGre's ``sigma2``) and ``+offset`` for a fitted offset."""
        kind = "Dahl" if isinstance(self.friction, Dahl) else "LuGre"
        return kind + ("+b" if {"b", "sigma2"} & set(self.free) else "") + ("+offset" if self.fit_offset else "")

    @property
    def loop(self) -> ClosedLoop:
        wn = 2.0 * math.pi * self.rate / 50.0
        return ClosedLoop(self.friction, mass=self.mass, b=self.b, offset=self.offset, Kp=self.mass * wn**2,
                          Kd=1.4 * self.mass * wn, quantum=self.quantum, dt=1.0 / self.rate,
                          noise=self.quantum / 3.0)

    def model(self) -> FrictionModel:
        """The true model as fitted (Dahl plus a :class:`prefriction.Viscous` term)."""
        return self.friction + Viscous(self.b) if "b" in self.free else self.friction

    def truth(self) -> dict[str, float]:
        """True values of the fitted parameters, ``mass`` and ``offset`` included."""
        from prefriction.identify.parameters import _entries

        values = {e.name: e.value for e in _entries(self.model())}
        out = {n: values[n] for n in self.free}
        out["mass"] = self.mass
        if self.fit_offset:
            out["offset"] = self.offset
        return out


STAGES = (
    Stage("Dahl+b open 0.3 kg 10 kHz 1 nm", Dahl(sigma=5e5, Fc=0.5, gamma=1.0), 0.3, 2.0, 0.05, 10_000.0, 1e-9,
          2.0, False, ("sigma", "Fc", "b")),
    Stage("LuGre closed 2.5 kg 5 kHz 10 nm", LuGre(sigma0=2e6, sigma1=50.0, sigma2=10.0, Fc=3.0, Fs=3.0, vs=1e-3),
          2.5, 0.0, 0.2, 5_000.0, 1e-8, 1e-3, True, ("sigma0", "sigma2", "Fc", "Fs")),
    Stage("Dahl+b closed 2.5 kg 2 kHz 10 nm", Dahl(sigma=2e6, Fc=3.0, gamma=2.0), 2.5, 8.0, -0.3, 2_000.0, 1e-8,
          2e-3, True, ("sigma", "Fc", "gamma", "b")),
    Stage("LuGre closed 95 kg 1 kHz 50 nm", LuGre(sigma0=2e5, sigma1=300.0, sigma2=203.5, Fc=20.39, Fs=20.39,
                                                  vs=0.01), 95.1, 0.0, -3.16, 1_000.0, 5e-8, 0.05, True,
          ("sigma0", "sigma2", "Fc", "Fs")),
    Stage("LuGre open 10 kg 2 kHz 20 nm", LuGre(sigma0=1e6, sigma1=100.0, sigma2=40.0, Fc=5.0, Fs=5.0, vs=1e-3),
          10.0, 0.0, 0.4, 2_000.0, 2e-8, 2.0, False, ("sigma0", "sigma2", "Fc", "Fs")),
)
"""The stages of the harness: 0.3 to 95 kg, 1 to 10 kHz, 1 to 50 nm, Dahl and LuGre, offset,
closed and open loop."""


def _grid() -> tuple[Stage, ...]:
    """Three stages (0.3 kg / 10 kHz / 1 nm; the 2.5 kg / 5 kHz / 10 nm stage of a user with
    ``sigma = 2e6`` N/m and ``Fc = 3`` N; an EMPS-like 95.1 kg / 1 kHz / 50 nm stage), each
    with Dahl (``gamma = 1``) and LuGre friction, each with a viscous term and an offset or with
    neither, each in a closed loop (PID) and in open loop."""
    import dataclasses

    stages = []
    for mass, rate, quantum, stroke, dahl, lugre, b, offset in (
            (0.3, 10_000.0, 1e-9, 1e-4, Dahl(sigma=5e5, Fc=0.5, gamma=1.0),
             LuGre(sigma0=5e5, sigma1=10.0, sigma2=2.0, Fc=0.5, Fs=0.5, vs=1e-3), 2.0, 0.05),
            (2.5, 5_000.0, 1e-8, 1e-3, Dahl(sigma=2e6, Fc=3.0, gamma=1.0),
             LuGre(sigma0=2e6, sigma1=50.0, sigma2=8.0, Fc=3.0, Fs=3.0, vs=1e-3), 8.0, 0.2),
            (95.1, 1_000.0, 5e-8, 0.05, Dahl(sigma=1e6, Fc=20.39, gamma=1.0),
             LuGre(sigma0=2e5, sigma1=300.0, sigma2=203.5, Fc=20.39, Fs=20.39, vs=0.01), 203.5, -3.16)):
        for friction in (dahl, lugre):
            for extras in (True, False):
                if isinstance(friction, Dahl):
                    free = ("sigma", "Fc", "b") if extras else ("sigma", "Fc")
                    fr, bb = friction, (b if extras else 0.0)
                else:
                    free = ("sigma0", "sigma2", "Fc", "Fs") if extras else ("sigma0", "Fc", "Fs")
                    fr, bb = (friction if extras else dataclasses.replace(friction, sigma2=0.0)), 0.0
                for closed in (True, False):
                    st = Stage("", fr, mass, bb, offset if extras else 0.0, rate, quantum,
                               stroke if closed else 2.0, closed, free, fit_offset=extras, pid=closed)
                    name = (f"{st.label} {'closed (PID)' if closed else 'open'} {mass:g} kg {rate / 1e3:g} kHz "
                            f"{quantum * 1e9:g} nm")
                    stages.append(dataclasses.replace(st, name=name))
    return tuple(stages)


GRID = _grid()
"""The grid of the done-when: 3 stages x {Dahl, LuGre} x {with viscous and offset, without} x
{closed loop (PID), open loop}, 24 stages."""


def stage_record(stage: Stage, n: int, rng: np.random.Generator, pace: int | None = None) -> Motion:
    """``n`` samples of ``stage`` (mass not given: fitted), from scipy (see the module text).

    Closed loop: six moves of random length up to ``stage.stroke`` [m] with alternating
    directions, cosine velocity profiles and rests, scaled to ``pace`` samples (default ``n``: a
    longer record moves more slowly) and continued at that pace to the record's end; the loop a PD
    (a PID with ``stage.pid``: ``u = Kp e + Ki sum(e) dt - Kd dx/dt``). Open loop: the force
    ``u = A Fc (sin(w t) + 0.4 sin(2.7 w t + 1))`` with ``A = stage.stroke`` and three periods
    of ``w`` in ``pace`` samples, from rest.
    """
    pace = n if pace is None else _pace(pace)
    loop = stage.loop
    dt = loop.dt
    t = np.arange(n) * dt
    noise = loop.noise * rng.standard_normal(n)
    if stage.closed:
        r = _moves(n, rng, stage.stroke, pace)
        rhs = _rhs(loop)
        x, u = np.empty(n), np.empty(n)
        y = np.array([r[0], 0.0, 0.0])
        prev = np.round(r[0] / loop.quantum) * loop.quantum
        Ki = loop.Kp * 2.0 * math.pi * stage.rate / 50.0 / 5.0 if stage.pid else 0.0
        integral = 0.0
        for k in range(n):
            xq = np.round((y[0] + noise[k]) / loop.quantum) * loop.quantum
            x[k] = xq
            integral += (r[k] - xq) * dt
            u[k] = loop.Kp * (r[k] - xq) + Ki * integral - loop.Kd * (xq - prev) / dt
            prev = xq
            if k < n - 1:
                y = _interval(rhs, y, k * dt, (k + 1) * dt, u[k], RTOL)
    else:
        w = 2.0 * math.pi * 3.0 / (pace * dt)
        Fc = stage.friction.Fc
        u = stage.stroke * Fc * (np.sin(w * t) + 0.4 * np.sin(2.7 * w * t + 1.0))
        xt = replay(loop, t, u, 0.0, 0.0, 0.0, rtol=RTOL)
        x = np.round((xt + noise) / loop.quantum) * loop.quantum
    return Motion(t, x, u, None, hold="zoh")


def _pace(pace: int) -> int:
    """``pace`` checked: samples of the six moves' pattern (:func:`stage_record`)."""
    if not isinstance(pace, (int, np.integer)) or pace < 28:
        raise ValueError(f"pace must be an integer of at least 28 samples (the moves' pattern), got {pace!r}")
    return int(pace)


def _moves(n: int, rng: np.random.Generator, stroke: float, pace: int) -> np.ndarray:
    """Reference [m]: a rest, then moves (cosine velocity profile) each followed by a rest, six in
    ``pace`` samples, to the record's end."""
    r = np.zeros(n)
    unit = pace // 28
    k, pos, sign = 2 * unit, 0.0, 1.0
    while k < n:
        steps = max(int(rng.uniform(2.0, 3.0) * unit), 2)
        target = pos + sign * stroke * rng.uniform(0.4, 1.0)
        s = np.arange(1, steps + 1) / steps
        seg = pos + (target - pos) * 0.5 * (1.0 - np.cos(np.pi * s))
        r[k:k + steps] = seg[: max(0, min(steps, n - k))]
        k += steps
        rest = int(rng.uniform(0.8, 1.5) * unit)
        r[k:k + rest] = target
        k += rest
        pos, sign = target, -sign
    return r


@dataclass(frozen=True)
class SuccessRow:
    """One line of :func:`success_table`: a stage at one start distance.

    ``held`` counts, per parameter, the fits whose 95 % interval holds the true value (among the
    ``returned`` fits that gave estimates); ``spread`` holds, per fit, the largest realised start
    factor ``max |ln(start / truth)|`` over the multiplicative parameters (``exp`` of it is the
    fit's realised start distance) and whether the fit succeeded; ``rss_mb`` is the peak
    resident set size of the process [MB] when the row was done; ``first`` counts the successes
    of the given start alone (without the second start from the data that a failed fit takes,
    :func:`prefriction.identify.motion_start.data_start`); ``seed`` is the seed of the record and
    the starts; ``median_cpu`` and ``max_cpu`` are the fits' CPU times [s] (``time.process_time``,
    all the process's threads), which a loaded machine does not inflate as it does the wall times."""

    stage: str
    distance: float
    samples: int
    fits: int
    successes: int
    converged: int
    median_time: float
    max_time: float
    worst: str
    label: str = ""
    returned: int = 0
    held: dict = field(default_factory=dict)
    spread: tuple = ()
    rss_mb: float = 0.0
    first: int = 0
    seed: int = 0
    median_cpu: float = 0.0
    max_cpu: float = 0.0

    @property
    def rate(self) -> float:
        """Fraction of fits within 5 % of every true parameter."""
        return self.successes / max(self.fits, 1)


def start_model(stage: Stage, rng: np.random.Generator,
                distance: float) -> tuple[FrictionModel, float, float | None]:
    """Start model, start mass [kg] and start offset [N] (``None`` without a fitted offset):
    every free parameter at the truth times ``exp(U(-ln d, ln d))`` (``gamma`` kept at 1 or
    above, or at 0.95 or below for a true ``gamma < 1``; LuGre's ``Fs`` at the start ``Fc``
    times the true ratio ``Fs / Fc``), the offset at the truth plus ``U(-ln d, ln d) Fc``."""
    import dataclasses

    def factor() -> float:
        return math.exp(rng.uniform(-math.log(distance), math.log(distance)))

    fr = stage.friction
    new = {}
    for name in stage.free:
        if hasattr(fr, name) and name != "Fs":
            value = getattr(fr, name) * factor()
            if name == "gamma":  # kept on the truth's side of the Dahl structure boundary gamma = 1
                value = max(value, 1.0) if fr.gamma >= 1.0 else min(value, 0.95)
            new[name] = value
    if isinstance(fr, LuGre):  # Fs - Fc started at the truth's ratio (0 for Fs = Fc: no Stribeck peak)
        Fc0 = new.get("Fc", fr.Fc)
        new["Fs"] = max(Fc0 * fr.Fs / fr.Fc, Fc0)  # Fs = Fc stays so after the rounding of the ratio
    start = dataclasses.replace(fr, **new)
    if "b" in stage.free:
        start = start + Viscous(stage.b * factor())
    mass0 = stage.mass * factor()
    if not stage.fit_offset:
        return start, mass0, None
    offset0 = stage.offset + rng.uniform(-math.log(distance), math.log(distance)) * fr.Fc
    return start, mass0, offset0


def success_table(stages: tuple = STAGES, distances: tuple = (1.25, 1.5, 2.0), *, fits: int = 10, samples: int = 1000,
                  seed: int = 0, progress=None, pace: int | None = None) -> list[SuccessRow]:
    """Fit every stage from ``fits`` seeded starts at each start distance; count the successes.

    Parameters
    ----------
    stages : tuple of Stage
        Default: :data:`STAGES`.
    distances : tuple of float
        Start distances ``d`` (factors ``>= 1``): starts drawn log-uniformly in ``[1/d, d]`` times the truth.
    fits : int
        Starts per stage and distance.
    samples : int
        Samples of each record.
    seed : int
        Seed of the records and the starts.
    progress : callable, optional
        Called with one line per fit.
    pace : int, optional
        Samples of the records' moves pattern (:func:`stage_record`); default ``samples``.

    Returns
    -------
    list of SuccessRow
        One row per stage and distance.
    """
    rows = []
    for i, stage in enumerate(stages):
        known = STAGES + GRID
        i = next((k for k, st in enumerate(known) if st is stage), i)  # a stage's draws do not depend on
        data = stage_record(stage, samples, np.random.default_rng([seed, i]), pace)  # which others run with it
        for d in distances:
            rng = np.random.default_rng([seed, i, int(round(100 * d))])
            fits_done = []
            for j in range(fits):
                f = _one_fit(stage, data, *start_model(stage, rng, d))
                fits_done.append(f)
                if progress is not None:
                    progress(f"{stage.name} d={d:g} fit {j + 1}/{fits}: {'ok' if f.good else 'FAIL'} "
                             f"max error {f.error:.2%} (start within x{math.exp(f.spread):.2f}) in {f.time:.1f} s"
                             + (" after a second start from the data" if f.retried else "")
                             + (f" ({f.message})" if f.message else ""))
            rows.append(_row(stage, d, samples, fits_done, seed))
    return rows


@dataclass(frozen=True)
class _Fit:
    """One fit of :func:`success_table`."""

    good: bool
    converged: bool
    error: float
    worst: str
    time: float
    spread: float
    held: dict
    message: str
    retried: bool = False
    cpu: float = 0.0


def _one_fit(stage: Stage, data: Motion, start: FrictionModel, m0: float, off0: float | None) -> _Fit:
    """Fit ``data`` from one start; errors, interval hits and the realised start distance."""
    from prefriction.identify.fit import fit
    from prefriction.identify.parameters import _entries

    truth = stage.truth()
    values = {e.name: e.value for e in _entries(start)}
    values["mass"] = m0
    spread = max(abs(math.log(values[n] / v)) for n, v in truth.items() if n != "offset")
    fixed = [e.name for e in _entries(start) if e.name not in stage.free]
    kw = {"offset": True, "offset0": off0} if stage.fit_offset else {}
    t0, c0 = time.perf_counter(), time.process_time()
    held: dict = {}
    retried = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = fit(start, data, fixed=fixed, mass0=m0, **kw)
            est = {n: res.estimate(n) for n in truth}
            for n, v in truth.items():
                lo, hi = res.interval(n)
                held[n] = bool(lo <= v <= hi)
            conv, msg = bool(res.success), ("" if res.success else res.message)
            retried = any("second start from" in line for line in res.start)
        except Exception as exc:  # noqa: BLE001 - a failure is a row of the table
            est, conv, msg = {}, False, f"{type(exc).__name__}: {exc}"
            retried = "second start from" in msg
    elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
    errs = {n: _error(n, est.get(n, math.nan), v, stage) for n, v in truth.items()}
    err = max(errs.values())
    name = max(errs, key=lambda n: errs[n] if math.isfinite(errs[n]) else math.inf)
    return _Fit(err <= TOLERANCE, conv, err, name, elapsed, spread, held, msg, retried, cpu)


def _row(stage: Stage, d: float, samples: int, fits: list[_Fit], seed: int = 0) -> SuccessRow:
    import resource

    bad = [f for f in fits if not f.good]
    worst = ""
    if bad:
        w = max(bad, key=lambda f: f.error if math.isfinite(f.error) else math.inf)
        worst = f"{w.worst} off {w.error:.0%}" + (f" ({w.message[:80]})" if w.message else "")
    held: dict = {}
    for f in fits:
        for n, h in f.held.items():
            held[n] = held.get(n, 0) + int(h)
    times, cpus = [f.time for f in fits], [f.cpu for f in fits]
    return SuccessRow(stage.name, d, samples, len(fits), sum(f.good for f in fits), sum(f.converged for f in fits),
                      float(np.median(times)), float(np.max(times)), worst, stage.label,
                      sum(bool(f.held) for f in fits), held, tuple((f.spread, f.good) for f in fits),
                      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                      sum(f.good and not f.retried for f in fits), seed, float(np.median(cpus)), float(np.max(cpus)))


def _error(name: str, value: float, truth: float, stage: Stage) -> float:
    if not math.isfinite(value):
        return math.inf
    scale = stage.friction.Fc if name == "offset" else abs(truth)
    return abs(value - truth) / scale


def table_text(rows: list[SuccessRow]) -> str:
    """The rows as a Markdown table, one line per stage and start distance."""
    lines = ["| stage | seed | start within | samples | success | converged | median [s] | max [s] | CPU median [s] | "
             "peak RSS [MB] | worst miss |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        lines.append(f"| {r.stage} | {r.seed} | x{r.distance:g} | {r.samples} | {r.successes}/{r.fits} "
                     f"| {r.converged}/{r.fits} | {r.median_time:.1f} | {r.max_time:.1f} | {r.median_cpu:.1f} "
                     f"| {r.rss_mb:.0f} | {r.worst} |")
    return "\n".join(lines)


BINS = (1.25, 1.5, 2.0)
"""Upper edges of the realised start distances ``exp(max |ln(start / truth)|)`` of the pooled table."""


def pooled_text(rows: list[SuccessRow], key=lambda r: r.label) -> str:
    """Success rates pooled over the stages with the same ``key`` (default: the model, e.g.
    ``Dahl+b+offset``), per drawn start distance ``d`` and per realised start distance (the
    largest factor of any parameter of a fit, binned at :data:`BINS`), with the median fit time
    and the largest peak memory of the group; in brackets the successes of the given start alone
    (without the second start from the data)."""
    groups: dict = {}
    for r in sorted(rows, key=key):
        groups.setdefault(key(r), []).append(r)
    groups["all"] = list(rows)
    dists = sorted({r.distance for r in rows})
    edges = (1.0,) + BINS
    head = ("| model | " + " | ".join(f"drawn within x{d:g} (given start alone)" for d in dists) + " | "
            + " | ".join(f"realised x{lo:g}-{hi:g}" for lo, hi in zip(edges, edges[1:]))
            + " | median fit [s] | peak RSS [MB] |")
    lines = [head, "|---|" + "---:|" * (len(dists) + len(BINS) + 2)]
    for name, rs in groups.items():
        cells = []
        for d in dists:
            sel = [r for r in rs if r.distance == d]
            ok, n = sum(r.successes for r in sel), sum(r.fits for r in sel)
            cells.append(_rate(ok, n) + f" ({sum(r.first for r in sel)})")
        spread = [p for r in rs for p in r.spread]
        for lo, hi in zip(edges, edges[1:]):
            sel = [good for s, good in spread if math.log(lo) < s <= math.log(hi) or (lo == 1.0 and s == 0.0)]
            cells.append(_rate(sum(sel), len(sel)))
        med = float(np.median([r.median_time for r in rs]))
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {med:.1f} | {max(r.rss_mb for r in rs):.0f} |")
    return "\n".join(lines)


def distance_text(rows: list[SuccessRow], key=lambda r: r.label) -> str:
    """Success rate per model (``key``) and drawn start distance, one line each: successes / fits,
    the successes of the given start alone (without the second start from the data), the median
    and largest wall and CPU time of a fit [s] and the largest peak resident set size [MB] of
    the processes that ran them; the models in alphabetical order, then an ``all`` line per
    distance."""
    groups: dict = {}
    for r in sorted(rows, key=lambda r: (key(r), r.distance)):
        groups.setdefault((key(r), r.distance), []).append(r)
    for d in sorted({r.distance for r in rows}):
        groups[("all", d)] = [r for r in rows if r.distance == d]
    lines = ["| model | start within | success | given start alone | wall median / max [s] | "
             "CPU median / max [s] | peak RSS [MB] |", "|---|---:|---:|---:|---:|---:|---:|"]
    for (name, d), rs in groups.items():
        ok, n = sum(r.successes for r in rs), sum(r.fits for r in rs)
        wall = f"{_sec(_median_of(rs, 'median_time'))} / {_sec(max(r.max_time for r in rs))}"
        cpu = f"{_sec(_median_of(rs, 'median_cpu'))} / {_sec(max(r.max_cpu for r in rs))}"
        lines.append(f"| {name} | x{d:g} | {_rate(ok, n)} | {sum(r.first for r in rs)} | {wall} | {cpu} | "
                     f"{max(r.rss_mb for r in rs):.0f} |")
    return "\n".join(lines)


def _sec(x: float) -> str:
    """Seconds in at most three digits."""
    return f"{x:.1f}" if x < 10.0 else f"{x:.0f}"


def _median_of(rows: list[SuccessRow], name: str) -> float:
    """Median over the fits of the rows' per-row medians, each weighted by its fit count (exact for
    rows of one fit)."""
    return float(np.median(np.repeat([getattr(r, name) for r in rows], [r.fits for r in rows])))


def coverage_text(rows: list[SuccessRow], key=lambda r: r.label) -> str:
    """How often the 95 % intervals of the fits of :func:`success_table` hold the truth, per
    parameter, pooled over the stages with the same ``key``, and over all. The fits of one record
    (a stage and a seed) share it (they differ only in the start), so each record counts once: its
    weight is spread evenly over its fits that returned estimates. ``SD`` is the binomial standard
    deviation of the pooled coverage at a true 95 % over the group's intervals (records times
    parameters), treated as independent; ``pooled`` is the fraction of those intervals that hold
    the truth. Groups of several models (``all``, or a ``key`` such as the loop) list each
    parameter over the records that have it (no list beyond eight names)."""
    records: dict = {}
    for r in rows:
        rec = records.setdefault((r.stage, r.seed), {"key": key(r), "held": {}, "returned": 0})
        rec["returned"] += r.returned
        for p, h in r.held.items():
            rec["held"][p] = rec["held"].get(p, 0) + h
    groups: dict = {}
    for rec in sorted(records.values(), key=lambda rec: rec["key"]):
        if rec["returned"]:
            groups.setdefault(rec["key"], []).append(rec)
    lines = ["| model | records | fits with estimates | coverage per parameter (records weighted equally) | pooled "
             "| intervals | SD at 95 % |", "|---|---:|---:|---|---:|---:|---:|"]
    if len(groups) > 1:
        groups["all"] = [rec for rs in groups.values() for rec in rs]
    for name, recs in groups.items():
        names = list(dict.fromkeys(p for rec in recs for p in rec["held"]))
        per = {p: float(np.mean([rec["held"][p] / rec["returned"] for rec in recs if p in rec["held"]]))
               for p in names}
        text = ", ".join(f"{p} {v:.0%}" for p, v in per.items()) if len(names) <= 8 else ""
        n = sum(len(rec["held"]) for rec in recs)
        held = sum(h / rec["returned"] for rec in recs for h in rec["held"].values())
        lines.append(f"| {name} | {len(recs)} | {sum(rec['returned'] for rec in recs)} | {text} | {held / n:.0%} "
                     f"| {n} | {_sd95(n):.1%} |")
    return "\n".join(lines)


def _sd95(n: int) -> float:
    """Binomial standard deviation of a coverage measured on ``n`` intervals at a true 95 %."""
    return math.sqrt(0.95 * 0.05 / max(n, 1))


KEYS = {"model": lambda r: r.label,
        "loop": lambda r: "closed loop" if " closed" in r.stage else "open loop",
        "mass": lambda r: r.stage.split(" kg")[0].rsplit(" ", 1)[-1] + " kg"}
"""Groupings of the tables (``--by``): the model column, the loop, the stage mass (from the stage name)."""


def row_from_dict(d: dict) -> SuccessRow:
    """A :class:`SuccessRow` from ``dataclasses.asdict`` of one, read back from JSON."""
    return SuccessRow(**{k: (tuple(map(tuple, v)) if k == "spread" else v) for k, v in d.items()})


def _rate(ok: int, n: int) -> str:
    return f"{ok}/{n} ({ok / n:.0%})" if n else "-"


def main(argv: list[str] | None = None) -> None:
    """``python -m prefriction.identify._success [--grid] [--stages 0,3] [--fits N] [--samples N]
    [--distances 1.25,1.5,2] [--seeds 0,1] [--pace N] [--jsonl FILE] [--report FILE] [--by model|loop|mass]``: fit,
    print the tables
    (one progress line per fit on stderr); each seed gives every stage a new record and new
    starts; ``--jsonl`` appends each row as a JSON line, ``--report`` prints the tables of such a
    file (or files, comma-separated) without fitting."""
    import argparse
    import dataclasses
    import json
    import sys

    ap = argparse.ArgumentParser(prog="python -m prefriction.identify._success", description=main.__doc__)
    ap.add_argument("--fits", type=int, default=10)
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--distances", default="1.25,1.5,2")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seeds", default="", help="comma-separated seeds (instead of --seed): a record per stage each")
    ap.add_argument("--grid", action="store_true", help="the 24 stages of GRID instead of STAGES")
    ap.add_argument("--stages", default="", help="indices into the stage list (default: all)")
    ap.add_argument("--jsonl", default="", help="append the rows to this file, one JSON line each")
    ap.add_argument("--report", default="", help="print the tables of --jsonl files (comma-separated) and stop")
    ap.add_argument("--pace", type=int, default=None,
                    help="samples of the six moves' pattern, repeated to the record's end (default: --samples)")
    ap.add_argument("--by", default="model", choices=sorted(KEYS), help="group the pooled tables by this")
    args = ap.parse_args(argv)
    if args.report:
        rows = []
        for path in args.report.split(","):
            with open(path, encoding="utf-8") as fh:
                rows += [row_from_dict(json.loads(line)) for line in fh if line.strip()]
    else:
        stages = GRID if args.grid else STAGES
        if args.stages:
            stages = tuple(stages[int(k)] for k in args.stages.split(","))
        seeds = [int(k) for k in args.seeds.split(",")] if args.seeds else [args.seed]
        rows = []
        for seed, stage in ((s, st) for s in seeds for st in stages):
            new = success_table((stage,), tuple(float(d) for d in args.distances.split(",")), fits=args.fits,
                                samples=args.samples, seed=seed, pace=args.pace,
                                progress=lambda line: print(line, file=sys.stderr, flush=True))
            rows += new
            if args.jsonl:
                with open(args.jsonl, "a", encoding="utf-8") as fh:
                    for r in new:
                        fh.write(json.dumps(dataclasses.asdict(r)) + "\n")
    key = KEYS[args.by]
    print(table_text(rows) + "\n\n" + distance_text(rows, key) + "\n\n" + pooled_text(rows, key) + "\n\n"
          + coverage_text(rows, key))


if __name__ == "__main__":
    main()
