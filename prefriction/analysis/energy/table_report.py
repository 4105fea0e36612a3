"""Energy analysis of a trajectory given at its velocity reversals (:func:`analyze_table`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from prefriction._validation import check_finite
from prefriction.analysis.energy.balance import branch_energy, bound_check, series
from prefriction.analysis.energy.checks import value_array, check_system
from prefriction.analysis.energy.lugre import lugre_bound
from prefriction.analysis.energy.lugre_report import lugre_table_energy
from prefriction.analysis.energy.report import EnergyReport, _rel_residual
from prefriction.models import ElastoPlastic, FrictionModel, LuGre, Oscillator
from prefriction.reversals import ReversalTable


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

    The table of a forced run (an input signal or a feedback controller, e.g.
    ``controllers.simulate_loop(...).reversals``) includes the input's work in its ``E_d``;
    pass ``work_input`` (``SimulationResult.work_input``, ``LoopResult.simulation.work_input``)
    so that (2.10) is checked with it and the report holds it as ``W_u``. Without it the work
    is taken as zero.

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
        reversal, finite (``SimulationResult.work_input``); required for a table without
        ``E_p`` if the system is forced.

    Returns
    -------
    EnergyReport

    Raises
    ------
    ValueError
        Empty table, a non-finite entry, times not strictly increasing, ``F0`` given for a
        table that has ``E_p``, or invalid ``F0``/``work_input``.
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
        if F0 != 0.0:
            raise ValueError(
                f"F0 applies only to tables without E_p (rate-dependent classes); the table of "
                f"{type(system.friction).__name__} has its own E_0, got F0 = {F0!r}"
            )
        W = _work_per_reversal(work_input, n, required=False, system=system)
        E_p = np.asarray(table.E_p, dtype=float)
        E_d = np.asarray(table.E_d, dtype=float)
        E_0 = float(table.E_0)
        check = branch_energy(F, direction, friction=friction)
        label = "branch potential of the tabulated F_i, (3.9) for gamma = 1"
    else:
        E_p, E_0, W = _undefined_table_energy(table, system, friction, direction, F0, work_input)
        E_d = np.concatenate(([E_0 + float(W[0]) - float(E_p[0])], E_p[:-1] + W[1:] - E_p[1:]))
        check, label = None, "none: E_p is computed from the tabulated forces"
    top = float(np.max(E_p))
    S, R = series(E_p, E_d[1:])
    bound = lugre_bound(E_p, friction, E_0) if isinstance(friction, (LuGre, ElastoPlastic)) else bound_check(E_p, friction=friction, E_0=E_0)
    return EnergyReport(
        source="reversal table",
        t=t,
        x=x,
        F=F,
        direction=direction,
        E_p=E_p,
        E_d=E_d,
        W_u=W,
        E_0=E_0,
        series_partial=S,
        series_remainder=R,
        residual_2_10=_rel_residual(E_p[:-1] - E_d[1:] - E_p[1:] + W[1:], top),
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
    W = _work_per_reversal(work_input, len(table), required=system.forced, system=system)
    F = np.asarray(table.F, dtype=float)
    s0 = -int(direction[0])
    if isinstance(friction, (LuGre, ElastoPlastic)):  # stored bristle energy sigma0 z^2 / 2, z' = 0 at v = 0
        return lugre_table_energy(F, friction), float(table.E_0) + float(lugre_table_energy(F0, friction)), W
    return branch_energy(F, direction, friction=friction), float(table.E_0) + float(branch_energy(F0, s0, friction=friction)), W


def _work_per_reversal(work_input: Any, n: int, *, required: bool, system: Oscillator) -> np.ndarray:
    """``work_input`` checked as one finite value per reversal [J]; zeros if ``None`` and not ``required``."""
    if work_input is None:
        if required:
            raise ValueError("work_input is required for the table of a forced system whose class defines no E_p "
                             f"({type(system.friction).__name__}; pass SimulationResult.work_input), got None")
        return np.zeros(n)
    W = np.atleast_1d(value_array("work_input", work_input))
    if W.shape != (n,):
        raise ValueError(f"work_input must hold one value per reversal ({n}), got {W.size}")
    return W
