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
value.

The estimates of a Maxwell-slip fit are strongly correlated (one soft direction carries most of
every parameter's variance), so one fit's intervals fail together and a handful of fits says little
about coverage. Each fit is therefore also checked against its linearisation: the estimate error
predicted by the fit's influence weights ``W = M_k J^T`` (:class:`prefriction.identify.statistics.Statistics`,
eq. S1 without the residual) from the record's own position error ``e = x_m - x`` (``x`` the
noise-free scipy record), ``W e``, must match the actual error; then ``W e_d`` over ``draws`` fresh
noise and rounding realisations ``e_d`` gives the coverage of the intervals (each draw standardised
by the fit's standard errors). Used by ``python -m prefriction.identify._success_events`` and
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
from typing import TYPE_CHECKING

import numpy as np

from scipy.stats import t as student_t

from prefriction.identify.data import Motion
from prefriction.identify.synthetic_events import EventRun, event_motion
from prefriction.models.base import FrictionModel
from prefriction.models.elasto_plastic import ElastoPlastic
from prefriction.models.gms import GMS
from prefriction.models.maxwell_slip import MaxwellSlip

if TYPE_CHECKING:
    from prefriction.identify.result import FitResult

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


def event_run(model: FrictionModel, n: int) -> tuple[np.ndarray, np.ndarray, EventRun]:
    """Times [s], force [N] and the noise-free scipy motion of the ``n``-sample record."""
    T = math.sqrt(MASS / model.sigma)
    t = np.arange(n) * 0.1 * T
    u = 0.05 + 1.6 * np.sin(2 * np.pi * t / (10 * T)) + 0.3 * np.sin(2 * np.pi * t / (3.3 * T))
    return t, u, event_motion(model, MASS, t, u, offset=OFFSET)


def _encoder(model: FrictionModel, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Positions [m] read by the encoder of the module docstring: Gaussian noise, then rounding."""
    X = model.Fc / model.sigma
    return np.round((x + 0.003 * X * rng.standard_normal(x.size)) / (0.005 * X)) * (0.005 * X)


def event_record_quantised(model: FrictionModel, n: int, seed: int,
                           run: tuple[np.ndarray, np.ndarray, EventRun] | None = None) -> Motion:
    """``n`` samples of the record of the module docstring (mass free), seeded; ``run`` the
    :func:`event_run` of ``model`` and ``n`` if already computed."""
    t, u, motion = event_run(model, n) if run is None else run
    return Motion(t, _encoder(model, motion.x, np.random.default_rng(seed)), u, None, "zoh")


@dataclass(frozen=True)
class EventFit:
    """One fit: converged, landed, covered, *identified* (the estimates whose relative standard
    error is at most 0.5, the others reported as not identifiable, land and are covered), CPU
    seconds, peak resident memory [MB], whether the element start replaced the given one, and
    the estimate farthest from its true value; the number of parameters whose intervals hold the
    truth (of ``n_par``), the largest difference between an actual and a linearly predicted
    estimate error in standard errors (``gap``), and per parameter the fraction of the linear
    draws whose intervals hold the truth (``linear``, module docstring)."""

    converged: bool
    landed: bool
    covered: bool
    identified: bool
    cpu: float
    rss: float
    element_start: bool
    worst: str
    held: int = 0
    n_par: int = 0
    gap: float = math.nan
    linear: np.ndarray | None = None


def _start(stage: EventStage, d: float, rng: np.random.Generator) -> tuple[FrictionModel, float]:
    from prefriction.identify.parameters import ParameterSpace

    space = ParameterSpace(stage.friction, None, list(stage.fixed) or None, None)
    vals = {k: (v * d ** rng.uniform(-1.0, 1.0) if k in space.free else v) for k, v in space.start.items()}
    if "Fs" in vals:
        vals["Fs"] = max(vals["Fs"], 1.05 * vals["Fc"])
    if "z_ba" in vals:   # ElastoPlastic: breakaway before the start's pre-sliding distance
        vals["z_ba"] = min(vals["z_ba"], 0.95 * vals["Fc"] / vals["sigma0"])
    return space.build(vals), MASS * d ** rng.uniform(-1.0, 1.0)


def linear_check(res: "FitResult", model: FrictionModel, data: Motion, x_true: np.ndarray, truth: np.ndarray,
                 draws: int) -> tuple[float, np.ndarray]:
    """The linearisation of a Motion fit against its record (module docstring).

    Parameters
    ----------
    res : FitResult
        A Motion fit with ``covariance="hac"`` statistics (its influence series).
    model : FrictionModel
        The true model (its ``Fc / sigma`` sets the encoder).
    data : Motion
        The fitted record; ``x_true`` [m] its noise-free positions, ``truth`` the true values of
        ``res.names``.
    draws : int
        Fresh encoder realisations (seeds ``10000 + i``).

    Returns
    -------
    gap : float
        ``max |(est - truth) - W e| / se`` over the parameters.
    inside : numpy.ndarray
        Per parameter, the fraction of the draws ``|W e_d| <= t se``.
    """
    psi, r = res.statistics.influence, np.asarray(res.residuals, dtype=float)
    if psi is None or psi.shape[1] != r.size or r.size != len(data):
        raise ValueError("linear_check needs a Motion fit with an influence series of one column per sample")
    with np.errstate(divide="ignore", invalid="ignore"):   # psi = W (simulated - measured), r = measured - simulated
        W = np.where(r != 0.0, -psi / r, 0.0)
    se = np.asarray(res.stderr)
    gap = float(np.max(np.abs(res.estimates - truth - W @ (data.x - x_true)) / se))
    tq = float(student_t.ppf(0.975, res.statistics.dof))
    hits = np.zeros(se.size)
    for i in range(draws):
        e = _encoder(model, x_true, np.random.default_rng(10000 + i)) - x_true
        hits += np.abs(W @ e) <= tq * se
    return gap, hits / max(draws, 1)


def event_fit(stage: EventStage, n: int, seed: int, d: float = 2.0, data: Motion | None = None,
              draws: int = 0, run: tuple | None = None) -> EventFit:
    """Fit ``stage`` to its ``n``-sample record of ``seed`` from a start ``d`` off (seeded); with
    ``draws``, the linear check (:func:`linear_check`) against the :func:`event_run` ``run``."""
    from prefriction.identify.fit import fit
    from prefriction.identify.parameters import ParameterSpace

    if draws and data is not None:
        raise ValueError("the linear check needs the harness's own record: give draws or data, not both")
    run = event_run(stage.friction, n) if run is None and data is None else run
    data = event_record_quantised(stage.friction, n, seed, run) if data is None else data
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
    gap, linear = (linear_check(res, stage.friction, data, run[2].x, T, draws) if draws and res.success
                   else (math.nan, None))
    return EventFit(bool(res.success), bool(res.success and err.max() <= TOLERANCE),
                    bool(res.success and np.all(inside)),
                    bool(res.success and np.all((err <= TOLERANCE) & inside | ~pinned)), cpu,
                    resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                    any(line.startswith("element start") for line in res.start), res.names[int(err.argmax())],
                    int(inside.sum()) if res.success else 0, len(res.names), gap, linear)


def event_success(stages: tuple = EVENT_STAGES, *, fits: int = 8, samples: int = 1000, d: float = 2.0,
                  progress: bool = True, draws: int = 0) -> list[tuple[EventStage, list[EventFit]]]:
    """``fits`` seeded fits of each stage from starts ``d`` off (one line per fit on stderr), each
    with ``draws`` linear draws (:func:`linear_check`)."""
    out = []
    for stage in stages:
        rows = []
        run = event_run(stage.friction, samples)
        for seed in range(fits):
            f = event_fit(stage, samples, seed, d, draws=draws, run=run)
            rows.append(f)
            if progress:
                lin = (f"; linearisation: actual minus predicted error at most {f.gap:.2f} standard errors, "
                       f"{100 * float(np.mean(f.linear)):.1f} % of {draws} draws' intervals hold"
                       if f.linear is not None else "")
                print(f"{stage.name} n={samples} seed={seed}: converged {f.converged}, within 5 % {f.landed} "
                      f"(worst {f.worst}), intervals hold the truth {f.covered} ({f.held} of {f.n_par}), "
                      f"identified parameters within 5 % and covered {f.identified}, {f.cpu:.1f} s CPU, "
                      f"{f.rss:.0f} MB{lin}", file=sys.stderr, flush=True)
        out.append((stage, rows))
    return out


def main(argv: list[str] | None = None) -> None:
    """``python -m prefriction.identify._success_events [--fits N] [--samples N] [--fix C,Fs]``: the table."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fits", type=int, default=8)
    p.add_argument("--samples", type=int, default=1000)
    p.add_argument("--distance", type=float, default=2.0)
    p.add_argument("--draws", type=int, default=0, help="linear draws per fit (coverage by linearisation)")
    p.add_argument("--model", choices=[s.name.split("(")[0].split(" ")[0] for s in EVENT_STAGES], default=None)
    p.add_argument("--fix", default="", help="comma-separated parameters also held at their true values "
                                             "(e.g. C,Fs: those a record sliding much faster than vs cannot pin)")
    a = p.parse_args(argv)
    extra = tuple(x for x in a.fix.split(",") if x)
    stages = tuple(EventStage(s.name + "".join(f", {x} fixed" for x in extra), s.friction, s.fixed + extra)
                   for s in EVENT_STAGES if a.model is None or s.name.startswith(a.model))
    print("| model | samples | converged | within 5 % | intervals hold the truth: all / pooled over parameters "
          "| identified: within 5 % and held | linear draws: pooled coverage, largest gap | CPU s (median) "
          "| peak MB |")
    print("|---|---|---|---|---|---|---|---|---|")
    for stage, rows in event_success(stages, fits=a.fits, samples=a.samples, d=a.distance, draws=a.draws):
        n = len(rows)
        lin = [r for r in rows if r.linear is not None]
        linear = (f"{100 * float(np.mean([r.linear for r in lin])):.1f} % of {len(lin) * a.draws} draws, "
                  f"{max(r.gap for r in lin):.2f} SE" if lin else "-")
        print(f"| {stage.name} | {a.samples} | {sum(r.converged for r in rows)}/{n} | {sum(r.landed for r in rows)}/{n} "
              f"| {sum(r.covered for r in rows)}/{n} / {sum(r.held for r in rows)}/{sum(r.n_par for r in rows)} "
              f"| {sum(r.identified for r in rows)}/{n} | {linear} | {np.median([r.cpu for r in rows]):.1f} "
              f"| {max(r.rss for r in rows):.0f} |")


if __name__ == "__main__":
    main()
