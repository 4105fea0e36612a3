"""Energy analysis of sampled trajectories: :func:`analyze_samples` (arrays) and
:func:`analyze_result` (a simulation, a sweep entry or a closed loop)."""

from __future__ import annotations

from typing import Any, Optional, Union

import numpy as np

from prefriction.analysis.energy.balance import bound_check, branch_energy, dissipation, series
from prefriction.analysis.energy.checks import ROUNDING, check_flag, check_method, check_samples, check_system
from prefriction.analysis.energy.lugre import lugre_bound
from prefriction.analysis.energy.lugre_report import LuGreEnergyReport, analyze_lugre_samples
from prefriction.analysis.energy.report import EnergyReport, _rel_residual
from prefriction.analysis.energy.sampled_energy import kinetic_energy
from prefriction.analysis.energy.sampled_reversals import SampledReversals, find_reversals
from prefriction.analysis.energy.stored_energy import initial_stored_energy, reversal_forces, stored_energy
from prefriction.analysis.energy.work import input_work, split_integrals
from prefriction.models import LuGre, Oscillator
from prefriction.simulation.result import SimulationResult
from prefriction.units import Scales

Report = Union[EnergyReport, LuGreEnergyReport]


def _peak_kinetic(t: np.ndarray, ek: np.ndarray, rev: SampledReversals) -> np.ndarray:
    """Peak kinetic energy in each complete half-cycle, refined by a parabola through 3 samples."""
    out = np.empty(max(len(rev) - 1, 0))
    for k in range(out.size):
        lo, hi = int(rev.index[k]) + 1, int(rev.index[k + 1]) + 1
        j = lo + int(np.argmax(ek[lo:hi]))
        out[k] = ek[j]
        if lo < j < hi - 1:
            hm, hp = t[j - 1] - t[j], t[j + 1] - t[j]
            dm, dp = (ek[j - 1] - ek[j]) / hm, (ek[j + 1] - ek[j]) / hp
            c = (dp - dm) / (hp - hm)  # E(tau) = E_j + b tau + c tau^2 through the 3 samples
            if c < 0.0:
                b_ = dp - c * hp
                out[k] = max(ek[j], ek[j] - b_ * b_ / (4.0 * c))
    return out


def _input_forces(
    system: Oscillator, t: np.ndarray, u: Optional[np.ndarray], zoh: bool
) -> tuple[Optional[np.ndarray], Optional[np.ndarray]]:
    """The input force as ``(continuous, held)`` sample arrays [N]: ``system.u`` without ``u``;
    ``u`` itself; with ``zoh``, ``u`` minus ``system.u`` held and ``system.u`` continuous."""
    own = np.asarray(system.u(t), dtype=float) * np.ones_like(t) if system.forced else None
    if u is None:
        return own, None
    if not zoh:
        return u, None
    return own, (u - own if own is not None else u)


def analyze_samples(
    t: Any, x: Any, v: Any, F: Any, *, system: Oscillator, u: Any = None, zoh: bool = False,
    method: str = "trapezoid",
) -> Report:
    """Energy analysis of a sampled trajectory of an oscillator (2.1), in SI units.

    Rate-independent models (Dahl, Maxwell-slip, elastic-plastic elements, GMS with ``Fs = Fc``
    and no damping, analysed as the equal Maxwell-slip model) give an :class:`EnergyReport`.
    A :class:`prefriction.LuGre` model gives a :class:`LuGreEnergyReport`: the stored bristle
    energy at the reversals and the viscous and hysteretic dissipation per half-cycle, apart
    (docs/mathematics.md#lugre-energy); ``F[0]`` must then be the friction force at ``t[0]``
    with the initial velocity. A :class:`prefriction.ElastoPlastic` model gives an
    :class:`EnergyReport` with the stored bristle energy at the reversals from the model's
    branch energy (:mod:`prefriction.analysis.energy.stored_energy`), the forces there
    extrapolated in time along the incoming branch; ``F[0]`` is its force at ``t[0]`` with the
    initial velocity.

    Detects the reversals (:func:`find_reversals`), evaluates the potential energy at each
    (:func:`branch_energy`, (3.9) for ``gamma = 1``), the dissipation per half-cycle (2.10)
    (plus the input's work ``int u v dt`` over the half-cycle under forcing), the truncated
    series (2.11) and the bound (2.12). Unforced, the peak kinetic energy of each complete
    half-cycle is an independent, model-free estimate of ``E_p`` (paper, note after (3.9)),
    reported as ``E_p_check``.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    x : array_like
        Positions [m], length N.
    v : array_like
        Velocities [m/s], length N.
    F : array_like
        Friction forces [N], length N, ``|F| <= Fc`` (rate-independent models).
    system : Oscillator
        The oscillator that produced the samples (mass, friction model, input ``u``).
    u : array_like, optional
        The total applied force [N] at the samples, length N, finite: input signal plus a
        controller's force, e.g. ``SimulationResult.u`` or ``controllers.LoopResult.u``. Default:
        ``system.u`` (zero if the system is unforced), which misses a feedback force.
    zoh : bool, default False
        ``True``: ``u`` comes from a sampled controller, ``u[k] - system.u(t[k])`` is held from
        ``t[k]`` to ``t[k+1]`` (zero-order hold) and its work there is exactly
        ``(u[k] - system.u(t[k])) (x[k+1] - x[k])``; ``system.u`` itself is integrated by
        ``method``. Requires ``u``.
    method : {"trapezoid", "simpson"}
        Quadrature of the input's work and of LuGre's dissipation powers.

    Returns
    -------
    EnergyReport or LuGreEnergyReport

    Raises
    ------
    ValueError
        Invalid arrays (see :func:`find_reversals`; ``u`` is checked like them), no reversal in
        the samples, ``|F| > Fc``, or ``zoh`` without ``u``.
    TypeError
        ``system`` is not an Oscillator, its model is rate-dependent other than LuGre and
        ElastoPlastic (a GMS with ``Fs > Fc`` or damping), or ``zoh`` is not a bool.
    """
    friction, mass = check_system(system, lugre=True)
    method = check_method(method)
    zoh = check_flag("zoh", zoh)
    if u is None:
        if zoh:
            raise ValueError("zoh=True needs the held force samples u (e.g. LoopResult.u), got u = None")
        t, x, v, F = check_samples(t=t, x=x, v=v, F=F)
    else:
        t, x, v, F, u = check_samples(t=t, x=x, v=v, F=F, u=u)
    if friction.rate_independent:
        over = np.abs(F) > friction.Fc * (1.0 + ROUNDING)
        if np.any(over):
            i = int(np.flatnonzero(over)[0])
            raise ValueError(
                f"F must lie in [-Fc, Fc] = [{-friction.Fc!r}, {friction.Fc!r}] (every sample), got F[{i}] = {float(F[i])!r}"
            )
    rev = find_reversals(t, v, x=x, F=F)
    if len(rev) == 0:
        raise ValueError(
            f"v changes sign nowhere in the {t.size} samples (t from {float(t[0])!r} to {float(t[-1])!r} s): "
            "the motion never reverses in them, and the bookkeeping (2.3)-(2.12) is made at reversals: give "
            "samples that contain at least one velocity reversal (a longer run if the motion still oscillates; "
            "an overdamped or monotone motion has none)"
        )
    cont, held = _input_forces(system, t, u, zoh)
    W = input_work(t, x, v, rev, method, u=cont, held=held)
    if isinstance(friction, LuGre):
        return analyze_lugre_samples(t, v, F, rev, W, system=system, method=method)
    if friction.rate_independent:
        # the samples obey |F| <= Fc; extrapolation to a reversal may overshoot near saturation
        E_p = branch_energy(np.clip(rev.F, -friction.Fc, friction.Fc), rev.direction, friction=friction)
        E_0 = float(kinetic_energy(v[0], mass=mass) + branch_energy(F[0], rev.initial_direction, friction=friction))
        bound = bound_check(E_p, friction=friction, E_0=E_0)
    else:  # a bristle that unloads elastically at a reversal (ElastoPlastic): its branch energy there
        F_max = friction.max_hysteretic_force
        E_p = stored_energy(np.clip(reversal_forces(t, F, rev), -F_max, F_max), rev.direction, friction=friction)
        E_0 = float(kinetic_energy(v[0], mass=mass)) + initial_stored_energy(
            float(F[0]), float(v[0]), rev.initial_direction, friction=friction, scales=Scales.of(system))
        bound = lugre_bound(E_p, friction, E_0)
    if cont is None and held is None and friction.rate_independent:
        check = _peak_kinetic(t, kinetic_energy(v, mass=mass), rev)
        label = "peak kinetic energy per half-cycle"
        dev = _rel_residual(check - E_p[: check.size], float(np.max(E_p))) if check.size else None
    else:
        check, label, dev = None, "peak kinetic energy (unforced rate-independent models only)", None
    E_d = np.concatenate(([E_0 + float(W[0]) - float(E_p[0])], dissipation(E_p, input_work=W[1:])))
    S, R = series(E_p, E_d[1:])
    # (2.10) against the friction force's own work int F dx = int F v dt per half-cycle ((2.5), (2.7))
    W_F = split_integrals(t, (F * v)[None, :], rev, method)[0]
    E_pot0 = E_0 - float(kinetic_energy(v[0], mass=mass))
    E_d_F = np.concatenate(([E_pot0], E_p[:-1])) + W_F - E_p
    return EnergyReport(
        source="samples", t=rev.t, x=rev.x, F=rev.F, direction=rev.direction, E_p=E_p, E_d=E_d,
        W_u=W, E_0=E_0, series_partial=S, series_remainder=R,
        residual_2_10=_rel_residual(E_d - E_d_F, float(np.max(E_p))),
        E_p_check=check, E_p_check_label=label, E_p_check_max_rel_dev=dev,
        bound=bound,
    )


def analyze_result(
    result: Any, *, system: Optional[Oscillator] = None, zoh: Optional[bool] = None, method: str = "trapezoid"
) -> Report:
    """:func:`analyze_samples` of a simulation's samples, with the applied force ``result.u``.

    The reversals are found in the samples (:func:`find_reversals`). A reversal on the last
    sample, where a run stopped by ``reversals=n`` ends, is not among them: the samples do not
    show the velocity's sign after it. Simulate one reversal more (or to a ``t_end`` past it) to
    have all ``n`` half-cycles analysed.

    Parameters
    ----------
    result : SimulationResult or controllers.LoopResult
        A run with samples: ``prefriction.simulate(..., dense=...)``, an entry of
        ``prefriction.sweep(..., dense=...)``, or ``controllers.simulate_loop(...)`` (any object
        with ``t, x, v, F, u, system`` and ``Ts``, the sample time of a sampled controller or
        ``None``).
    system : Oscillator, optional
        The oscillator of a :class:`prefriction.SimulationResult` (required there); a loop
        result carries its own, and a different one is refused.
    zoh : bool, optional
        Whether the controller's force is held between the samples (see :func:`analyze_samples`).
        Default: ``result.Ts is not None`` for a loop result, ``False`` for a simulation (pass
        ``True`` for a ``simulate`` or ``sweep`` run with a sampled ``feedback``).
    method : {"trapezoid", "simpson"}
        Quadrature of the powers.

    Returns
    -------
    EnergyReport or LuGreEnergyReport

    Raises
    ------
    TypeError
        ``result`` is neither kind (e.g. an exception in a failed sweep entry), ``system``
        missing for a simulation result or given differently for a loop result.
    ValueError
        The run holds no samples (simulate with ``dense=``), or as :func:`analyze_samples`.
    """
    if isinstance(result, SimulationResult):
        if system is None:
            raise TypeError("system is required with a SimulationResult (the oscillator that was simulated), got None")
        default_zoh = False
    elif all(hasattr(result, name) for name in ("t", "x", "v", "F", "u", "system", "Ts")):
        if system is not None and system is not result.system:
            raise TypeError(f"system must be None or the loop's own oscillator (result.system), got {system!r}")
        system, default_zoh = result.system, result.Ts is not None
    else:
        raise TypeError(
            "result must be a prefriction.SimulationResult (simulate, sweep) or a controllers.LoopResult, "
            f"got {type(result).__name__}: {result!r}"[:300]
        )
    if result.t is None:
        raise ValueError("result holds no samples (result.t is None): simulate with dense=True or dense=times")
    zoh = default_zoh if zoh is None else zoh
    return analyze_samples(result.t, result.x, result.v, result.F, system=system,
                           u=result.u, zoh=zoh, method=method)
