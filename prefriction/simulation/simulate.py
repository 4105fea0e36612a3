"""Time simulation of the oscillator (2.1) with any friction model, every reversal located (CasADi).

Between two velocity reversals the branch direction ``s`` is fixed and the model's right-hand
side is smooth (:class:`prefriction.FrictionModel`). The integrator (``casadi.integrator``,
plugin ``erk``: adaptive explicit Runge-Kutta 5(4), compiled with gcc and cached on disk by
:mod:`prefriction.simulation.compiled`) locates every zero of ``s v`` on its dense output (to
round-off) and restarts on the new branch through an event transition; the model's own events
(Dahl's saturation for gamma < 1), touches and rest of a forced mass are events too (see
:mod:`prefriction.simulation.plant`). One plant is compiled per model structure: numbers,
input numbers and the tolerance are run-time inputs (``docs/simulator.md``).

Unforced runs without dense output use a compact model (2 states for Dahl with gamma >= 1: one
call per reversal, the next branch started in Python); forced or dense runs record up to
``K = 2`` reversals per call in a register. Calls go through a persistent argument buffer, so
the cost per reversal is the integration itself (about 60 steps at ``rtol = 1e-8``), the same
for 50 or 1e4 reversals.

The model is integrated in normalised units (:mod:`prefriction.units`) with every state scaled
per call by the current amplitude, so the relative accuracy does not depend on ``sigma``,
``Fc``, the mass or the energy (1e-20 to 1e6 times ``Fc^2 / sigma`` in the first excursion);
results are converted to SI. The tolerance ``eps`` of the plant is ``rtol`` times a calibration
factor such that the error of reversal times, positions and forces over 50 reversals stays
below ``rtol`` (``prefriction bench``); global errors grow linearly with the number of cycles,
as for any one-step method.

This module validates the arguments and assembles the result: the plant (its layout and
driver) is built in :mod:`prefriction.simulation.build`, run by
:func:`~prefriction.simulation.drive.drive` in :mod:`prefriction.simulation.drive`, the
reversal table :mod:`prefriction.simulation.lazy_table`, the compiled integrator and its buffers
:mod:`prefriction.simulation.integrator`, the force scale of forced runs
:mod:`prefriction.simulation.force_scale`.
"""

from __future__ import annotations

import math
import time
from typing import Any, Optional, Union

import numpy as np

from prefriction.signals import Constant, compiled_form
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.drive import RAMP_ROUNDOFF, drive
from prefriction.simulation.samples import N_DENSE, samples_si
from prefriction.simulation.rest import initial_direction
from prefriction.simulation.run import Run
from prefriction.simulation.plant import EPS_CAL, PlantSpec
from prefriction.simulation.force_scale import MAX_AMPLITUDE, MIN_AMPLITUDE, applied_force_scale, check_amplitude
from prefriction.simulation.budget import check_input_budget
from prefriction.simulation.build import build_plant
from prefriction._validation import check_count, check_finite, check_positive
from prefriction.models import Oscillator, check_oscillator
from prefriction.simulation.lazy_table import reversal_table
from prefriction.simulation.result import RunStats, SimulationResult
from prefriction.units import Scales

__all__ = ["MAX_AMPLITUDE", "MAX_PERIODS", "MAX_REVERSALS", "METHODS", "MIN_AMPLITUDE", "RAMP_ROUNDOFF", "RunStats",
           "SimulationResult", "simulate"]

METHODS = ("native", "erk")
"""Integrators of :func:`simulate`: ``"native"`` (the C driver, ``docs/simulator.md#native``)
and ``"erk"`` (CasADi's integrator, the reference the native driver is tested against)."""

_K = 2  # reversals recorded per integrator call (register length; forced or dense runs)
_MIN_ORDER = 2  # continuous controllers are padded to this order (one plant for P, PD, PID)
_ZERO = Constant(0.0)  # the input of a sampled loop without an input force (the hold is added)
MAX_REVERSALS = 10**7
"""Most reversals of one :func:`simulate` call, requested or reached by ``t_end`` (the run holds
its table in memory: about 100 bytes per reversal at the peak, so about 1 GB;
``docs/simulator.md#limits``)."""
MAX_PERIODS = 10**7
"""Most sample periods ``t_end / Ts`` of a sampled controller (one controller step and one sample each)."""
_CAL = EPS_CAL  # calibration of the run-time tolerance eps: global error over 50 reversals ~ 0.7 rtol


def simulate(
    system: Oscillator,
    v0: float,
    *,
    x0: float = 0.0,
    F0: float = 0.0,
    reversals: Optional[int] = None,
    t_end: Optional[float] = None,
    rtol: float = 1e-8,
    atol: Optional[float] = None,
    method: str = "native",
    dense: Union[bool, np.ndarray, list] = False,
    feedback: Optional[LinearFeedback] = None,
    jit: bool = True,
) -> SimulationResult:
    """Simulate the oscillator (2.1) ``m x'' = u - F`` with any friction model, every reversal located.

    Parameters
    ----------
    system : Oscillator
        Mass, friction model (:class:`prefriction.Dahl` or any :class:`prefriction.FrictionModel`)
        and optional input force ``u(t)`` [N]: a :mod:`prefriction.signals` signal (compiled once
        per kind), samples ``(t, u)`` (linear between samples, held outside them; the
        integration is broken at the sample times) or a callable that accepts a CasADi symbol
        (compiled once per function).
    v0 : float
        Initial velocity [m/s]. If ``v0 = 0`` the motion starts in direction ``-sign(F0)``
        (unforced) or ``sign(u(0) - F0)`` (forced); with no net force the mass rests. A motion
        smaller than :data:`MIN_AMPLITUDE` normalised units (e.g. a denormal ``v0``) is refused, and
        so is ``|v0|`` above :data:`MAX_AMPLITUDE` velocity units ``Fc / sqrt(m sigma)``.
    x0, F0 : float, default 0.0
        Initial position [m] and friction force [N], ``|F0| <= max_hysteretic_force`` of the
        model (Dahl: ``Fc``; LuGre: ``Fs``).
    reversals : int, optional
        Stop at this many reversals, ``1 <= reversals <=`` :data:`MAX_REVERSALS`.
    t_end : float, optional
        Stop at this time [s] (> 0). At least one of ``reversals`` and ``t_end`` is required;
        a forced system or a closed loop needs ``t_end``.
    rtol : float, default 1e-8
        Relative tolerance, ``1e-13 <= rtol <= 1e-2``; reversal times, positions and forces come
        out with a relative error of about ``rtol`` (see ``prefriction bench``).
    atol : float, optional
        Tolerance relative to the current amplitude of the motion (dimensionless); defaults to
        ``rtol``. The error control is absolute on states scaled by that amplitude, so the two
        act alike and the smaller one is used (``docs/simulator.md``).
    method : str, default "native"
        One of :data:`METHODS`. ``"native"``: the C driver (the model's and the input's
        generated code driven by a Runge-Kutta 5(4) in C, one C call per run or block;
        ``docs/simulator.md#native``) where it applies (a C compiler; a sampled controller under
        any input force), else CasADi's integrator. ``"erk"``: CasADi's integrator (adaptive
        explicit Runge-Kutta 5(4) with events; ``"rosenbrock"`` works with the same events but
        is 5-10 times slower on these non-stiff problems; ``cvodes``/``idas`` events and
        ``collocation`` fail: docs/simulator.md, why only erk). Both agree to the tolerance.
    dense : bool or array_like, default False
        ``False``: reversal table only (no dense output is computed). ``True``: samples every
        ``2 pi / 64`` normalised time units (64 per small oscillation). An array: samples at
        these times [s], increasing, within ``[0, t_end]``.
    feedback : LinearFeedback, optional
        Closed loop ``u = C xc + D (r - x)`` added to the input force (see
        :class:`prefriction.simulation.feedback.LinearFeedback`). A sampled controller also returns
        samples at its sample instants; ``t_end / Ts`` at most :data:`MAX_PERIODS`.
    jit : bool, default True
        Compile the integrator with the C compiler (cached on disk); the environment variable
        ``PREFRICTION_NO_JIT=1`` or a missing compiler selects the interpreted integrator.

    Returns
    -------
    SimulationResult
        Reversal table (SI), stop status, run statistics, the model events per half-cycle
        (``events``; total ``stats.events``) and, if requested, samples.

    Raises
    ------
    TypeError
        For arguments of the wrong type, or an input/reference callable that cannot be traced.
    ValueError
        For values out of range, or neither ``reversals`` nor ``t_end``.
    SolverError
        If the integrator fails; the message names the time, the state and what to try.
    """
    model = check_oscillator(system, "simulate")
    try:
        hash(model.structure_key)
    except TypeError:
        raise TypeError(f"{type(model).__name__}.structure_key must be hashable (a tuple of numbers and strings): "
                        f"it keys the compiled plant; got {model.structure_key!r:.120}") from None
    v0 = check_finite("v0", v0)
    x0 = check_finite("x0", x0)
    F0 = check_finite("F0", F0)
    Fc = system.friction.Fc
    F_max = system.friction.max_hysteretic_force
    if abs(F0) > F_max:
        raise ValueError(f"F0 must lie in [-{F_max!r}, {F_max!r}] N (the model's max_hysteretic_force, "
                         f"{type(system.friction).__name__}), got {F0!r}")
    if reversals is None and t_end is None:
        raise ValueError("give reversals (number of reversals) or t_end (end time [s]) or both; got neither")
    # one budget for every run that can grow: at most MAX_REVERSALS reversals, requested or reached by t_end
    n_target = MAX_REVERSALS if reversals is None else check_count(
        "reversals", reversals, 1, MAX_REVERSALS, "the reversal table is held in memory")
    t_end_si = math.inf if t_end is None else check_positive("t_end", t_end)
    check_input_budget(system.u, t_end_si, MAX_REVERSALS)
    rtol = check_positive("rtol", rtol)
    if not 1e-13 <= rtol <= 1e-2:
        raise ValueError(f"rtol must lie in [1e-13, 1e-2], got {rtol!r}")
    atol = rtol if atol is None else check_positive("atol", atol)
    if not 1e-16 <= atol <= 1e-2:
        raise ValueError(f"atol must lie in [1e-16, 1e-2], got {atol!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if feedback is not None and not isinstance(feedback, LinearFeedback):
        raise TypeError(f"feedback must be a prefriction LinearFeedback or None, got {feedback!r}")
    if not isinstance(jit, bool):
        raise TypeError(f"jit must be True or False, got {jit!r}")
    forced = system.forced or feedback is not None
    if forced and t_end is None:
        raise ValueError("t_end is required for a forced system or a closed loop (a reversal may never come)")
    if feedback is not None and feedback.sampled and t_end_si / feedback.Ts > MAX_PERIODS:
        raise ValueError(f"Ts = {feedback.Ts!r} s of the sampled controller gives t_end / Ts = {t_end_si / feedback.Ts:.3g} "
                         f"sample periods; allowed at most {MAX_PERIODS:_} (one controller step and sample each): "
                         f"Ts >= {t_end_si / MAX_PERIODS:.3g} s or a shorter t_end")

    sc = Scales.of(system)
    fb_kind, n_c = "none", 0
    n_user = 0 if feedback is None else feedback.n_states
    if feedback is not None:
        fb_kind = "sampled" if feedback.sampled else "continuous"
        if fb_kind == "continuous":
            feedback = _padded(feedback, _MIN_ORDER)  # P, PD and PID loops share one plant
            n_c = feedback.n_states
    want_dense = not (dense is False or dense is None)
    times_si = _dense_times(dense, t_end_si) if want_dense and not isinstance(dense, bool) else None
    if want_dense and fb_kind == "sampled":
        raise ValueError("dense samples are not available with a sampled controller: its samples are at k Ts")
    u_plant, fb_plant = system.u, fb_kind
    if fb_kind == "sampled" and compiled_form(system.u if system.forced else _ZERO).key == ("PiecewiseLinear",):
        # the held force joins the input's piecewise-linear pieces: the plant of an open loop
        u_plant, fb_plant = (system.u if system.forced else _ZERO), "none"
    spec = PlantSpec.of(
        model, u_plant, feedback.reference if fb_kind == "continuous" else None,
        fb=fb_plant, n_c=n_c, energy=want_dense, K=_K, n_out=N_DENSE if want_dense else 1,
        method="erk", compact=True,
    )
    force_scale = applied_force_scale(system, feedback, x0, t_end_si) / Fc if forced else 0.0
    check_amplitude(v0, F0, force_scale, sc)
    breaks = []
    if system.forced:
        breaks.append(np.asarray(system.u.breaks()) / sc.t)
    if fb_kind == "continuous":
        breaks.append(np.asarray(feedback.reference.breaks()) / sc.t)
    breaks = _sample_times(np.unique(np.concatenate(breaks)) if breaks else np.zeros(0))
    t_end_n = t_end_si / sc.t
    plant = build_plant(system.friction, spec, feedback, jit, native=method == "native",
                        held_input=fb_kind == "sampled")
    # error control on states scaled by amplitude * eps (the plant's run-time tolerance)
    eps = min(rtol, atol) * _CAL * math.sqrt(plant.L.n_active / plant.L.nx)
    run = Run(system, spec, feedback, eps, plant, sc=sc)
    run.eps_native = min(rtol, atol) * _CAL  # the native drivers' RMS norm runs over the active states only
    run.snap = rtol
    run.P0 = run._constant_params(run.L)
    run.force_scale = force_scale

    xc0 = np.array(feedback.xc0, dtype=float) if feedback is not None else np.zeros(0)
    run.st, s0 = _initial_state(run, x0, v0, F0, xc0, stops=forced or t_end is not None)
    run.breaks = breaks

    start = time.perf_counter()
    samples, u_hist = drive(run, t_end_n, n_target, None if times_si is None else times_si / sc.t, want_dense, xc0,
                            rtol)
    if reversals is None and len(run.rev) >= n_target:
        raise ValueError(
            f"t_end = {t_end_si:.6g} s needs more than {MAX_REVERSALS:_} reversals (the reversal table is held in "
            f"memory): the run reached {MAX_REVERSALS:_} at t = {run.rev[-1][0] * sc.t:.6g} s; allowed: a t_end below "
            f"that, or reversals=n to stop after n reversals")
    if len(run.rev) >= n_target:
        status, message = 1, f"reached {int(n_target)} reversals at t = {run.rev.t[int(n_target) - 1] * sc.t:.9g} s"
    else:
        status, message = 0, f"reached t_end = {t_end_si:.9g} s"
    if run.note:
        message += f"; {run.note}"
    wall = time.perf_counter() - start

    n_rev = int(min(len(run.rev), n_target))
    table, W_r = reversal_table(run.rev.columns(n_rev, writable=True), system, s0, v0, F0, run.sc)
    events = np.array(run.rev_events[:n_rev], dtype=int)
    # after the last reversal: the events up to t_end (a run stopped at its reversal has none)
    total = int(events.sum()) + (int(run.st.get("ne", 0)) if len(run.rev) <= n_rev else 0)
    stats = RunStats(wall_time=wall, setup_time=run.setup_time, calls=run.calls, steps=run.steps, jit=run.mode,
                     events=total)
    extra = samples_si(run, samples, u_hist, times_si, n_user) if len(samples) else {}
    return SimulationResult(reversals=table, status=status, message=message, stats=stats, work_input=W_r,
                            events=events, **extra)




def _sample_times(breaks: np.ndarray) -> np.ndarray:
    """The sample times after 0 (normalised) at which the run is broken: ``breaks`` without
    repeats to round-off (the input's and the reference's own copies of one time)."""
    b = breaks[breaks > 0]
    keep = np.ones(b.size, dtype=bool)
    keep[1:] = np.diff(b) > 1e-12 * np.maximum(1.0, b[1:])
    return b[keep]




def _dense_times(dense: Any, t_end: float) -> np.ndarray:
    """The requested sample times [s] as an array; ``ValueError`` unless increasing within [0, t_end]."""
    try:
        times = np.asarray(dense, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"dense must be True, False or a 1-D array of sample times [s], got {dense!r}") from None
    if times.ndim != 1 or times.size < 1 or not np.all(np.isfinite(times)):
        raise ValueError("dense must be True, False or a 1-D array of finite sample times [s]")
    if np.any(np.diff(times) <= 0) or times[0] < 0 or times[-1] > t_end:
        raise ValueError(f"dense sample times must increase and lie in [0, t_end] = [0, {t_end!r}] s")
    return times


def _initial_state(run: Run, x0: float, v0: float, F0: float, xc0: np.ndarray, *, stops: bool) -> tuple[dict, float]:
    """Normalised initial state of ``run`` and the initial branch direction ``s0``.

    If ``v0 = 0`` the motion starts in the direction of the net force; with no net force the mass
    rests (``ValueError`` unless the run ``stops`` at a time: no reversal would ever come).
    """
    system, feedback, sc = run.system, run.fb, run.sc
    model = system.friction
    Fc = model.Fc
    u0 = float(system.u(0.0)) if system.forced else 0.0
    if feedback is not None:
        e0 = float(feedback.reference(0.0)) - x0
        u0 += float(feedback.force(xc0, e0))
    acc0 = (u0 - F0) / Fc
    s0, rest = initial_direction(v0, acc0, F0)
    if rest and not stops:
        raise ValueError("v0 = 0 and F0 = 0 without input: the mass rests, no reversal will come; give t_end")
    z, m = model.initial_state(F0 / Fc, s0)
    # the friction force at t = 0: for a rate-dependent model (LuGre: sigma1 z' + sigma2 v) it
    # differs from the state's force F0 when v0 != 0
    F = float(model.force(list(z), list(m), v0 / sc.v, s0, run.q))
    st = {"x": x0 / sc.x, "v": v0 / sc.v, "F": F, "z": list(z), "m": list(m),
          "t": 0.0, "s": s0, "rest": rest, "W": 0.0, "Ef": 0.0, "xc": xc0, "uhold": 0.0, "ne": 0}
    if run.L.potential:  # the branch's mechanical energy v^2 / 2 + potential - W (speed at events)
        st["Eb"] = 0.5 * st["v"] ** 2 + float(model.branch_potential(st["z"], st["m"], s0, run.q))
    return st, s0




def _padded(fb: LinearFeedback, order: int) -> LinearFeedback:
    """``fb`` with zero states appended up to ``order`` (they never move and add no force)."""
    n = fb.n_states
    if n >= order:
        return fb
    A = np.zeros((order, order))
    A[:n, :n] = fb.A
    B = np.zeros((order, 1))
    B[:n] = fb.B
    C = np.zeros((1, order))
    C[:, :n] = fb.C
    xc0 = np.concatenate([fb.xc0, np.zeros(order - n)])
    k_aw = None if fb.u_max is None else np.concatenate([fb.k_aw, np.zeros(order - n)])
    return LinearFeedback(A=A, B=B, C=C, D=fb.D, Ts=fb.Ts, reference=fb.reference, xc0=xc0, u_max=fb.u_max,
                          k_aw=k_aw)
