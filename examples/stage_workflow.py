"""One stage from a record to C code: record, fit, compensate, plan a move, export, in one script.

The stage: a 2.5 kg carriage whose friction is a Dahl model (3.2) with rest stiffness
``sigma = 2e6 N/m``, Coulomb force ``Fc = 3 N``, ``gamma = 1``, run by a PID at 5 kHz reading a
10 nm encoder; its drive applies 0.2 N less than the controller commands (an amplifier offset).
Every step writes a figure into ``OUTDIR``:

1. ``1_record.png``: a closed-loop record (reference, encoder position, commanded force). By default
   synthetic, from an independent scipy integration of the stage (LSODA per sample interval,
   restarted at every velocity reversal; :func:`synthetic_record`); or a user's CSV with the
   columns ``t, x, u[, r]`` [s, m, N, m] (a header line, comma-separated), a positioning loop's
   record (with the reference ``r``, set ``RECORD_PID`` to the loop's controller).
2. ``2_fit.png``, ``2_validation.png``: a Dahl model and the offset fitted to the first 60 % of
   the record by the closed-loop output error (:func:`prefriction.identify.fit_closed_loop`: the
   model simulated in the record's loop) and validated on the held-out 40 % (the fitted stage in
   the same loop: its controller force against the recorded one). A user's CSV without the
   reference is fitted as force against displacement instead (a slow record).
3. ``3_compensation.png``: the PID designed on the fitted stage, alone, with the fitted model's
   feedforward and with a friction observer of the fitted model, tracking back-and-forth moves in
   the *true* stage's sampled loop, with the encoder step, measurement noise and the fitted
   model's error (mismatch).
4. ``4_optimal_move.png``: the minimum-time 20 um move of the fitted stage under ``|u| <= 12 N``
   (IPOPT, one phase per velocity sign), replayed through the true stage.
5. ``5_c_code.png``: the compensated controller as C99 (``stage_ctl.h``, ``stage_ctl.c``), compiled
   with gcc and run in closed loop with the exported stage; its positions against the Python loop.

The identification step is one function, :func:`identify_stage`: swap it for another route
(e.g. the inverse model, :func:`prefriction.identify.fit_inverse`) and the rest of the chain is
unchanged.

Run: ``python examples/stage_workflow.py OUTDIR [RECORD.csv] [--quick]`` (``--quick``: a
shorter record and loop, for the tests).
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import controllers, export, identify
from prefriction.plotting import new_figure, save
from prefriction.signals import PointToPoint

MASS, SIGMA, FC, OFFSET = 2.5, 2e6, 3.0, 0.2      # kg, N/m, N, N: the true stage
TS, QUANTUM, NOISE = 2e-4, 1e-8, 2e-9             # s (5 kHz), m (10 nm encoder), m rms
WN = 2.0 * math.pi * 200.0                        # rad/s: the PID's closed-loop bandwidth
U_MAX = 12.0                                      # N: the optimal move's force limit
RECORD_PID = (7.5e6, 5.0e9, 7.5e3)                # N/m, N/(m s), N s/m: the record's PID, poles near 200 Hz


def log(message: str) -> None:
    """One line of progress on stderr."""
    print(message, file=sys.stderr, flush=True)


# --- 1. the record ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Record:
    """A positioning loop's record: times [s], reference [m] (``nan`` if unknown), encoder
    positions [m] and the motor force held over each sample [N]."""

    t: np.ndarray
    r: np.ndarray
    x: np.ndarray
    u: np.ndarray


def record_reference(n: int) -> np.ndarray:
    """Reference positions [m] at ``n`` samples: a 4 Hz sine whose amplitude swells from 1.5 um
    to 15 um and back every 0.75 s, so the record holds small pre-sliding loops nested in large
    ones; slow enough that the inertial force ``m x''`` stays below 0.03 N (1 % of ``Fc``)."""
    t = np.arange(n) * TS
    return 15e-6 * (0.55 - 0.45 * np.cos(2.0 * np.pi * t / 0.75)) * np.sin(2.0 * np.pi * 4.0 * t)


def synthetic_record(seconds: float, seed: int = 1) -> Record:
    """The stage's closed-loop record from scipy, independent of the simulator.

    ``m x'' = u - OFFSET - F`` with Dahl's ``F' = sigma v (1 - sign(v) F / Fc)``, integrated by
    LSODA (``rtol = 1e-10``) over each sample interval under the held force and restarted at
    every velocity reversal; a digital PID ``u = kp e + ki Ts sum(e) + kd (e_k - e_(k-1)) / Ts``
    on the encoder position (rounded to 10 nm after 2 nm rms noise). The record holds the
    commanded force ``u``; the drive applies ``u - OFFSET`` (an amplifier offset [N]).
    """
    rng = np.random.default_rng(seed)
    n = int(round(seconds / TS))
    r = record_reference(n)
    kp, ki, kd = RECORD_PID

    def rhs(_t: float, y: np.ndarray, u: float) -> list[float]:
        v, F = y[1], y[2]
        return [v, (u - F) / MASS, SIGMA * v * (1.0 - np.sign(v) * F / FC)]

    def reversal(_t: float, y: np.ndarray, _u: float) -> float:
        return y[1]
    reversal.terminal = True  # type: ignore[attr-defined]

    y = np.zeros(3)
    x, u = np.empty(n), np.empty(n)
    integral, e_prev = 0.0, 0.0
    noise = NOISE * rng.standard_normal(n)
    for k in range(n):
        x[k] = np.round((y[0] + noise[k]) / QUANTUM) * QUANTUM
        e = r[k] - x[k]
        integral += TS * e
        u[k] = kp * e + ki * integral + kd * (e - e_prev) / TS
        e_prev = e
        t0, t1 = k * TS, (k + 1) * TS
        for _ in range(100):  # one sample interval, restarted at each reversal
            direction = np.sign(y[1]) or np.sign(rhs(t0, y, u[k] - OFFSET)[1]) or 1.0
            reversal.direction = -direction  # type: ignore[attr-defined]
            sol = solve_ivp(rhs, (t0, t1), y, method="LSODA", rtol=1e-10, atol=1e-15, args=(u[k] - OFFSET,),
                            events=reversal)
            y, t0 = sol.y[:, -1].copy(), float(sol.t[-1])
            if sol.status != 1 or t0 >= t1:
                break
            y[1] = 0.0
    return Record(np.arange(n) * TS, r, x, u)


def read_record(path: Path) -> Record:
    """A user's record from a CSV file with a header and the columns ``t, x, u[, r]`` [s, m, N, m]
    (``r``: the reference, when known)."""
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[1] not in (3, 4) or len(data) < 200:
        raise ValueError(f"{path}: expected the columns t, x, u [s, m, N] (and r [m]) and at least 200 rows, got "
                         f"{data.shape[1]} columns and {len(data)} rows")
    t, x, u = data[:, 0], data[:, 1], data[:, 2]
    r = data[:, 3] if data.shape[1] == 4 else np.full_like(t, np.nan)
    return Record(t - t[0], r, x, u)


def plot_record(rec: Record, outdir: Path) -> Path:
    known = bool(np.all(np.isfinite(rec.r)))
    fig, axes = new_figure(3 if known else 2, 1, size=(8.0, 6.5 if known else 5.0), sharex=True)
    axes = list(axes[:, 0])
    if known:
        axes[0].plot(rec.t, rec.r * 1e6, color="k", lw=1.0, label="reference")
    axes[0].plot(rec.t, rec.x * 1e6, lw=0.8, ls="--" if known else "-", label="encoder position")
    axes[0].set_ylabel("position [µm]")
    axes[0].legend(loc="upper right", fontsize=8)
    if known:
        axes[1].plot(rec.t, (rec.r - rec.x) * 1e9, lw=0.6, color="C3")
        axes[1].set_ylabel("tracking error [nm]")
    axes[-1].plot(rec.t, rec.u, lw=0.6, color="C2")
    axes[-1].set_ylabel("commanded force u [N]")
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title("1. closed-loop record (PID at 5 kHz, 10 nm encoder)")
    return save(fig, outdir, "1_record.png")


# --- 2. identification --------------------------------------------------------------------------

@dataclass(frozen=True)
class Identified:
    """What the identification step hands on: the fit, its score on held-out data, the stage."""

    fit: identify.FitResult
    validation: identify.Validation
    stage: pf.Oscillator


def record_loop(dt: float = TS) -> identify.DigitalLoop:
    """The record's controller as the closed-loop fit simulates it: the digital PID of
    :func:`synthetic_record` with the gains ``RECORD_PID`` at the sample time ``dt`` [s],
    ``C(z) = kp + ki dt z / (z - 1) + kd (z - 1) / (dt z)``. For a record of your own loop, set
    ``RECORD_PID`` to its gains, or return its law here (any python-control system)."""
    kp, ki, kd = RECORD_PID
    z = control.tf([1.0, 0.0], [1.0], dt)
    return identify.DigitalLoop.from_controller(kp + ki * dt * z / (z - 1.0) + kd * (z - 1.0) / (dt * z), dt)


def identify_stage(rec: Record, mass: float = MASS) -> Identified:
    """Fit a Dahl model and a force offset to the first 60 % of a closed-loop record, score it on
    the rest.

    A record with its reference (the synthetic one, or a CSV with the column ``r``): the closed-loop output error
    (:func:`prefriction.identify.fit_closed_loop`): the model simulated inside the record's loop
    (:func:`record_loop`) fitted to the measured positions and forces, the route for a record
    taken under feedback (an open-loop :class:`prefriction.identify.Motion` replay of a stiff
    loop's force drifts away from the positions). The held-out 40 %: the fitted stage in the
    same loop, run over the whole reference, its controller force against the recorded one.
    A CSV without the reference: a slow record's force is the friction plus the offset
    (:class:`prefriction.identify.ForceDisplacement`), scored on held-out data.

    The start values are an engineer's guesses (half the stiffness, 2/3 of the Coulomb force);
    ``gamma`` is held at 1, the structure the friction observer, the optimal move and the
    exported controller all take. The mass [kg] is the data sheet's. Another identification
    route replaces this one function and nothing else.
    """
    split = int(0.6 * len(rec.t))
    start = pf.Dahl(sigma=1e6, Fc=2.0, gamma=1.0)
    if not np.all(np.isfinite(rec.r)):
        part = identify.ForceDisplacement(rec.t[:split], rec.x[:split], rec.u[:split])
        held_out = identify.ForceDisplacement(rec.t[split:], rec.x[split:], rec.u[split:])
        fit = identify.fit(start, part, fixed=["gamma"], offset=True)
        return Identified(fit, fit.validate(held_out), pf.Oscillator(fit.model, mass=mass))
    loop = record_loop(float(rec.t[1] - rec.t[0]))
    part = identify.Motion(rec.t[:split], rec.x[:split], rec.u[:split], mass=mass, x_noise=NOISE, quantum=QUANTUM)
    fit = identify.fit_closed_loop(start, part, loop, rec.r[:split], fixed=["gamma"])
    _, force = identify.simulate_closed_loop(fit.model, loop, rec.t, rec.r, mass=mass, offset=fit.estimate("offset"))
    validation = identify.Validation(rec.t[split:], rec.u[split:], force[split:], "N", "Dahl")
    return Identified(fit, validation, pf.Oscillator(fit.model, mass=mass))


# --- 3. compensation ------------------------------------------------------------------------------

def back_and_forth(seconds: float) -> "pf.signals.Signal":
    """20 um S-curve moves forward and back every 50 ms (a sum of :class:`PointToPoint`)."""
    moves = [PointToPoint((-1.0) ** k * 20e-6, v_max=2e-3, a_max=0.5, j_max=500.0, start=0.05 * k)
             for k in range(max(int(seconds / 0.05), 1))]
    return sum(moves)


def reversal_spikes(res: "controllers.LoopResult", seconds: float) -> float:
    """The largest ``|r - x|`` [m] in the 5 ms after each move ends (where friction reverses)."""
    worst = 0.0
    for k in range(1, int(seconds / 0.05)):
        near = (res.t >= 0.05 * k) & (res.t <= 0.05 * k + 0.005)
        worst = max(worst, float(np.max(np.abs(res.error[near]))))
    return worst


# --- the chain ------------------------------------------------------------------------------------

def main(outdir: "str | Path", record_csv: "str | None" = None, quick: bool = False) -> dict:
    """Run every step, write the figures and the C code into ``outdir``, return the numbers."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    true_stage = pf.Oscillator(pf.Dahl(sigma=SIGMA, Fc=FC, gamma=1.0), mass=MASS)
    out: dict = {"figures": []}
    clock = time.perf_counter()

    # 1. record
    rec = read_record(Path(record_csv)) if record_csv else synthetic_record(0.6 if quick else 1.5)
    out["figures"].append(plot_record(rec, outdir))
    log(f"1. record: {len(rec.t)} samples over {rec.t[-1]:.3g} s ({time.perf_counter() - clock:.1f} s)")

    # 2. fit on the first 60 %, validate on the rest
    ident = identify_stage(rec)
    fit, val, stage = ident.fit, ident.validation, ident.stage
    out["figures"] += [fit.plot(outdir / "2_fit.png"), plot_validation(val, outdir)]
    out["fit"], out["validation"] = fit, val
    log(f"2. fit: sigma {fit.model.sigma:.4g} N/m, Fc {fit.model.Fc:.4g} N, offset {fit.estimate('offset'):.3g} N; "
        f"held out: rms {val.rms:.3g} N, fit {val.fit_percent:.3g} % ({time.perf_counter() - clock:.1f} s)")

    # 3. PID alone against PID + the fitted model's feedforward, in the true stage's loop
    pid = controllers.design_pid(stage, wn=WN)
    seconds = 0.2 if quick else 0.5
    ref = back_and_forth(seconds)
    feedforward = controllers.Feedforward(fit.model)
    observer = controllers.FrictionObserver(fit.model, pole=1000.0)  # the fitted gamma = 1 is its structure
    loops = {}
    for name, comp in (("PID alone", None), ("PID + feedforward", feedforward), ("PID + friction observer", observer)):
        loops[name] = controllers.simulate_loop(true_stage, pid, ref, seconds, Ts=TS, compensator=comp,
                                                quantization=QUANTUM, noise_rms=NOISE)
    out["spikes"] = {name: reversal_spikes(res, seconds) for name, res in loops.items()}
    out["figures"].append(plot_compensation(loops, outdir))
    log("3. compensation: reversal error " + ", ".join(f"{name} {e * 1e9:.3g} nm" for name, e in out["spikes"].items())
        + f" ({time.perf_counter() - clock:.1f} s)")

    # 4. the minimum-time move of the fitted stage, replayed through the true one
    move = pf.optimal.point_to_point(stage, 20e-6, u_max=U_MAX)
    on_true = pf.optimal.replay(true_stage, move.u, move.t_final * 1.5, 20e-6)
    out["move"], out["move_on_true"] = move, on_true
    out["figures"].append(plot_move(move, on_true, outdir))
    log(f"4. optimal move: {move.t_final * 1e3:.4g} ms; on the true stage it ends "
        f"{abs(on_true.x_error) * 1e9:.3g} nm off ({time.perf_counter() - clock:.1f} s)")

    # 5. the compensated controller in C, against the Python loop (no encoder step or noise: same numbers)
    ctl = export.controller_source(pid, "stage_ctl", outdir, Ts=TS, compensator=feedforward, mass=stage.mass)
    plant = export.plant_source(true_stage, "stage", outdir, Ts=TS)
    py = controllers.simulate_loop(true_stage, pid, ref, seconds, Ts=TS, compensator=feedforward)
    c = export.run_loop_c(ctl, plant, py.reference, ref.velocity(py.t))
    out["c_vs_python"] = float(np.max(np.abs(c.x - py.x)))
    out["figures"].append(plot_c(py, c, outdir))
    log(f"5. C code: {ctl.header.name} + {ctl.source.name}; max |x_C - x_Python| = {out['c_vs_python']:.2g} m "
        f"({time.perf_counter() - clock:.1f} s)")
    out["seconds"] = time.perf_counter() - clock
    return out


# --- figures of steps 2 to 5 ------------------------------------------------------------------------

def plot_validation(val: identify.Validation, outdir: Path) -> Path:
    """The held-out force: recorded against the fitted stage's (in the loop, or the friction of a
    force-displacement fit plus the offset)."""
    fig, axes = new_figure(2, 1, size=(8.0, 5.5), sharex=True)
    ax1, ax2 = axes[:, 0]
    ax1.plot(val.t, val.measured, color="0.55", lw=0.8, label="recorded")
    ax1.plot(val.t, val.predicted, color="C0", lw=1.2, label="fitted stage")
    ax1.set_ylabel("force u [N]")
    ax1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.02), ncol=2, fontsize=8, frameon=False)
    ax2.plot(val.t, val.measured - val.predicted, color="C3", lw=0.6)
    ax2.set_ylabel("recorded - fitted [N]")
    ax2.set_xlabel("time [s]")
    ax1.set_title(f"2. held-out 40 %: rms {val.rms:.3g} N, fit {val.fit_percent:.1f} %")
    return save(fig, outdir, "2_validation.png")


def plot_compensation(loops: dict, outdir: Path) -> Path:
    fig, axes = new_figure(2, 1, size=(8.0, 5.5))
    ax1, ax2 = axes[:, 0]
    first = next(iter(loops.values()))
    window = (first.t >= 0.095) & (first.t <= 0.17)  # one move forward and the start of the next
    ax1.plot(first.t * 1e3, first.reference * 1e6, color="k", lw=1.0)
    ax1.axvspan(95.0, 170.0, color="0.9")
    ax1.set_ylabel("reference [µm]")
    ax1.set_xlabel("time [ms] (shaded: the window below)")
    for name, res in loops.items():
        ax2.plot(res.t[window] * 1e3, res.error[window] * 1e9, lw=0.9, label=name)
    ax2.set_ylabel("tracking error r - x [nm]")
    ax2.set_xlabel("time [ms]")
    ax2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, fontsize=8)
    ax1.set_title("3. true stage in the loop: 10 nm encoder, 2 nm noise, fitted model")
    return save(fig, outdir, "3_compensation.png")


def plot_move(move: "pf.optimal.PointToPointResult", on_true: "pf.optimal.Replay", outdir: Path) -> Path:
    fig, axes = new_figure(2, 1, size=(8.0, 5.0), sharex=True)
    ax1, ax2 = axes[:, 0]
    ax1.plot(move.replay.run.t * 1e3, move.replay.run.x * 1e6, label="fitted stage (replayed)")
    ax1.plot(on_true.run.t * 1e3, on_true.run.x * 1e6, "--", label="true stage")
    ax1.axhline(move.distance * 1e6, color="k", lw=0.6, ls=":", label="target")
    ax1.set_ylabel("position [µm]")
    ax1.legend(loc="lower right", fontsize=8)
    tu = np.linspace(0.0, move.t_final * 1.5, 2000)
    ax2.plot(tu * 1e3, move.u(tu), color="C2")
    ax2.set_ylabel("force u [N]")
    ax2.set_xlabel("time [ms]")
    ax1.set_title(f"4. minimum-time 20 µm move, |u| <= {U_MAX:g} N: {move.t_final * 1e3:.3f} ms")
    return save(fig, outdir, "4_optimal_move.png")


def plot_c(py: "controllers.LoopResult", c: "export.LoopRun", outdir: Path) -> Path:
    fig, axes = new_figure(2, 1, size=(8.0, 5.5), sharex=True)
    ax1, ax2 = axes[:, 0]
    ax1.plot(py.t * 1e3, py.x * 1e6, label="Python loop (simulate_loop)")
    ax1.plot(py.t * 1e3, c.x * 1e6, "--", label="C controller + C stage")
    ax1.set_ylabel("position [µm]")
    ax1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=8)
    ax2.plot(py.t * 1e3, c.x - py.x, color="C3")
    ax2.set_ylabel("x_C - x_Python [m]")
    ax2.set_xlabel("time [ms]")
    ax1.set_title("5. exported PID + feedforward, compiled with gcc, against the Python loop")
    return save(fig, outdir, "5_c_code.png")


if __name__ == "__main__":
    usage = "usage: stage_workflow.py OUTDIR [RECORD.csv] [--quick]"
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print(usage)
        raise SystemExit(0)
    args = [a for a in sys.argv[1:] if a != "--quick"]
    if not args or len(args) > 2 or any(a.startswith("-") for a in args):
        print(f"{usage}\nerror: one output directory and at most one CSV record expected, got {sys.argv[1:]!r}",
              file=sys.stderr)
        raise SystemExit(2)
    result = main(args[0], args[1] if len(args) > 1 else None, quick="--quick" in sys.argv[1:])
    print(f"wrote {len(result['figures'])} figures and the C code to {args[0]} in {result['seconds']:.0f} s")
