"""``friction_along(model, t, x)``: the friction force along a prescribed motion."""

from __future__ import annotations

import functools
import time
from typing import Any, Optional

import numpy as np

from prefriction._validation import check_count, check_finite
from prefriction.along.engine import Units, stepper
from prefriction._memory import check_memory
from prefriction.along.motion import Motion
from prefriction.along.native import along_driver, fast_samples, first_direction, run_native
from prefriction.along.result import AlongResult
from prefriction.models.base import FrictionModel

__all__ = ["friction_along", "initial_state", "check_model"]


def check_model(model: Any) -> FrictionModel:
    """``model`` if it is a :class:`prefriction.FrictionModel`, else ``TypeError``."""
    if not isinstance(model, FrictionModel):
        raise TypeError(f"model must be a prefriction.FrictionModel (e.g. prefriction.Dahl), got {model!r} "
                        f"of type {type(model).__name__}")
    return model


def initial_state(model: FrictionModel, F0: Any, s0: float) -> tuple[float, np.ndarray]:
    """``F0`` [N] checked and the model's state ``[z; m]`` with that force at the start of a
    branch of direction ``s0`` (``docs/along.md#initial-state``)."""
    F0 = check_finite("F0", F0)
    top = model.max_hysteretic_force
    if abs(F0) > top:
        raise ValueError(f"F0 must lie in [-{top!r}, {top!r}] N (the largest force of {type(model).__name__} "
                         f"at rest), got {F0!r}")
    z, m = model.initial_state(F0 / model.Fc, s0)
    return F0, np.array([*z, *m], dtype=float)


def friction_along(model: FrictionModel, t: Any, x: Any, *, F0: float = 0.0, v: Any = None,
                   substeps: int = 16) -> AlongResult:
    """Friction force [N] of ``model`` along the prescribed motion ``x(t)``.

    The motion is linear between samples; each interval is advanced by the model's exact step
    (:meth:`prefriction.FrictionModel.advance`: Dahl, Maxwell-slip, LuGre, GMS, Viscous and
    their sums), reversals at the samples where the direction changes and model events
    (saturation, element slips) located inside the interval; a model without an exact step is
    integrated with ``substeps`` Runge-Kutta sub-steps per interval. The step is one CasADi
    Function per model structure, compiled once (``docs/along.md``).

    Parameters
    ----------
    model : FrictionModel
        Any friction model (a sum ``a + b`` included).
    t : array_like
        Sample times [s], 1-D, strictly increasing, 2 to 2e7 samples.
    x : array_like
        Positions [m] at ``t``.
    F0 : float, default 0.0
        Force [N] of the model's state at the start, on a virgin branch (the elastic or
        bristle force; ``docs/along.md#initial-state``), ``|F0| <= model.max_hysteretic_force``.
    v : array_like, optional
        Velocities [m/s] at ``t`` for the rate-dependent part of the force at the samples
        (damping, viscous terms); default: the velocity of the interval that ends at each
        sample (of the first interval at the first sample). The state always follows the
        piecewise-linear motion.
    substeps : int, default 16
        Runge-Kutta sub-steps per interval for a model without an exact step (1 to 64).

    Returns
    -------
    AlongResult
        ``t``, ``x``, ``F`` [N], the velocities used, the states and flags, the events per
        interval (these four made on first access, ``docs/along.md#states-on-access``), the
        number of events and the reversal samples; ``summary()`` and ``plot(path)``.

    Raises
    ------
    TypeError
        If ``model`` is not a FrictionModel or an array is not real.
    ValueError
        If the arrays are not 1-D, have other lengths than ``t``, fewer than 2 or more than
        2e7 samples, more samples than fit in 4 GiB with the model's state
        (:func:`prefriction._memory.check_memory`), non-finite entries, ``t`` is not strictly increasing, ``F0`` is out of range
        or ``substeps`` not in [1, 64].
    prefriction.SolverError
        If the model's force is not finite at a sample (named).

    Examples
    --------
    >>> import numpy as np, prefriction as pf
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> res = pf.friction_along(pf.Dahl(sigma=1e5, Fc=1.0), t, 1e-4 * np.sin(2 * np.pi * t))
    >>> round(float(res.F.max()), 6)  # Fc (1 - exp(-sigma x_max / Fc)) on the virgin branch [N]
    0.999955
    """
    model = check_model(model)
    substeps = check_count("substeps", substeps, 1, 64)
    run = stepper(model, substeps)
    lib = along_driver(model, run.substeps)
    fast = None if lib is None else fast_samples(lib, t, x, v)  # checked in C
    motion = Motion.of(t, x, v) if fast is None else None  # checks and names what is wrong
    if fast is not None:
        t_arr, x_arr, v_arr = fast
    else:  # Motion.of's arrays are its own
        t_arr, x_arr, v_arr = motion.t, motion.x, None if v is None else motion.v_at
    v_arr = None if v_arr is None else v_arr.copy()  # the result's own
    k = model.n_states + model.n_flags  # the states of every sample (made on first access), three times at the peak
    check_memory(f"friction_along of {type(model).__name__} ({k} states and flags per sample)", t_arr.size,
                 16 + 3 * k, "samples", "pass fewer samples, or feed the record through prefriction.FrictionStream "
                 "(one sample at a time, in constant memory)")
    s0 = motion.s0 if fast is None else first_direction(lib, x_arr)
    F0, X0 = initial_state(model, F0, s0)
    start = time.perf_counter()
    U = Units.of(model)
    q = np.asarray(model.runtime_params(), dtype=float)
    step = "exact" if run.exact else f"rk4 x {substeps}"
    v_at = functools.partial(_velocities, t_arr, x_arr, v_arr)
    if lib is not None:  # one C pass over the motion writing the forces (prefriction.along.native)
        v0 = (v_arr[0] if v_arr is not None else (x_arr[1] - x_arr[0]) / (t_arr[1] - t_arr[0])) / U.v
        _X, F_first, _e = run.step(X0, 0.0, 0.0, s0, s0, v0, q)
        done = run_native(lib, X0, float(F_first), t_arr, x_arr, v_arr, s0, q, U)
        if not done.finite:
            _check_finite(done.F, t_arr)
        replay = functools.partial(_replay, lib, X0, float(F_first), t_arr, x_arr, v_arr, s0, q, U)
        return AlongResult(model, t_arr, x_arr, done.F, v_at, replay, done.n_events, done.reversals, F0, step,
                           time.perf_counter() - start)
    _X, F_first, _e = run.step(X0, 0.0, 0.0, s0, s0, motion.v_at[0] / U.v, q)
    rows = np.vstack([motion.v / U.v, motion.dt / U.t, motion.s_prev, motion.s, motion.v_at[1:] / U.v])
    Xb, Fb, evb = run.run(X0, rows, q)
    F = U.F * np.concatenate(([float(F_first)], Fb))
    _check_finite(F, t_arr)
    X = np.hstack((X0[:, None], Xb)).T
    ev = np.concatenate(([0], evb.astype(np.int64)))
    return AlongResult(model, t_arr, x_arr, F, v_at, (X, ev), int(ev.sum()), motion.reversals, F0, step,
                       time.perf_counter() - start)


def _velocities(t: np.ndarray, x: np.ndarray, v: Optional[np.ndarray]) -> np.ndarray:
    """The velocities [m/s] at the samples (``docs/along.md#motion``): the user's ``v``, else the
    velocity of the interval that ends at each sample (of the first interval at the first)."""
    if v is not None:
        return v
    vi = np.diff(x) / np.diff(t)
    return np.concatenate((vi[:1], vi))


def _replay(lib: Any, X0: np.ndarray, F_first: float, t: np.ndarray, x: np.ndarray, v: Optional[np.ndarray],
            s0: float, q: np.ndarray, U: Units) -> tuple[np.ndarray, np.ndarray]:
    """The states and event counts at every sample: the run's C pass again, its states written."""
    done = run_native(lib, X0, F_first, t, x, v, s0, q, U, states=True)
    assert done.X is not None and done.events is not None
    return done.X, done.events


def _check_finite(F: np.ndarray, t: np.ndarray) -> None:
    bad = ~np.isfinite(F)
    if np.any(bad):
        from prefriction.errors import SolverError

        i = int(np.flatnonzero(bad)[0])
        raise SolverError(f"the model's force is not finite at sample {i} (t = {t[i]!r} s); check the model's "
                          f"parameters, or give more substeps for a model without an exact step")
