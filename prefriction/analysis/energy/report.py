"""The energy report of a trajectory (:class:`EnergyReport`), from samples or a reversal table."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Union

import numpy as np

from prefriction.analysis.energy.balance import BoundCheck, bound_check, branch_energy, dissipation, series
from prefriction.analysis.energy.checks import ROUNDING, check_method, check_samples, check_system, value_array
from prefriction.analysis.energy.sampled_energy import cumulative, kinetic_energy
from prefriction.analysis.energy.sampled_reversals import SampledReversals, find_reversals
from prefriction.analysis.energy.lugre import lugre_bound
from prefriction.analysis.energy.lugre_report import LuGreEnergyReport, analyze_lugre_samples, lugre_table_energy
from prefriction._validation import check_finite
from prefriction.models import FrictionModel, LuGre, Oscillator
from prefriction.reversals import ReversalTable


@dataclass(frozen=True, eq=False)
class EnergyReport:
    """Energy balance of a trajectory at its velocity reversals (paper section 2).

    Attributes
    ----------
    source : str
        ``"samples"`` or ``"reversal table"``.
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N], length n.
    direction : numpy.ndarray
        Sign of the velocity after each reversal (+1 or -1).
    E_p : numpy.ndarray
        Potential energy at each reversal [J]: the branch potential of the Dahl model,
        (3.9) for ``gamma = 1`` (samples), or the table's ``E_p``.
    E_d : numpy.ndarray
        Energy dissipated in the half-cycle from reversal k to k + 1 [J], length n - 1,
        (2.10): ``E_p[k] + W_u[k] - E_p[k+1]`` (samples; ``W_u`` the input's work, zero
        unforced) or the table's ``E_d[1:]``. Under forcing a reversal can occur before the
        force zero crossing; the Dahl branch potential then rises at the reversal and that
        ``E_d`` is negative (the Dahl model has no dissipation rate ``D >= 0``, paper after (2.3)).
    E_0 : float
        Energy of the initial state [J].
    E_d_initial : float
        Energy dissipated in the first excursion, from the initial state to the first
        reversal [J] (may include gross sliding; not part of (2.10)-(2.12)).
    series_partial, series_remainder : numpy.ndarray
        Truncated series (2.11), see :func:`series`.
    residual_2_10 : float
        ``max_k |E_p[k] - E_d[k] - E_p[k+1] + W_u[k]|`` relative to ``max(E_p)``: how well the
        dissipation and potential energies agree with (2.10) (0 by construction for samples).
    E_p_check : numpy.ndarray or None
        Independent estimate of ``E_p``: the peak kinetic energy in each complete unforced
        half-cycle (samples, length n - 1, paper's note after (3.9)), or the branch potential
        of the tabulated ``F_i`` (table, length n). ``None`` for forced samples.
    E_p_check_label : str
        What ``E_p_check`` is.
    E_p_check_max_rel_dev : float or None
        ``max |E_p_check - E_p| / max(E_p)`` over the entries compared.
    bound : BoundCheck
        The bound (2.12) and the initial energy.
    """

    source: str
    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    direction: np.ndarray
    E_p: np.ndarray
    E_d: np.ndarray
    E_0: float
    E_d_initial: float
    series_partial: np.ndarray
    series_remainder: np.ndarray
    residual_2_10: float
    E_p_check: Optional[np.ndarray]
    E_p_check_label: str
    E_p_check_max_rel_dev: Optional[float]
    bound: BoundCheck

    def __len__(self) -> int:
        return len(self.t)

    @property
    def E_p_decreasing(self) -> bool:
        """True if ``E_p`` strictly decreases from reversal to reversal (clockwise hysteresis)."""
        return bool(np.all(np.diff(self.E_p) < 0.0))

    def __repr__(self) -> str:
        last = f", E_p[-1]={self.E_p[-1]:.4g} J" if len(self) else ""
        return (f"EnergyReport({self.source}: {len(self)} reversals, E_0={self.E_0:.4g} J{last}, "
                f"residual (2.10)={self.residual_2_10:.2g}, bound {'holds' if self.bound.holds else 'VIOLATED'})")

    def summary(self) -> str:
        """The closing lines of :meth:`format`: balances, checks and the bound, without the table."""
        return self.format(max_rows=0).split("\n\n", 1)[1]

    def format(self, max_rows: int = 20) -> str:
        """Return the report as a readable text table and summary (at most ``max_rows`` rows)."""
        head = (
            f"{'i':>5} {'t [s]':>13} {'x [m]':>13} {'F [N]':>13} {'E_p [J]':>12} "
            f"{'E_d(i) [J]':>12} {'sum E_d(n>=i)':>13} {'E_p/bound':>10}"
        )
        n = len(self)
        half = max_rows // 2
        idx = list(range(n)) if n <= max_rows else list(range(half)) + list(range(n - half, n))
        lines = [f"Energy at reversals ({self.source}); E_d(i): half-cycle from reversal i to i+1", head, "-" * len(head)]
        prev = -1
        for i in idx:
            if i != prev + 1:
                lines.append(f"{'...':>5}")
            e_d = f"{self.E_d[i]:>12.5e}" if i < n - 1 else f"{'-':>12}"
            lines.append(
                f"{i + 1:>5} {self.t[i]:>13.7g} {self.x[i]:>13.6g} {self.F[i]:>13.6g} {self.E_p[i]:>12.5e} "
                f"{e_d} {self.series_partial[i]:>13.5e} {self.E_p[i] / self.bound.bound:>10.6f}"
            )
            prev = i
        lines.append("")
        lines.append(f"first excursion (initial state to reversal 1) dissipated {self.E_d_initial:.6e} J")
        if n:
            lines.append(f"E_p strictly decreasing: {'yes' if self.E_p_decreasing else 'NO'}")
            lines.append(f"(2.10) E_p(i) = E_d(i) + E_p(i+1): max relative residual {self.residual_2_10:.3e}")
            lines.append(
                f"(2.11) E_p(i) = sum E_d(n>=i) + remainder; over {max(n - 1, 0)} half-cycles the remainder is E_p(last) = "
                f"{self.E_p[-1]:.4e} J = {self.E_p[-1] / self.E_p[0] if self.E_p[0] > 0 else 0.0:.3e} E_p(first)"
            )
        if self.E_p_check_max_rel_dev is not None:
            lines.append(f"E_p vs {self.E_p_check_label}: max relative deviation {self.E_p_check_max_rel_dev:.3e}")
        lines.append(self.bound.format())
        return "\n".join(lines)


def _rel_residual(values: np.ndarray, scale: float) -> float:
    """``max |values|`` relative to ``scale`` (absolute if ``scale`` is 0); 0 for no values."""
    if values.size == 0:
        return 0.0
    return float(np.max(np.abs(values)) / scale) if scale > 0 else float(np.max(np.abs(values)))


def _input_power(system: Oscillator, t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Power ``u v`` [W] of the input force at the samples."""
    u = np.asarray(system.u(t), dtype=float) if system.forced else np.zeros_like(t)
    return u * v


def _work_to_reversals(t: np.ndarray, p: np.ndarray, rev: SampledReversals, method: str) -> np.ndarray:
    """Integral of the power ``p`` from ``t[0]`` to each reversal (``p = 0`` at a reversal)."""
    cum = cumulative(t, p, method)
    i = rev.index
    return cum[i] + 0.5 * p[i] * (rev.t - t[i])


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


def analyze_samples(
    t: Any, x: Any, v: Any, F: Any, *, system: Oscillator, method: str = "trapezoid"
) -> Union[EnergyReport, LuGreEnergyReport]:
    """Energy analysis of a sampled trajectory of an oscillator (2.1), in SI units.

    Rate-independent models (Dahl, Maxwell-slip, elastic-plastic elements, GMS with ``Fs = Fc``
    and no damping, analysed as the equal Maxwell-slip model) give an :class:`EnergyReport`.
    A :class:`prefriction.LuGre` model gives a :class:`LuGreEnergyReport`: the stored bristle
    energy at the reversals and the viscous and hysteretic dissipation per half-cycle, apart
    (docs/mathematics.md#lugre-energy); ``F[0]`` must then be the friction force at ``t[0]``
    with the initial velocity.

    Detects the reversals (:func:`find_reversals`), evaluates the potential energy at each
    (:func:`branch_energy`, (3.9) for ``gamma = 1``), the dissipation per half-cycle (2.10)
    (plus the input's work ``int u v dt`` over the half-cycle if the system is forced), the
    truncated series (2.11) and the bound (2.12). Unforced, the peak kinetic energy of each
    complete half-cycle is an independent, model-free estimate of ``E_p`` (paper, note after
    (3.9)), reported as ``E_p_check``.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    x : array_like
        Positions [m], length N.
    v : array_like
        Velocities [m/s], length N.
    F : array_like
        Friction forces [N], length N, ``|F| <= Fc``.
    system : Oscillator
        The oscillator that produced the samples (mass, friction model, input ``u``).
    method : {"trapezoid", "simpson"}
        Quadrature of the input's work (forced systems) and of LuGre's dissipation powers.

    Returns
    -------
    EnergyReport or LuGreEnergyReport

    Raises
    ------
    ValueError
        Invalid arrays (see :func:`find_reversals`), no reversal in the samples, or
        ``|F| > Fc``.
    TypeError
        ``system`` is not an Oscillator, or its model is rate-dependent other than LuGre
        (a GMS with ``Fs > Fc`` or damping).
    """
    friction, mass = check_system(system, lugre=True)
    method = check_method(method)
    t, x, v, F = check_samples(t=t, x=x, v=v, F=F)
    if isinstance(friction, LuGre):
        return analyze_lugre_samples(t, x, v, F, system=system, u=_input_power(system, t, np.ones_like(t)), method=method)
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
            "no reversal to analyse; simulate longer"
        )
    # the samples obey |F| <= Fc; extrapolation to a reversal may overshoot near saturation
    E_p = branch_energy(np.clip(rev.F, -friction.Fc, friction.Fc), rev.direction, friction=friction)
    s0 = rev.initial_direction
    E_0 = float(kinetic_energy(v[0], mass=mass) + branch_energy(F[0], s0, friction=friction))
    if system.forced:
        W = _work_to_reversals(t, _input_power(system, t, v), rev, method)
        w_first, w_half = float(W[0]), np.diff(W)
        check, label, dev = None, "peak kinetic energy (unforced only)", None
    else:
        w_first, w_half = 0.0, np.zeros(len(rev) - 1)
        check = _peak_kinetic(t, kinetic_energy(v, mass=mass), rev)
        label = "peak kinetic energy per half-cycle"
        dev = _rel_residual(check - E_p[: check.size], float(np.max(E_p))) if check.size else None
    E_d = dissipation(E_p, input_work=w_half)
    S, R = series(E_p, E_d)
    return EnergyReport(
        source="samples",
        t=rev.t,
        x=rev.x,
        F=rev.F,
        direction=rev.direction,
        E_p=E_p,
        E_d=E_d,
        E_0=E_0,
        E_d_initial=E_0 + w_first - float(E_p[0]),
        series_partial=S,
        series_remainder=R,
        residual_2_10=_rel_residual(E_p[:-1] + w_half - E_d - E_p[1:], float(np.max(E_p))),
        E_p_check=check,
        E_p_check_label=label,
        E_p_check_max_rel_dev=dev,
        bound=bound_check(E_p, friction=friction, E_0=E_0),
    )


def analyze_table(
    table: ReversalTable, *, system: Oscillator, F0: float = 0.0, work_input: Any = None
) -> EnergyReport:
    """Energy analysis of a trajectory given at its reversals (a :class:`ReversalTable`).

    Takes ``E_p`` and the dissipation from the table (``table.E_d[k + 1]`` is the half-cycle
    from reversal k to k + 1), checks (2.10) between them, forms the series (2.11), checks the
    bound (2.12), and recomputes ``E_p`` independently from the tabulated forces as the branch
    potential of the model ((3.9) for Dahl with ``gamma = 1``), reported as ``E_p_check``.

    Tables of rate-dependent classes (:class:`prefriction.LuGre`; :class:`prefriction.GMS`,
    analysed only with ``Fs = Fc`` and no damping, as the equal Maxwell-slip model) hold no
    ``E_p`` (NaN) and only the kinetic part of ``E_0``. Their ``E_p`` is computed here from the
    tabulated forces (LuGre: the stored bristle energy ``F_i^2 / (2 sigma0)``, exact because
    ``z' = 0`` at a reversal), ``E_0`` adds the stored energy of ``F0``, and the dissipation is
    ``E_p[k] + W_u[k] - E_p[k+1]`` with the input work ``work_input``.

    Parameters
    ----------
    table : ReversalTable
        Reversal states in SI units, e.g. from :func:`prefriction.exact_reversals` or
        ``prefriction.simulate(...).reversals``.
    system : Oscillator
        The oscillator of the table.
    F0 : float, default 0.0
        Initial friction force [N] of the run (``simulate``'s ``F0``), ``|F0| <= Fc``; only for
        tables without ``E_p`` (rate-dependent classes).
    work_input : array_like, optional
        Work of the input force over each half-cycle that ends at a reversal [J], one value per
        reversal, finite (``SimulationResult.work_input``); only for tables without ``E_p``,
        required if the system is forced.

    Returns
    -------
    EnergyReport

    Raises
    ------
    ValueError
        Empty table, a non-finite entry, times not strictly increasing, ``F0`` or
        ``work_input`` given for a table that has ``E_p``, or invalid ``F0``/``work_input``.
    TypeError
        ``table`` is not a ReversalTable, or ``system`` not an Oscillator with a model the
        analysis covers.
    """
    friction, _ = check_system(system, lugre=True)
    if not isinstance(table, ReversalTable):
        raise TypeError(f"table must be a prefriction.ReversalTable, got {table!r} of type {type(table).__name__}")
    if len(table) < 1:
        raise ValueError("table holds no reversal (length 0); need at least 1")
    defined = system.friction.rate_independent  # the table's E_p, E_d and E_0 are the model's
    for name in ("t", "x", "F") + (("E_p", "E_d", "E_0") if defined else ()):
        bad = ~np.isfinite(np.atleast_1d(np.asarray(getattr(table, name), dtype=float)))
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"table.{name} must be finite, got a non-finite entry at index {i} (reversal {i + 1})")
    t = np.asarray(table.t, dtype=float)
    if np.any(np.diff(t) <= 0.0):
        i = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
        raise ValueError(f"table.t must be strictly increasing, got t[{i + 1}] = {float(t[i + 1])!r} <= t[{i}] = {float(t[i])!r}")
    x = np.asarray(table.x, dtype=float)
    F = np.asarray(table.F, dtype=float)
    n = t.size
    # direction after reversal k is opposite to the motion that ended there
    direction = np.empty(n, dtype=int)
    if n >= 2:
        direction[1:] = -np.sign(np.diff(x)).astype(int)
        direction[0] = -direction[1]
    else:
        direction[0] = -1 if F[0] > 0 else 1
    direction[direction == 0] = np.where(F[direction == 0] > 0, -1, 1)
    if defined:
        if F0 != 0.0 or work_input is not None:
            raise ValueError(
                f"F0 and work_input apply only to tables without E_p (rate-dependent classes); the table of "
                f"{type(system.friction).__name__} has its own E_0 and E_d, got F0 = {F0!r}, work_input = {work_input!r}"
            )
        E_p = np.asarray(table.E_p, dtype=float)
        E_d = np.asarray(table.E_d, dtype=float)[1:]
        E_0, E_d_initial = float(table.E_0), float(table.E_d[0])
        check = branch_energy(F, direction, friction=friction)
        label = "branch potential of the tabulated F_i, (3.9) for gamma = 1"
    else:
        E_p, E_0, W = _undefined_table_energy(table, system, friction, direction, F0, work_input)
        E_d = E_p[:-1] + W[1:] - E_p[1:]
        E_d_initial = E_0 + float(W[0]) - float(E_p[0])
        check, label = None, "none: E_p is computed from the tabulated forces"
    top = float(np.max(E_p))
    S, R = series(E_p, E_d)
    bound = lugre_bound(E_p, friction, E_0) if isinstance(friction, LuGre) else bound_check(E_p, friction=friction, E_0=E_0)
    return EnergyReport(
        source="reversal table",
        t=t,
        x=x,
        F=F,
        direction=direction,
        E_p=E_p,
        E_d=E_d,
        E_0=E_0,
        E_d_initial=E_d_initial,
        series_partial=S,
        series_remainder=R,
        residual_2_10=_rel_residual(E_p[:-1] - E_d - E_p[1:] + (0.0 if defined else W[1:]), top),
        E_p_check=check,
        E_p_check_label=label,
        E_p_check_max_rel_dev=None if check is None else _rel_residual(check - E_p, top),
        bound=bound,
    )


def _undefined_table_energy(
    table: ReversalTable, system: Oscillator, friction: FrictionModel, direction: np.ndarray, F0: Any, work_input: Any
) -> tuple[np.ndarray, float, np.ndarray]:
    """``E_p``, ``E_0`` and the input work per reversal for a table whose class defines no ``E_p``."""
    F0 = check_finite("F0", F0)
    if abs(F0) > friction.Fc:
        raise ValueError(f"F0 must lie in [-Fc, Fc] = [{-friction.Fc!r}, {friction.Fc!r}] N, got {F0!r}")
    n = len(table)
    if work_input is None:
        if system.forced:
            raise ValueError("work_input is required for the table of a forced system whose class defines no E_p "
                             "(pass SimulationResult.work_input), got None")
        W = np.zeros(n)
    else:
        W = np.atleast_1d(value_array("work_input", work_input))
        if W.shape != (n,):
            raise ValueError(f"work_input must hold one value per reversal ({n}), got {W.size}")
    F = np.asarray(table.F, dtype=float)
    s0 = -int(direction[0])
    if isinstance(friction, LuGre):
        return lugre_table_energy(F, friction), float(table.E_0) + float(lugre_table_energy(F0, friction)), W
    return branch_energy(F, direction, friction=friction), float(table.E_0) + float(branch_energy(F0, s0, friction=friction)), W
