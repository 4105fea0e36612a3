"""Closed-loop simulation of a python-control controller around the reversal-aware friction stage.

:func:`simulate_loop` turns any SISO, proper python-control LTI controller (error ``e = r - x``
[m] to force ``u`` [N]) into a :class:`prefriction.simulation.feedback.LinearFeedback`. A
sampled controller runs in compiled code, many samples per call
(:func:`prefriction.simulation.loops.run_sampled`); a continuous one, or a sampled one with a
disturbance input, through :func:`prefriction.simulate`. Both integrate ``m x'' = u - F`` with
the stage's friction model (any model of the protocol :class:`prefriction.models.FrictionModel`:
Dahl, Maxwell-slip, GMS, LuGre) and land on every velocity reversal and model event (inside
the sample intervals too) (``docs/controllers.md``).
"""

from __future__ import annotations

import math
from typing import Any, Callable, Optional, Union

import control
import numpy as np

import prefriction
from prefriction._validation import (check_count, check_finite, check_nonnegative, check_positive, check_real_array,
                                     check_signal)
from prefriction.models import Oscillator
from prefriction.signals import Signal
from prefriction.simulation.feedback import LinearFeedback, sample_count
from prefriction.simulation.loops import run_sampled
from prefriction.simulation.loops.compiled_loop import MAX_DELAY
from prefriction.simulation.loops.runner import Compensation, Measurement

from ._linear import _check_system, _sample_time, as_lti, closed_loop
from ._loop_result import LoopResult
from ._pid import PID
from ._reference import reference_velocity
from .compensators import Compensator, scaled_model

Reference = Union[float, Callable[[Any], Any], tuple]

DISCRETIZATIONS = ("zoh", "foh", "tustin", "bilinear", "backward_diff", "forward_diff", "euler", "gbt", "matched")


def _evaluate(reference: Reference, t: np.ndarray) -> np.ndarray:
    """Numeric reference at times ``t`` [s] (samples: linear, held constant outside their range)."""
    if isinstance(reference, tuple):
        return np.interp(t, reference[0], reference[1])
    if isinstance(reference, Signal):  # vectorised
        return np.broadcast_to(np.asarray(reference(t), dtype=float), t.shape).copy()
    if callable(reference):
        vals = np.empty(t.shape)
        for i, ti in enumerate(t):
            v = reference(float(ti))
            vals[i] = float(v) if np.ndim(v) == 0 or np.size(v) == 1 else math.nan
            if not math.isfinite(vals[i]):
                raise ValueError(f"reference r(t) must return a finite scalar [m], got {v!r} at t={ti!r} s")
        return vals
    return np.full(t.shape, float(reference))


def _check_reference(reference: Any) -> Reference:
    """The reference as :func:`check_signal` returns it; samples ``(t, r)`` must be finite real
    numbers (``TypeError``/``ValueError`` naming the reference otherwise)."""
    if isinstance(reference, tuple) and len(reference) == 2:
        for part, letter, unit in zip(reference, ("t", "r"), ("s", "m")):
            check_real_array(f"reference samples {letter}", part, unit)
    return check_signal("reference", reference, "m", "r")


def _check_t_out(t_out: Any, t_end: float) -> np.ndarray:
    """``t_out`` as a 1-D float array of strictly increasing times in ``[0, t_end]`` [s]."""
    times = check_real_array("t_out", t_out, "s", lo=0.0, hi=t_end)
    if times.ndim != 1 or times.size < 1:
        raise ValueError(f"t_out must be a 1-D array of at least 1 output time [s], got an array of shape {times.shape}")
    if np.any(np.diff(times) <= 0.0):
        i = int(np.flatnonzero(np.diff(times) <= 0.0)[0])
        raise ValueError(f"t_out must be strictly increasing, got t_out[{i + 1}] = {float(times[i + 1])!r} "
                         f"<= t_out[{i}] = {float(times[i])!r}")
    return times


def _dc_gain(C: control.StateSpace) -> Optional[float]:
    try:
        with np.errstate(all="ignore"):
            g = complex(np.squeeze(control.dcgain(C)))
    except (ValueError, np.linalg.LinAlgError):
        return None
    if not math.isfinite(g.real) or g.real <= 0.0 or abs(g.imag) > 1e-9 * abs(g.real):
        return None
    return g.real


def simulate_loop(
    system: Oscillator,
    controller: "PID | control.LTI",
    reference: Reference,
    t_end: float,
    *,
    Ts: Optional[float] = None,
    discretization: str = "zoh",
    x0: float = 0.0,
    v0: float = 0.0,
    F0: float = 0.0,
    xc0: Any = None,
    t_out: Any = None,
    rtol: float = 1e-8,
    jit: bool = True,
    compensator: Optional[Compensator] = None,
    quantization: float = 0.0,
    noise_rms: float = 0.0,
    seed: int = 0,
    delay: int = 0,
    mismatch: Optional[tuple[float, float]] = None,
) -> LoopResult:
    """Simulate the positioning loop ``u = C(r - x)`` around a friction stage, every reversal located.

    The plant is :func:`prefriction.simulate`'s: ``m x'' = u - F`` with the stage's friction
    model (Dahl (3.2), Maxwell-slip, GMS, LuGre or any other model of the protocol
    :class:`prefriction.models.FrictionModel`), integrated in normalised units, with each
    velocity reversal and model event (e.g. an element that starts to slip) located, inside a
    sample interval too, and the model's state switched there.

    Parameters
    ----------
    system : prefriction.Oscillator
        The stage: mass [kg] and friction model. An input force of the oscillator
        (``system.u``) acts as a disturbance added to the control force.
    controller : controllers.PID or control.TransferFunction or control.StateSpace
        SISO, proper controller from the error ``e = r - x`` [m] to the force ``u`` [N].
        Continuous (its states are integrated with the plant) or discrete with ``dt > 0``
        (sampled-data loop: ``u[k] = C xc[k] + D e[k]`` held constant over each sample
        interval, zero-order hold), e.g. from ``control.c2d``. A :class:`PID` with a force
        limit ``u_max`` applies ``clip(v, -u_max, u_max)`` to its output ``v`` and corrects
        its integrator by back-calculation with ``k_aw`` of :meth:`PID.back_calculation_gain`:
        ``xc[k+1] = A xc[k] + B e[k] + Ts k_aw (u[k] - v[k])`` in a sampled loop,
        ``xc' = A xc + B e + k_aw (u - v)`` in a continuous one (Astrom and Hagglund).
    reference : float, callable or (t, r)
        Position reference [m]: a number (a step at ``t = 0``), a callable ``r(t)`` of time
        [s], or samples ``(t, r)`` of equal length (linear between samples, held constant
        outside them). With a continuous controller a callable must accept a CasADi symbol
        (numpy ufuncs and arithmetic, no ``if`` on ``t``); with a sampled controller any
        Python callable works (it is read at the sample instants only).
    t_end : float
        End time [s], ``0 < t_end < inf``; a sampled loop has at most
        :data:`prefriction.simulation.feedback.MAX_SAMPLES` sample instants (``t_end / Ts``).
    Ts : float, optional
        Sample time [s], ``0 < Ts < inf``. Default: the discrete controller's ``dt``; ``None``
        for a continuous controller. Given with a continuous controller, the controller is
        discretised with ``control.c2d(controller, Ts, method=discretization)``.
    discretization : str, default "zoh"
        ``control.c2d`` method used when a continuous controller is given with ``Ts``.
    x0, v0, F0 : float, default 0.0
        Initial position [m], velocity [m/s] and friction force [N] (``|F0|`` at most the
        model's ``max_hysteretic_force``: ``Fc`` for Dahl, ``Fs`` for LuGre).
    xc0 : array_like, optional
        Initial controller state, one finite real number per controller state (zeros by
        default).
    t_out : array_like, optional
        Output times [s] of a continuous loop, strictly increasing in ``[0, t_end]`` (default 2001
        equally spaced). Not allowed with a sampled controller (its outputs are at ``k Ts``).
    rtol : float, default 1e-8
        Relative tolerance of the simulator, ``1e-13 <= rtol <= 1e-2``.
    jit : bool, default True
        Let the simulator compile its integrator (cached on disk).
    compensator : controllers.Feedforward, LuGreObserver, FrictionObserver or DisturbanceObserver, optional
        A friction compensator whose force is added to the controller's at every sample
        (sampled loops without an input force of the oscillator; ``docs/compensation.md``).
    quantization : float, default 0.0
        Encoder step [m], ``>= 0``: the measured position is rounded to it (0: exact).
    noise_rms : float, default 0.0
        Standard deviation [m] of white Gaussian measurement noise, ``>= 0``, drawn from
        ``numpy.random.default_rng(seed)``.
    seed : int, default 0
        Seed of the measurement noise.
    delay : int, default 0
        Measurement delay in whole samples, ``0 <= delay <= 8``: the controller and the
        compensator see ``x(t_{k - delay})``.
    mismatch : (float, float), optional
        Factors ``(stiffness, coulomb)`` applied to the compensator's friction model
        (:func:`controllers.compensators.scaled_model`): the compensator's model differs from
        the plant's; each factor finite and ``> 0``. Refused with the model-free
        :class:`DisturbanceObserver` (it has no model to scale).

    Returns
    -------
    LoopResult
        Samples ``t, reference, x, v, F, u, error`` and the reversal table; ``summary()``.

    Raises
    ------
    ValueError
        Non-positive or non-finite ``t_end`` or ``Ts``; more than ``MAX_SAMPLES`` samples;
        ``Ts`` different from the discrete controller's ``dt``; malformed reference samples
        (lengths differ, not increasing, not finite); an improper or non-SISO controller;
        ``t_out`` with a sampled controller, not 1-D, not strictly increasing or outside
        ``[0, t_end]``; ``xc0`` of the wrong length or not finite; a compensator or a
        measurement option with a continuous controller or an oscillator with its own input
        force; negative ``quantization`` or ``noise_rms``; ``delay`` outside ``[0, 8]``;
        ``mismatch`` without a compensator, with a disturbance observer, or with a factor that is not
        finite and positive; non-finite ``x0`` or ``v0``, ``|F0|`` above the model's
        ``max_hysteretic_force``; a disturbance observer's bandwidth above ``pi / Ts``.
    TypeError
        Wrong argument types, unknown keyword arguments, a reference callable that cannot be
        traced in a continuous loop, a compensator that is not one of the four kinds.
    prefriction.SolverError
        If the integration fails (the message names the time, the state and what to try).

    Warns
    -----
    UnstableLoopWarning
        If the loop closed around the pre-sliding linearisation ``1/(m s^2 + sigma)`` is not
        asymptotically stable (the poles are in the message).
    """
    _check_system(system)
    t_end = check_positive("t_end", t_end)
    measurement, noise_rms = _measurement_options(quantization, noise_rms, seed, delay)
    if compensator is not None and not isinstance(compensator, Compensator):
        raise TypeError(f"compensator must be a controllers.Feedforward, LuGreObserver, FrictionObserver or "
                        f"DisturbanceObserver, got {compensator!r} of type {type(compensator).__name__}")
    x0, v0, F0 = _check_start(system, x0, v0, F0)
    if mismatch is not None:
        compensator = _mismatched(compensator, mismatch)
    special = compensator is not None or measurement.quantization > 0.0 or noise_rms > 0.0 or measurement.delay != 0
    reference = _check_reference(reference)
    if Ts is not None:
        Ts = check_positive("Ts", Ts)
    if discretization not in DISCRETIZATIONS:
        raise ValueError(f"discretization must be one of {DISCRETIZATIONS}, got {discretization!r}")
    saturated = isinstance(controller, PID) and controller.u_max is not None
    C = as_lti(controller)
    dt = _sample_time(C)
    if dt is not None:
        if Ts is not None and not math.isclose(Ts, dt, rel_tol=1e-12):
            raise ValueError(f"Ts={Ts!r} differs from the discrete controller's sample time dt={dt!r}; omit Ts")
        Ts = dt
    elif Ts is not None:
        C = control.c2d(C, Ts, method=discretization)
    if Ts is not None:
        n_samples = sample_count(t_end, Ts, t_end / Ts)  # refuse runs that would exhaust the memory
    if special and (Ts is None or system.forced):
        raise ValueError("a compensator, quantization, noise_rms and delay need a sampled controller (Ts or a "
                         "discrete controller) and an oscillator without its own input force (system.u = None)")
    closed_loop(system, C, regime="presliding", warn=True, delay=measurement.delay if Ts is not None else 0)
    fb_reference = reference
    stats = None
    extra: dict = {}
    if Ts is not None:
        if t_out is not None:
            raise ValueError("t_out is not allowed with a sampled controller: its outputs are at the sample instants k Ts")
        if callable(reference) and not isinstance(reference, Signal):  # read at the sample instants only
            tk = Ts * np.arange(int(math.floor(t_end / Ts * (1 + 1e-12))) + 2)
            fb_reference = (tk, _evaluate(reference, tk))
        fb = LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, Ts=Ts, reference=fb_reference, xc0=xc0)
        if saturated and system.forced:
            raise ValueError(
                "a force limit u_max needs an oscillator without its own input force (system.u = None), "
                f"got system.u = {system.u!r}"
            )
        if system.forced:  # a disturbance force: prefriction.simulate (its native sampled loop)
            sim = prefriction.simulate(system, v0, x0=x0, F0=F0, t_end=t_end, rtol=rtol, feedback=fb, jit=jit)
        else:
            comp = None
            if compensator is not None:
                tk = Ts * np.arange(n_samples + 1)  # one past the end: the last sample's force
                params, state0 = compensator.numbers(system.mass, Ts, x0)
                comp = Compensation(compensator.structure(), params, state0,
                                    reference_velocity(reference, tk, _evaluate(reference, tk), Ts))
            if noise_rms > 0.0:
                noise = noise_rms * np.random.default_rng(seed).standard_normal(n_samples)
                measurement = Measurement(measurement.quantization, measurement.delay, noise)
            sim, stats, extra = run_sampled(
                system, fb, t_end, x0=x0, v0=v0, F0=F0, rtol=rtol, jit=jit,
                u_max=controller.u_max if saturated else None,
                k_aw=controller.back_calculation_gain() if saturated else None,
                measurement=measurement, compensation=comp,
            )
    else:
        dense = np.linspace(0.0, t_end, 2001) if t_out is None else _check_t_out(t_out, t_end)
        limit = {"u_max": controller.u_max, "k_aw": controller.back_calculation_gain()} if saturated else {}
        fb = LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, Ts=Ts, reference=fb_reference, xc0=xc0, **limit)
        sim = prefriction.simulate(system, v0, x0=x0, F0=F0, t_end=t_end, rtol=rtol, dense=dense, feedback=fb, jit=jit)
    t = sim.t
    r = _evaluate(reference, t)
    return LoopResult(
        t=t, reference=r, x=sim.x, v=sim.v, F=sim.F, u=sim.u, error=r - sim.x, xc=sim.xc,
        reversals=sim.reversals, Ts=Ts, controller=C, system=system, kp=None if saturated else _dc_gain(C),
        simulation=sim, loop_stats=stats, compensator=compensator,
        measured=extra.get("y"), compensation=extra.get("comp"),
    )


def _check_start(system: Oscillator, x0: Any, v0: Any, F0: Any) -> tuple[float, float, float]:
    """``x0`` [m], ``v0`` [m/s] finite and ``|F0|`` [N] within the model's largest force at rest
    (as :func:`prefriction.simulate`; a compensator's initial state is built from them)."""
    x0, v0, F0 = check_finite("x0", x0), check_finite("v0", v0), check_finite("F0", F0)
    F_max = system.friction.max_hysteretic_force
    if not abs(F0) <= F_max:
        raise ValueError(f"F0 must lie in [-{F_max!r}, {F_max!r}] N (the model's max_hysteretic_force, "
                         f"{type(system.friction).__name__}), got {F0!r}")
    return x0, v0, F0


def _mismatched(compensator: Optional[Compensator], mismatch: Any) -> Compensator:
    """The compensator with its model scaled by ``mismatch = (stiffness, coulomb)``, checked."""
    if compensator is None:
        raise ValueError(f"mismatch needs a compensator (it scales the compensator's model), got mismatch={mismatch!r}")
    if not (isinstance(mismatch, tuple) and len(mismatch) == 2):
        raise TypeError(f"mismatch must be a tuple (stiffness, coulomb) of factors, got {mismatch!r}")
    if not hasattr(compensator, "model"):
        raise ValueError(f"mismatch scales a compensator's friction model, and the {type(compensator).__name__} has "
                         f"none (it is model-free): omit mismatch, got mismatch={mismatch!r}")
    factors = [check_positive(f"mismatch[{i}] (the {what} factor)", f) for i, (what, f)
               in enumerate(zip(("stiffness", "coulomb"), mismatch))]
    return compensator.with_model(scaled_model(compensator.model, *factors))


def _measurement_options(quantization: Any, noise_rms: Any, seed: Any, delay: Any) -> tuple[Measurement, float]:
    """The checked measurement options without noise, and the noise's rms [m] (the noise is
    drawn once the sample count is known)."""
    quantization = check_nonnegative("quantization", quantization)
    noise_rms = check_nonnegative("noise_rms", noise_rms)
    check_count("seed", seed, 0)
    delay = check_count("delay", delay, 0, MAX_DELAY, why="the measurement buffer of the compiled loop")
    return Measurement(quantization, delay), noise_rms
