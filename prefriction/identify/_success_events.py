"""Success rate and cost of :class:`Motion` fits of models with in-branch events from far starts.

The records come from scipy (:mod:`prefriction.identify.synthetic_events`: DOP853 restarted at
every sample, velocity reversal and in-branch event), independent of the fitter: a 1 kg mass
driven both ways by a two-tone force with an offset of 0.1 N, 0.1 time units ``sqrt(m / sigma)``
per sample, the position rounded to an encoder step of 0.005 pre-sliding distances ``Fc / sigma``
after Gaussian noise of 0.003 of them. Each fit starts every free parameter (mass and offset
included) at the truth times a factor drawn log-uniformly in ``[1 / d, d]`` (a GMS or
ElastoPlastic ``Fs`` at least 1.05 ``Fc``, an ElastoPlastic ``z_ba`` at most 0.95 ``Fc / sigma0``).
A fit *converges* when the solver says so, *lands* when every estimate is within 5 % of its true
value (the offset within 5 % of ``Fc``), and *covers* when every 95 % interval holds the true
value. Used by ``python -m prefriction.identify._success_events`` and
``docs/identify_motion.md#limits``; the rows complement :mod:`prefriction.identify._success`.
"""

from __future__ import annotations

import argparse
import math
import resource
import sys
import time
import warnings
from dataclasses import dataclass

import numpy as np

from prefriction.identify.data import Motion
from prefriction.identify.synthetic_events import event_record
from prefriction.models.base import FrictionModel
from prefriction.models.elasto_plastic import ElastoPlastic
from prefriction.models.gms import GMS
from prefriction.models.maxwell_slip import MaxwellSlip

__all__ = ["EVENT_STAGES", "EventStage", "event_record_quantised", "event_success"]

MASS = 1.0
OFFSET = 0.1
TOLERANCE = 0.05


@dataclass(frozen=True)
class EventStage:
    """A model with in-branch events and the parameters its fits hold fixed."""

    name: str
    friction: FrictionModel
    fixed: tuple = ()


EVENT_STAGES = (
    EventStage("Maxwell-slip(3) + offset", MaxwellSlip([6e4, 3e4, 1e4], [0.3, 0.4, 0.3])),
    EventStage("GMS(2) + offset", GMS(k=[6e4, 4e4], alpha=[0.4, 0.6], Fc=1.0, Fs=1.3, vs=1e-3, C=50.0),
               ("alpha[0]", "alpha[1]", "vs", "delta", "sigma2", "damping[0]", "damping[1]")),
    EventStage("ElastoPlastic + offset", ElastoPlastic(sigma0=1e5, sigma1=100.0, sigma2=10.0, Fc=1.0, Fs=1.5,
                                                       vs=5e-3, z_ba=5e-6)),
)


def event_record_quantised(model: FrictionModel, n: int, seed: int) -> Motion:
    """``n`` samples of the record of the module docstring (mass free), seeded."""
    T = math.sqrt(MASS / model.sigma)
    t = np.arange(n) * 0.1 * T
    u = 0.05 + 1.6 * np.sin(2 * np.pi * t / (10 * T)) + 0.3 * np.sin(2 * np.pi * t / (3.3 * T))
    X = model.Fc / model.sigma
    d = event_record(model, MASS, t, u, offset=OFFSET, noise=0.003 * X, rng=np.random.default_rng(seed),
                     known_mass=False)
    return Motion(d.t, np.round(d.x / (0.005 * X)) * (0.005 * X), d.u, None, d.hold)


@dataclass(frozen=True)
class EventFit:
    """One fit: converged, landed, covered, *identified* (the estimates whose relative standard
    error is at most 0.5, the others reported as not identifiable, land and are covered), CPU
    seconds, peak resident memory [MB], whether the element start replaced the given one, and
    the estimate farthest from its true value."""

    converged: bool
    landed: bool
    covered: bool
    identified: bool
    cpu: float
    rss: float
    element_start: bool
    worst: str


def _start(stage: EventStage, d: float, rng: np.random.Generator) -> tuple[FrictionModel, float]:
    from prefriction.identify.parameters import ParameterSpace

    space = ParameterSpace(stage.friction, None, list(stage.fixed) or None, None)
    vals = {k: (v * d ** rng.uniform(-1.0, 1.0) if k in space.free else v) for k, v in space.start.items()}
    if "Fs" in vals:
        vals["Fs"] = max(vals["Fs"], 1.05 * vals["Fc"])
    if "z_ba" in vals:   # ElastoPlastic: breakaway before the start's pre-sliding distance
        vals["z_ba"] = min(vals["z_ba"], 0.95 * vals["Fc"] / vals["sigma0"])
    return space.build(vals), MASS * d ** rng.uniform(-1.0, 1.0)


def event_fit(stage: EventStage, n: int, seed: int, d: float = 2.0, data: Motion | None = None) -> EventFit:
    """Fit ``stage`` to its ``n``-sample record of ``seed`` from a start ``d`` off (seeded)."""
    from prefriction.identify.fit import fit
    from prefriction.identify.parameters import ParameterSpace

    data = event_record_quantised(stage.friction, n, seed) if data is None else data
    start, mass0 = _start(stage, d, np.random.default_rng(1000 + seed))
    truth = dict(ParameterSpace(stage.friction, None, list(stage.fixed) or None, None).start,
                 mass=MASS, offset=OFFSET)
    t0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fit(start, data, fixed=list(stage.fixed) or None, offset=True, mass0=mass0)
    cpu = time.process_time() - t0
    T = np.array([truth[k] for k in res.names])
    err = np.array([abs(e - t) / (stage.friction.Fc if k == "offset" else abs(t))
                    for k, e, t in zip(res.names, res.estimates, T)])
    inside = (res.low <= T) & (T <= res.high)
    pinned = np.abs(res.stderr) <= 0.5 * np.abs(res.estimates)
    return EventFit(bool(res.success), bool(res.success and err.max() <= TOLERANCE),
                    bool(res.success and np.all(inside)),
                    bool(res.success and np.all((err <= TOLERANCE) & inside | ~pinned)), cpu,
                    resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                    any(line.startswith("element start") for line in res.start), res.names[int(err.argmax())])


def event_success(stages: tuple = EVENT_STAGES, *, fits: int = 8, samples: int = 1000, d: float = 2.0,
                  progress: bool = True) -> list[tuple[EventStage, list[EventFit]]]:
    """``fits`` seeded fits of each stage from starts ``d`` off (one line per fit on stderr)."""
    out = []
    for stage in stages:
        rows = []
        for seed in range(fits):
            f = event_fit(stage, samples, seed, d)
            rows.append(f)
            if progress:
                print(f"{stage.name} n={samples} seed={seed}: converged {f.converged}, within 5 % {f.landed} "
                      f"(worst {f.worst}), intervals hold the truth {f.covered}, identified parameters within "
                      f"5 % and covered {f.identified}, {f.cpu:.1f} s CPU, "
                      f"{f.rss:.0f} MB", file=sys.stderr, flush=True)
        out.append((stage, rows))
    return out


def main(argv: list[str] | None = None) -> None:
    """``python -m prefriction.identify._success_events [--fits N] [--samples N] [--fix C,Fs]``: the table."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fits", type=int, default=8)
    p.add_argument("--samples", type=int, default=1000)
    p.add_argument("--distance", type=float, default=2.0)
    p.add_argument("--model", choices=[s.name.split("(")[0].split(" ")[0] for s in EVENT_STAGES], default=None)
    p.add_argument("--fix", default="", help="comma-separated parameters also held at their true values "
                                             "(e.g. C,Fs: those a record sliding much faster than vs cannot pin)")
    a = p.parse_args(argv)
    extra = tuple(x for x in a.fix.split(",") if x)
    stages = tuple(EventStage(s.name + "".join(f", {x} fixed" for x in extra), s.friction, s.fixed + extra)
                   for s in EVENT_STAGES if a.model is None or s.name.startswith(a.model))
    print("| model | samples | converged | within 5 % | intervals hold the truth | identified: within 5 % and "
          "held | CPU s (median) |")
    print("|---|---|---|---|---|---|---|")
    for stage, rows in event_success(stages, fits=a.fits, samples=a.samples, d=a.distance):
        n = len(rows)
        print(f"| {stage.name} | {a.samples} | {sum(r.converged for r in rows)}/{n} | {sum(r.landed for r in rows)}/{n} "
              f"| {sum(r.covered for r in rows)}/{n} | {sum(r.identified for r in rows)}/{n} "
              f"| {np.median([r.cpu for r in rows]):.1f} |")


if __name__ == "__main__":
    main()
