"""The EMPS benchmark as an opt-in check of the identification routes (``docs/identify_closed_loop.md#emps``).

EMPS (Janot, Gautier and Brunot, *Data set and reference models of EMPS*, Workshop on Nonlinear
System Identification Benchmarks, 2019): a 95 kg ball-screw stage under a PD position loop at
1 kHz, ``DATA_EMPS.mat`` (estimation, 24,841 samples) and ``DATA_EMPS_PULSES.mat`` (validation:
force pulses added to the loop's output). The data carry no licence: nothing of them is shipped;
:func:`load` reads the user's own copy (a public copy: GitHub ``forgi86/sysid-neural-continuous``,
``examples/EMPS/data/``).

:func:`benchmark` runs each route on the estimation record and scores each fitted model by the
benchmark's metric: the recorded force of the pulses record as input, the open-loop simulated
position, RMSE after a 20-sample warm-up, against the published rigid-body inverse model
(``M = 95.1089`` kg, ``Fv = 203.5034`` N s/m, ``Fc = 20.3935`` N, ``offset = -3.1648`` N) in the
same replay. Rigid-body models are replayed by classical Runge-Kutta with 10 steps per sample
(as the reference Simulink model: ode45, largest step ``dt / 10``), friction models by
:func:`prefriction.identify.motion_predict.predict_motion` (both from rest at the first
measured position, the force held over each sample). And by the drift-free check of
``Simulation_EMPS_Validation.m``: the model inside the loop following the pulses record's
reference with its pulses (:func:`loop_rmse`).
"""

from __future__ import annotations

import io
import os
import stat
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from prefriction.identify.data import Motion

__all__ = ["EMPSRecord", "PUBLISHED", "Row", "benchmark", "format_table", "load", "loop_rmse", "open_loop_rmse"]

PUBLISHED = {"mass": 95.1089, "b": 203.5034, "Fc": 20.3935, "offset": -3.1648}
"""The published inverse model (``Script_IDIM_LS.m``): mass [kg], viscous [N s/m], Coulomb [N], offset [N]."""
FILES = ("DATA_EMPS.mat", "DATA_EMPS_PULSES.mat")
WARMUP = 20
"""Samples left out of the benchmark's RMSE."""


@dataclass(frozen=True, eq=False)
class EMPSRecord:
    """One EMPS record in SI units.

    Attributes
    ----------
    t, x, reference, u : numpy.ndarray
        Times [s], motor positions ``qm`` [m], reference ``qg`` [m], force ``gtau vir`` [N].
    gtau, kp, kv : float
        Drive gain [N/V] and the loop's gains (``vir = kv (kp (qg - qm) - v)``).
    extra : numpy.ndarray or None
        The pulses ``gtau pulses_N`` [N] added to the controller's output (the pulses record;
        ``pulses_N`` is in volts despite its name: ``vir`` minus the loop's law is ``pulses_N``
        within 0.04 V).
    """

    t: np.ndarray
    x: np.ndarray
    reference: np.ndarray
    u: np.ndarray
    gtau: float
    kp: float
    kv: float
    extra: np.ndarray | None = None

    def motion(self) -> Motion:
        """The record as :class:`Motion` data with the mass free."""
        return Motion(self.t, self.x, self.u, None)


def _read_own(path: Path) -> bytes:
    """The bytes of a regular file the calling user owns and nobody else can write (no link followed)."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise ValueError(f"cannot open {str(path)!r} ({exc.strerror}); it must be a regular file, not a link") from exc
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fh.fileno())
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"{str(path)!r} is not a regular file")
        if hasattr(os, "getuid") and (st.st_uid != os.getuid() or st.st_mode & (stat.S_IWGRP | stat.S_IWOTH)):
            raise ValueError(f"{str(path)!r} belongs to another user or others can write it: the toolbox loads only "
                             f"its user's own files (copy it into a directory of yours)")
        return fh.read()


def load(directory: str | os.PathLike) -> tuple[EMPSRecord, EMPSRecord]:
    """The estimation and pulses records from a directory holding ``DATA_EMPS.mat`` and ``DATA_EMPS_PULSES.mat``.

    Raises
    ------
    ValueError
        If a file is missing, a link, another user's, or lacks a variable (named).
    """
    from scipy.io import loadmat

    out = []
    for name in FILES:
        path = Path(directory) / name
        if not path.exists():
            raise ValueError(f"{str(path)!r} does not exist: the directory must hold {' and '.join(FILES)}")
        mat = loadmat(io.BytesIO(_read_own(path)))
        try:
            t, qm, qg, vir = (np.asarray(mat[k], dtype=float).ravel() for k in ("t", "qm", "qg", "vir"))
            gtau, kp, kv = (float(np.asarray(mat[k]).ravel()[0]) for k in ("gtau", "kp", "kv"))
        except KeyError as exc:
            raise ValueError(f"{str(path)!r} lacks the variable {exc.args[0]!r} of the EMPS files") from exc
        extra = gtau * np.asarray(mat["pulses_N"], dtype=float).ravel() if "pulses_N" in mat else None
        out.append(EMPSRecord(t, qm, qg, gtau * vir, gtau, kp, kv, extra))
    return out[0], out[1]


def _rigid_replay(u: np.ndarray, x0: float, dt: float, mass: float, est: dict[str, float], sub: int = 10) -> np.ndarray:
    """Open-loop positions of ``m a + b_s v + Fc_s sign(v) + offset = u`` (Runge-Kutta, ``sub`` steps per sample)."""
    b, b_neg = est["b"], est.get("b_neg", est["b"])
    Fc, Fc_neg, off = est["Fc"], est.get("Fc_neg", est["Fc"]), est.get("offset", 0.0)
    h = dt / sub
    x, v = x0, 0.0
    out = np.empty(u.size)
    out[0] = x0

    def acc(vv: float, uk: float) -> float:
        fr = (b * vv + Fc) if vv > 0.0 else (b_neg * vv - Fc_neg) if vv < 0.0 else 0.0
        return (uk - fr - off) / mass

    for k in range(u.size - 1):
        uk = float(u[k])
        for _ in range(sub):
            a1 = acc(v, uk)
            a2 = acc(v + 0.5 * h * a1, uk)
            a3 = acc(v + 0.5 * h * a2, uk)
            a4 = acc(v + h * a3, uk)
            x += h * (v + h / 6.0 * (a1 + a2 + a3))
            v += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        out[k + 1] = x
    return out


def open_loop_rmse(result: Any, record: EMPSRecord) -> float:
    """The benchmark's metric [m] of a fitted model (a FitResult of any route) on ``record``."""
    from prefriction.identify.motion_predict import predict_motion
    from prefriction.identify.static_map import StaticFriction

    if isinstance(result.model, StaticFriction):
        est = {n: result.estimate(n) for n in result.names if n != "mass"}
        x = _rigid_replay(record.u, float(record.x[0]), float(np.mean(np.diff(record.t))), result.mass, est)
    else:
        x = predict_motion(result, record.motion(), v0=0.0, F0=0.0)
    return float(np.sqrt(np.mean((x[WARMUP:] - record.x[WARMUP:]) ** 2)))


def loop_rmse(result: Any, record: EMPSRecord) -> float:
    """Position RMSE [m] after the warm-up of a fitted model simulated inside the EMPS loop on ``record``.

    The loop (:meth:`DigitalLoop.emps`) follows the recorded reference with the recorded pulses
    added (``Simulation_EMPS_Validation.m``); a rigid body's Coulomb term is a Dahl model of
    stiffness 1e8 N/m (0.2 um of pre-sliding), its direction-dependent levels a symmetric one and
    an offset.
    """
    from prefriction.identify.closed_loop_fit import simulate_closed_loop
    from prefriction.models import Dahl, DirectionalViscous, Viscous
    from prefriction.identify.digital_loop import DigitalLoop
    from prefriction.identify.static_map import StaticFriction

    off = result.estimate("offset") if "offset" in result.names else 0.0
    model = result.model
    if isinstance(model, StaticFriction):
        fc_neg = model.Fc if model.Fc_neg is None else model.Fc_neg
        viscous = Viscous(model.b) if model.b_neg is None else DirectionalViscous(model.b, model.b_neg)
        model, off = Dahl(sigma=1e8, Fc=0.5 * (model.Fc + fc_neg)) + viscous, off + 0.5 * (model.Fc - fc_neg)
    loop = DigitalLoop.emps(record.kp, record.kv, record.gtau, dt=float(np.mean(np.diff(record.t))))
    x, _ = simulate_closed_loop(model, loop, record.t, record.reference, mass=result.mass, offset=off,
                                x0=float(record.x[0]), extra=record.extra)
    return float(np.sqrt(np.mean((x[WARMUP:] - record.x[WARMUP:]) ** 2)))


@dataclass
class Row:
    """One route's result: estimates with 95 % intervals, the metric and the time."""

    route: str
    model: str
    start: str
    estimates: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    rmse: float = float("nan")
    seconds: float = 0.0
    loop_rmse: float = float("nan")
    note: str = ""

    def holds(self) -> dict[str, bool]:
        """Whether each interval holds the published value (``b`` for ``Fv``)."""
        return {n: lo <= PUBLISHED[n] <= hi for n, (_, lo, hi) in self.estimates.items() if n in PUBLISHED}


def _row(route: str, label: str, start: str, fit: Callable[[], Any], pulses: EMPSRecord) -> Row:
    t0 = time.perf_counter()
    res = fit()
    sec = time.perf_counter() - t0
    est = {n: (float(res.estimates[i]), float(res.low[i]), float(res.high[i])) for i, n in enumerate(res.names)}
    return Row(route, label, start, est, open_loop_rmse(res, pulses), sec, loop_rmse(res, pulses))


def benchmark(directory: str | os.PathLike, *, starts: tuple[float, ...] = (1.0, 0.5, 2.0),
              closed_loop: bool = True, progress: Callable[[str], None] | None = None) -> list[Row]:
    """Each route on the EMPS estimation record, scored on the pulses record (module docstring).

    Parameters
    ----------
    directory : path
        Holds ``DATA_EMPS.mat`` and ``DATA_EMPS_PULSES.mat``.
    starts : tuple of float, default (1.0, 0.5, 2.0)
        Factors on the published values (and a Dahl stiffness of 5e6 N/m) for the dynamic
        model's start values.
    closed_loop : bool, default True
        Also run the closed-loop output-error route from every start (about 15 s each after a
        compilation of about 10 s).
    progress : callable, optional
        Called with one line per finished row.

    Returns
    -------
    list of Row
    """
    import warnings

    from prefriction.identify.closed_loop_fit import fit_closed_loop
    from prefriction.models import Dahl, DirectionalViscous, Viscous
    from prefriction.identify.digital_loop import DigitalLoop
    from prefriction.identify.inverse import fit_inverse
    from prefriction.identify.routes import recommend
    from prefriction.identify.static_map import StaticFriction

    est, pulses = load(directory)
    data = est.motion()
    say = progress or (lambda _line: None)
    P = PUBLISHED
    rows = []
    rec = recommend(data, controller_known=True)
    rows.append(Row("open-loop Motion fit", "-", "-", note=f"not run: recommend() says {rec.route!r} (horizon "
                    f"{rec.horizon} of {rec.samples} samples)"))
    say(f"recommend: {rec}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows.append(_row("inverse", "rigid body (Coulomb + viscous)", "closed form",
                         lambda: fit_inverse(StaticFriction(Fc=1.0, b=1.0), data), pulses))
        rows.append(_row("inverse", "rigid body, direction-dependent", "closed form",
                         lambda: fit_inverse(StaticFriction(Fc=1.0, b=1.0, Fc_neg=1.0, b_neg=1.0), data,
                                             offset=False), pulses))
        say(f"{rows[-2].route}: {rows[-2].model}, {rows[-2].seconds:.2f} s")
        for f in starts:
            model = Dahl(sigma=f * 5e6, Fc=f * P["Fc"]) + Viscous(f * P["b"])
            rows.append(_row("inverse", "Dahl + Viscous", f"{f:g} x", lambda model=model, f=f: fit_inverse(
                model, data, fixed=["gamma"], mass0=f * P["mass"], offset0=f * P["offset"]), pulses))
            say(f"inverse: Dahl + Viscous from {f:g} x, {rows[-1].seconds:.1f} s")
        model = Dahl(sigma=5e6, Fc=P["Fc"]) + DirectionalViscous(P["b"], P["b"])
        rows.append(_row("inverse", "Dahl + DirectionalViscous", "1 x", lambda: fit_inverse(
            model, data, fixed=["gamma"], mass0=P["mass"], offset0=P["offset"]), pulses))
        if closed_loop:
            loop = DigitalLoop.emps(est.kp, est.kv, est.gtau, dt=float(np.mean(np.diff(est.t))))
            for f in starts:
                model = Dahl(sigma=f * 5e6, Fc=f * P["Fc"]) + Viscous(f * P["b"])
                rows.append(_row("closed-loop", "Dahl + Viscous", f"{f:g} x", lambda model=model, f=f: fit_closed_loop(
                    model, data, loop, est.reference, fixed=["gamma"], mass0=f * P["mass"],
                    offset0=f * P["offset"], recorded=False), pulses))
                say(f"closed-loop: Dahl + Viscous from {f:g} x, {rows[-1].seconds:.1f} s")
    ref = Row("published", "rigid body (Script_IDIM_LS.m)", "-",
              {n: (v, v, v) for n, v in P.items()})
    ref.rmse = open_loop_rmse(_Published(), pulses)
    ref.loop_rmse = loop_rmse(_Published(), pulses)
    rows.insert(1, ref)
    return rows


class _Published:
    """The published rigid-body inverse model in the shape :func:`open_loop_rmse` reads."""

    def __init__(self) -> None:
        from prefriction.identify.static_map import StaticFriction

        self.model = StaticFriction(Fc=PUBLISHED["Fc"], b=PUBLISHED["b"])
        self.mass = PUBLISHED["mass"]
        self.names = ("mass", "Fc", "b", "offset")

    def estimate(self, name: str) -> float:
        return PUBLISHED[name]


def format_table(rows: list[Row]) -> str:
    """A Markdown table of the rows: estimates [95 % interval] of M, Fv, Fc, offset, the metric, the time."""
    head = ("| route | model | start | M [kg] | Fv [N s/m] | Fc [N] | offset [N] | pulses RMSE [mm] | in the loop [um] "
            "| time [s] |\n|---|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        cells = []
        for n in ("mass", "b", "Fc", "offset"):
            if n not in r.estimates:
                cells.append("-")
                continue
            v, lo, hi = r.estimates[n]
            comparable = r.route != "published" and "b_neg" not in r.estimates
            ok = "" if not comparable else (" ✓" if lo <= PUBLISHED[n] <= hi else " ✗")
            cells.append(f"{v:.4f}" if r.route == "published" else f"{v:.4g} [{lo:.4g}, {hi:.4g}]{ok}")
        rmse = "-" if not np.isfinite(r.rmse) else f"{1e3 * r.rmse:.3f}"
        in_loop = "-" if not np.isfinite(r.loop_rmse) else f"{1e6 * r.loop_rmse:.2f}"
        sec = "-" if r.seconds == 0.0 else f"{r.seconds:.1f}"
        extra = [f"{n} {r.estimates[n][0]:.4g} [{r.estimates[n][1]:.4g}, {r.estimates[n][2]:.4g}]"
                 for n in ("sigma", "b_neg", "Fc_neg") if n in r.estimates]
        note = "; ".join(([r.note] if r.note else []) + extra)
        lines.append(f"| {r.route} | {r.model}{' (' + note + ')' if note else ''} | {r.start} | "
                     + " | ".join(cells) + f" | {rmse} | {in_loop} | {sec} |")
    return "\n".join(lines)
