"""``prefriction bench --export``: time per step of the exported C code on this machine.

Each friction model is exported with :func:`prefriction.export.c_source`, compiled with
``gcc -std=c99 -O2`` and timed over 1e5 samples (a C timing loop reading the process's CPU
time, so that waiting for a shared core does not count; the least of ``repeats`` passes), next to the same force from :func:`prefriction.friction_along` (CasADi's compiled
block, warm) and from :class:`prefriction.FrictionStream` (one Python call per sample), with the
largest difference of the C forces from ``friction_along``. The exported plant and a compensated
loop (controller and plant in C) run 1e5 samples next to ``controllers.simulate_loop`` (its
compiled loop), timed per sample, with the largest difference of the positions. Target: <= 200 ns per step for
Dahl and LuGre.
"""

from __future__ import annotations

import sys
import tempfile
import time

import numpy as np

__all__ = ["run"]

N = 100_000
TS = 2.0**-13
TARGET_NS = 200.0
LOOP_SAMPLES = 100_000


def _cases() -> list[tuple[str, object, float | None]]:
    from prefriction.models import GMS, Dahl, LuGre, MaxwellSlip

    return [
        ("Dahl gamma = 1", Dahl(2e5, 1.5, 1.0), None),
        ("Dahl gamma = 0.5", Dahl(2e5, 1.5, 0.5), None),
        ("Dahl gamma = 3", Dahl(2e5, 1.5, 3.0), None),
        ("LuGre", LuGre(2e5, 400.0, 0.5, 1.2, 1.6, 2e-3), TS),
        ("Maxwell-slip, 3 elements", MaxwellSlip([1e5, 6e4, 3e4], [0.3, 0.5, 0.6]), None),
        ("GMS, 3 elements", GMS([1e5, 6e4, 3e4], [0.3, 0.3, 0.4], 1.2, 1.6, 2e-3, 50.0), TS),
    ]


def _motion() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(N) * TS
    return t, 1e-5 * np.sin(2 * np.pi * 3 * t) * (1.0 + 0.9 * np.sin(2 * np.pi * 0.7 * t)) + 2e-6


def _warm(fun, repeats: int) -> float:
    fun()
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()  # CPU time, as the C timing loop measures
        fun()
        best = min(best, time.process_time() - start)
    return best


def _model_rows(repeats: int, d: str) -> tuple[list[str], bool]:
    from prefriction.along import FrictionStream, friction_along
    from prefriction.export.model import c_source
    from prefriction.export.run import run_c

    t, x = _motion()
    rows, ok = [], True
    for i, (label, model, Ts) in enumerate(_cases()):
        print(f"bench --export: {label}", file=sys.stderr)
        src = c_source(model, f"m{i}", d, Ts=Ts)
        run = run_c(src, x, rounds=repeats)
        along = friction_along(model, t, x)
        t_along = _warm(lambda: friction_along(model, t, x), repeats) / N
        stream_n = 2000
        def stream() -> None:
            s = FrictionStream(model, x[0], t0=t[0])
            for k in range(1, stream_n):
                s.step(x[k], t[k])
        t_stream = _warm(stream, 1) / (stream_n - 1)
        diff = float(np.max(np.abs(run.F[1:] - along.F[1:])) / np.max(np.abs(along.F)))
        ns = run.ns_per_step
        if label.startswith(("Dahl gamma = 1", "LuGre")):
            ok = ok and ns <= TARGET_NS
        rows.append(f"{label:26s} {ns:9.1f} {t_along * 1e9:12.1f} {t_stream * 1e9:14.0f} "
                    f"{t_along * 1e9 / ns:8.1f}x {t_stream * 1e9 / ns:8.0f}x {diff:11.2e}")
    return rows, ok


def _loop_rows(repeats: int, d: str) -> list[str]:
    from prefriction.controllers import Feedforward, PID, simulate_loop
    from prefriction.export.controller import controller_source
    from prefriction.export.loop_run import run_loop_c
    from prefriction.export.plant import plant_source
    from prefriction.export.plant_run import run_plant_c
    from prefriction.models import Dahl, LuGre, Oscillator
    from prefriction.signals import Sine

    rows = []
    for label, stage in (("Dahl stage", Oscillator(Dahl(1e5, 1.0, 1.0), mass=0.5)),
                         ("LuGre stage", Oscillator(LuGre(1e5, 300.0, 0.4, 1.0, 1.3, 1e-3), mass=0.5))):
        print(f"bench --export: {label}", file=sys.stderr)
        Ts, n = 1e-4, LOOP_SAMPLES
        ref = Sine(1e-5, 20.0)
        tk = np.arange(n) * Ts
        v = 1e-5 * 2 * np.pi * 20 * np.cos(2 * np.pi * 20 * tk)
        pid = PID(kp=4e5, ki=2e7, kd=600.0)
        ff = Feedforward(stage.friction)
        plant = plant_source(stage, "stage", d, Ts=Ts)
        ctl = controller_source(pid, "ctl", d, Ts=Ts, compensator=ff, mass=stage.mass)
        sim = [None]

        def loop() -> None:
            sim[0] = simulate_loop(stage, pid, ref, (n - 1) * Ts, Ts=Ts, compensator=ff)
        t_sim = _warm(loop, 1) / n
        res = sim[0]
        c_loop = run_loop_c(ctl, plant, np.asarray(res.reference), v, rounds=repeats)
        free = run_plant_c(plant, np.zeros(2000), rounds=repeats)
        diff = float(np.max(np.abs(c_loop.x - res.x)) / np.max(np.abs(res.x)))
        rows.append(f"{label:12s} {c_loop.ns_per_sample / 1e3:8.2f} {t_sim * 1e6:16.2f} "
                    f"{t_sim * 1e9 / c_loop.ns_per_sample:8.1f}x {free.ns_per_step / 1e3:10.3f} {diff:12.1e}")
    return rows


def run(repeats: int = 5) -> str:
    """The tables of the export benchmark (module notes) and the target's verdict.

    Parameters
    ----------
    repeats : int, default 5
        Timed passes per measurement; the least time is kept.

    Returns
    -------
    str
        The printed text.
    """
    from prefriction.export.run import gcc

    if gcc() is None:
        return "prefriction bench --export: gcc is not on the PATH; nothing measured\n"
    with tempfile.TemporaryDirectory(prefix="pf-bench-export-") as d:
        rows, ok = _model_rows(repeats, d)
        loops = _loop_rows(repeats, d)
    head = (f"exported friction models: ns per sample, {N} samples (C: gcc -O2, CPU time, best of {repeats}; friction_along: "
            f"compiled CasADi block, warm; FrictionStream: Python, 2000 samples; CPU times)\n"
            f"{'model':26s} {'C':>9s} {'along':>12s} {'stream':>14s} {'along/C':>9s} {'stream/C':>9s} {'|C-along|':>11s}")
    loop_head = (f"\nexported loop (PID + Feedforward + the stage's period, every reversal located), Ts = 1e-4 s, "
                 f"{LOOP_SAMPLES} samples of a 10 um 20 Hz sine, against simulate_loop (compiled CasADi loop, warm)\n"
                 f"{'stage':12s} {'C us':>8s} {'simulate_loop us':>16s} {'ratio':>9s} {'rest us':>10s} "
                 f"{'|x_C - x_sim|':>12s}")
    verdict = (f"\ntarget: C step <= {TARGET_NS:.0f} ns for Dahl (gamma = 1) and LuGre: "
               f"{'PASS' if ok else 'FAIL'}")
    return "\n".join([head, *rows, loop_head, *loops, verdict]) + "\n"
