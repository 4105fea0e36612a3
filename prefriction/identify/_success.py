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

__all__ = ["STAGES", "Stage", "SuccessRow", "stage_record", "start_model", "success_table", "table_text"]

TOLERANCE = 0.05
"""Largest relative error of every estimate for a fit to count as a success."""


@dataclass(frozen=True)
class Stage:
    """A synthetic stage: friction, mass, loop, sample rate and encoder.

    Attributes
    ----------
    name : str
        Short label of the table.
    friction : LuGre or Dahl
        The true friction (Dahl with ``gamma >= 1``).
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

    @property
    def loop(self) -> ClosedLoop:
        wn = 2.0 * math.pi * self.rate / 50.0
        return ClosedLoop(self.friction, mass=self.mass, b=self.b, offset=self.offset, Kp=self.mass * wn**2,
                          Kd=1.4 * self.mass * wn, quantum=self.quantum, dt=1.0 / self.rate,
                          noise=self.quantum / 3.0)

    def model(self) -> FrictionModel:
        """The true model as fitted (Dahl plus a :class:`prefriction.Viscous` term)."""
        return self.friction + Viscous(self.b) if isinstance(self.friction, Dahl) else self.friction

    def truth(self) -> dict[str, float]:
        """True values of the fitted parameters, ``mass`` and ``offset`` included."""
        from prefriction.identify.parameters import _entries

        values = {e.name: e.value for e in _entries(self.model())}
        out = {n: values[n] for n in self.free}
        out.update(mass=self.mass, offset=self.offset)
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


def stage_record(stage: Stage, n: int, rng: np.random.Generator) -> Motion:
    """``n`` samples of ``stage`` (mass not given: fitted), from scipy (see the module text).

    Closed loop: six moves of random length up to ``stage.stroke`` [m] with alternating
    directions, cosine velocity profiles and rests, scaled to the record. Open loop: the force
    ``u = A Fc (sin(w t) + 0.4 sin(2.7 w t + 1))`` with ``A = stage.stroke`` and three periods
    of ``w`` in the record, from rest.
    """
    loop = stage.loop
    dt = loop.dt
    t = np.arange(n) * dt
    noise = loop.noise * rng.standard_normal(n)
    if stage.closed:
        r = _moves(n, rng, stage.stroke)
        rhs = _rhs(loop)
        x, u = np.empty(n), np.empty(n)
        y = np.array([r[0], 0.0, 0.0])
        prev = np.round(r[0] / loop.quantum) * loop.quantum
        for k in range(n):
            xq = np.round((y[0] + noise[k]) / loop.quantum) * loop.quantum
            x[k] = xq
            u[k] = loop.Kp * (r[k] - xq) - loop.Kd * (xq - prev) / dt
            prev = xq
            if k < n - 1:
                y = _interval(rhs, y, k * dt, (k + 1) * dt, u[k], 1e-10)
    else:
        w = 2.0 * math.pi * 3.0 / (n * dt)
        Fc = stage.friction.Fc
        u = stage.stroke * Fc * (np.sin(w * t) + 0.4 * np.sin(2.7 * w * t + 1.0))
        xt = replay(loop, t, u, 0.0, 0.0, 0.0)
        x = np.round((xt + noise) / loop.quantum) * loop.quantum
    return Motion(t, x, u, None, hold="zoh")


def _moves(n: int, rng: np.random.Generator, stroke: float) -> np.ndarray:
    """Reference [m]: a rest, then six moves (cosine velocity profile) each followed by a rest."""
    r = np.zeros(n)
    unit = n // 28
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
    """One line of :func:`success_table`: a stage at one start distance."""

    stage: str
    distance: float
    samples: int
    fits: int
    successes: int
    converged: int
    median_time: float
    max_time: float
    worst: str

    @property
    def rate(self) -> float:
        """Fraction of fits within 5 % of every true parameter."""
        return self.successes / max(self.fits, 1)


def start_model(stage: Stage, rng: np.random.Generator, distance: float) -> tuple[FrictionModel, float, float]:
    """Start model, start mass [kg] and start offset [N]: every free parameter at the truth times
    ``exp(U(-ln d, ln d))`` (``gamma`` kept at 1 or above; LuGre's ``Fs`` at the start ``Fc``
    times the true ratio ``Fs / Fc``), the offset at the truth plus ``U(-ln d, ln d) Fc``."""
    import dataclasses

    def factor() -> float:
        return math.exp(rng.uniform(-math.log(distance), math.log(distance)))

    fr = stage.friction
    new = {}
    for name in stage.free:
        if hasattr(fr, name) and name != "Fs":
            value = getattr(fr, name) * factor()
            new[name] = max(value, 1.0) if name == "gamma" else value
    if isinstance(fr, LuGre):  # Fs - Fc started at the truth's ratio (0 for Fs = Fc: no Stribeck peak)
        new["Fs"] = new.get("Fc", fr.Fc) * fr.Fs / fr.Fc
    start = dataclasses.replace(fr, **new)
    if isinstance(fr, Dahl):
        start = start + Viscous(stage.b * factor())
    offset0 = stage.offset + rng.uniform(-math.log(distance), math.log(distance)) * fr.Fc
    return start, stage.mass * factor(), offset0


def success_table(stages: tuple = STAGES, distances: tuple = (1.25, 1.5, 2.0), *, fits: int = 10, samples: int = 1000,
                  seed: int = 0, progress=None) -> list[SuccessRow]:
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

    Returns
    -------
    list of SuccessRow
        One row per stage and distance.
    """
    from prefriction.identify.fit import fit
    from prefriction.identify.parameters import _entries

    rows = []
    for i, stage in enumerate(stages):
        i = next((k for k, known in enumerate(STAGES) if known is stage), i)  # a stage's draws do not depend on
        data = stage_record(stage, samples, np.random.default_rng([seed, i]))  # which others run with it
        truth = stage.truth()
        for d in distances:
            rng = np.random.default_rng([seed, i, int(round(100 * d))])
            ok = conv = 0
            times, worst, worst_err = [], "", -1.0
            for j in range(fits):
                start, m0, off0 = start_model(stage, rng, d)
                fixed = [e.name for e in _entries(start) if e.name not in stage.free]
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        res = fit(start, data, fixed=fixed, offset=True, mass0=m0, offset0=off0)
                        est = {n: res.estimate(n) for n in truth}
                        conv += bool(res.success)
                        msg = "" if res.success else res.message
                    except Exception as exc:  # noqa: BLE001 - a failure is a row of the table
                        est, msg = {}, f"{type(exc).__name__}: {exc}"
                times.append(time.perf_counter() - t0)
                errs = {n: _error(n, est.get(n, math.nan), v, stage) for n, v in truth.items()}
                err = max(errs.values())
                good = err <= TOLERANCE
                ok += good
                if not good and not err <= worst_err:
                    worst_err = err
                    name = max(errs, key=lambda n: errs[n] if math.isfinite(errs[n]) else math.inf)
                    worst = f"{name} off {err:.0%}" + (f" ({msg[:80]})" if msg else "")
                if progress is not None:
                    progress(f"{stage.name} d={d:g} fit {j + 1}/{fits}: {'ok' if good else 'FAIL'} "
                             f"max error {err:.2%} in {times[-1]:.1f} s" + (f" ({msg})" if msg else ""))
            rows.append(SuccessRow(stage.name, d, samples, fits, ok, conv, float(np.median(times)),
                                   float(np.max(times)), worst))
    return rows


def _error(name: str, value: float, truth: float, stage: Stage) -> float:
    if not math.isfinite(value):
        return math.inf
    scale = stage.friction.Fc if name == "offset" else abs(truth)
    return abs(value - truth) / scale


def table_text(rows: list[SuccessRow]) -> str:
    """The rows as a Markdown table."""
    lines = ["| stage | start within | samples | success | converged | median [s] | max [s] | worst miss |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        lines.append(f"| {r.stage} | x{r.distance:g} | {r.samples} | {r.successes}/{r.fits} | {r.converged}/{r.fits} "
                     f"| {r.median_time:.1f} | {r.max_time:.1f} | {r.worst} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    """``python -m prefriction.identify._success [--fits N] [--samples N] [--distances 1.5,2]``:
    print the table, one progress line per fit on stderr."""
    import argparse
    import sys

    ap = argparse.ArgumentParser(prog="python -m prefriction.identify._success", description=main.__doc__)
    ap.add_argument("--fits", type=int, default=10)
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--distances", default="1.5,2")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    rows = success_table(STAGES, tuple(float(d) for d in args.distances.split(",")), fits=args.fits,
                         samples=args.samples, seed=args.seed,
                         progress=lambda line: print(line, file=sys.stderr, flush=True))
    print(table_text(rows))


if __name__ == "__main__":
    main()
