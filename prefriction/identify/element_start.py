"""Start values of Maxwell-slip and GMS Motion fits from the force balance along the measured motion.

A Maxwell-slip element of stiffness ``k_i`` and slip deflection ``d_i = W_i / k_i`` carries
``k_i p(x; d_i)``, ``p`` the play (stop) operator of half-width ``d_i`` applied to the position
from the virgin state: ``p_0 = 0``, ``p_(j+1) = clip(p_j + x_(j+1) - x_j, -d_i, d_i)``. For
given deflections the force balance (2.1) integrated over short windows ``[t_a, t_b]``,

    m (v_b - v_a) + F_off (t_b - t_a) + sum_i k_i int p(x; d_i) dt = int u dt,                (1)

is linear in the mass, the offset and the stiffnesses, and needs no acceleration (``x`` and
``v`` from a cubic Savitzky-Golay fit over :data:`WINDOW` samples, the windows :data:`SPAN`
samples long; a filtered acceleration, as the inverse model uses, lags the transients after the
reversals that set the deflections, and put them 30 % off). The deflections are searched on a
grid (every choice of ``N`` of :data:`GRID` log-spaced deflections), the rest solved by linear
least squares at each, and the best choice refined by ``scipy.optimize.least_squares`` over the
logarithms of the deflections (variable projection: the linear part solved at each). No start
value enters; the deflections come out distinct and ordered, away from the saddle of equal
deflections, where two elements can trade stiffness and slip force without changing the force.
A GMS element sticks like a Maxwell-slip element up to ``alpha_i S(v)``: its stiffnesses come
from the same search and its Coulomb force from the slip forces, ``Fc = sum W_i / sum alpha_i``.

:func:`prefriction.identify.fit` starts from it only where its shooting segments follow the record
more closely than those of the user's start (:func:`prefriction.identify.shooting.start_error`),
and :attr:`prefriction.identify.FitResult.start` says what replaced what.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from prefriction.identify.data import Motion
from prefriction.models.base import FrictionModel

__all__ = ["ElementStart", "element_start", "play"]

GRID = 16
"""Deflections of the grid search, log-spaced over three decades below half the record's travel."""
SPAN = 5
"""Samples of each window of the integrated balance (1); windows start every other sample."""
WINDOW = 11
"""Samples of the Savitzky-Golay window (cubic) of the positions and velocities."""
COMBINATIONS = 5_000
"""Most choices of deflections tried (Maxwell-slip with more elements than that allows: no grid start)."""


@dataclass(frozen=True)
class ElementStart:
    """What :func:`element_start` found: the start model, mass [kg] (``None``: known), offset [N],
    and one line saying what replaced what."""

    model: FrictionModel
    mass: float | None
    offset: float
    line: str


def play(x: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """Play operators of half-widths ``widths`` [m] along the positions ``x`` [m] from the virgin
    state (module docstring): ``(x.size, widths.size)`` element deflections [m]."""
    out = np.empty((x.size, widths.size))
    p = np.zeros(widths.size)
    out[0] = p
    dx = np.diff(x)
    for j in range(dx.size):
        p = np.clip(p + dx[j], -widths, widths)
        out[j + 1] = p
    return out


def _kind(model: FrictionModel) -> str | None:
    name = type(model).__name__
    return name if name in ("MaxwellSlip", "GMS") else None


def element_start(model: FrictionModel, data: Motion, free: list[str], mass0: float | None,
                  offset0: float, offset: bool) -> ElementStart | None:
    """A start of a Maxwell-slip or GMS Motion fit from the integrated force balance (1).

    Parameters
    ----------
    model : MaxwellSlip or GMS
        The user's start model (its element order is kept: the elements found are assigned to the
        user's elements in the order of their slip deflections).
    data : Motion
        A forced record (not a free decay).
    free : list of str
        The free parameters: only these are replaced.
    mass0 : float or None
        The start mass [kg] (``None``: known, ``data.mass``).
    offset0 : float
        The start offset [N].
    offset : bool
        Whether the offset is fitted.

    Returns
    -------
    ElementStart or None
        ``None`` for another model, a free decay, too many elements for the grid, a record
        shorter than ``4 WINDOW`` samples, or no choice of deflections with positive stiffnesses
        (and mass).
    """
    kind = _kind(model)
    if kind is None or data.free_decay or len(data) < 4 * WINDOW:
        return None
    n = len(model.stiffness if kind == "MaxwellSlip" else model.k)
    if math.comb(GRID, n) > COMBINATIONS:
        return None
    mass_free = data.mass is None and "mass" in free
    fit_offset = offset and "offset" in free
    mass_known = float(data.mass) if data.mass is not None else float(mass0)
    found = _search(data, n, mass_free, mass_known, fit_offset, offset0 if offset else 0.0)
    if found is None:
        return None
    k, widths, mass, off, rms = found
    if not mass_free:
        mass = mass0
    if not fit_offset:
        off = offset0
    new = _assign(model, kind, k, widths, free)
    if new is None:
        return None
    changed = [f"{name} {a:.4g} -> {b:.4g}" for name, a, b in _changes(model, new, free)]
    if mass_free and mass0 is not None:
        changed.append(f"mass {mass0:.4g} -> {mass:.4g} kg")
    if offset and "offset" in free:
        changed.append(f"offset {offset0:.4g} -> {off:.4g} N")
    line = (f"element start (the force balance m dv + F_off dt + sum k_i int p(x; d_i) dt = int u dt over "
            f"{SPAN}-sample windows, {n} of {GRID} slip deflections by grid search then refined, linear least "
            f"squares in the rest; rms {rms:.3g} N s): " + ", ".join(changed))
    return ElementStart(new, mass if mass_free else mass0, float(off), line)


def _search(data: Motion, n: int, mass_free: bool, mass: float, offset: bool,
            offset0: float) -> tuple[np.ndarray, np.ndarray, float, float, float] | None:
    """Stiffnesses, deflections [m], mass [kg], offset [N] and rms residual [N s] of (1)."""
    from scipy.optimize import least_squares

    from prefriction.identify.motion_start import derivatives

    xs, v, _a = derivatives(data.t, data.x, WINDOW)
    half = 0.5 * float(np.ptp(xs))
    if not half > 0.0:
        return None
    dt = np.diff(data.t)
    held = data.u[:-1] if data.hold == "zoh" else 0.5 * (data.u[:-1] + data.u[1:])
    cu = np.r_[0.0, np.cumsum(held * dt)]
    i = np.arange(0, len(data) - SPAN, 2)
    j = i + SPAN

    def columns(widths: np.ndarray) -> np.ndarray:
        P = play(xs, widths)
        cP = np.vstack([np.zeros((1, widths.size)), np.cumsum(0.5 * (P[1:] + P[:-1]) * dt[:, None], axis=0)])
        return cP[j] - cP[i]

    base = ([v[j] - v[i]] if mass_free else []) + ([data.t[j] - data.t[i]] if offset else [])
    B = np.column_stack(base) if base else np.zeros((i.size, 0))
    y = cu[j] - cu[i] - (0.0 if mass_free else mass * (v[j] - v[i])) - (0.0 if offset else offset0 * (data.t[j] - data.t[i]))
    nb = B.shape[1]

    def solve(C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        M = np.column_stack([B, C])
        coef, *_ = np.linalg.lstsq(M, y, rcond=None)
        return coef, y - M @ coef

    grid = np.geomspace(1e-3 * half, half, GRID)
    C = columns(grid)
    best, keep = np.inf, None
    for combo in itertools.combinations(range(GRID), n):
        coef, r = solve(C[:, combo])
        if np.any(coef[nb:] <= 0.0) or (mass_free and not coef[0] > 0.0):
            continue
        if float(r @ r) < best:
            best, keep = float(r @ r), grid[list(combo)]
    if keep is None:
        return None
    sol = least_squares(lambda lw: solve(columns(np.exp(lw)))[1], np.log(keep), method="trf",
                        bounds=(np.log(1e-4 * half), np.log(2.0 * half)), max_nfev=50 * n)
    widths = np.exp(sol.x)
    coef, r = solve(columns(widths))
    if np.any(coef[nb:] <= 0.0) or (mass_free and not coef[0] > 0.0) or not float(r @ r) <= best:
        widths = keep
        coef, r = solve(columns(widths))
    return (coef[nb:], widths, float(coef[0]) if mass_free else mass, float(coef[int(mass_free)]) if offset else offset0,
            float(np.sqrt(np.mean(r * r))))


def _assign(model: FrictionModel, kind: str, k: np.ndarray, widths: np.ndarray,
            free: list[str]) -> FrictionModel | None:
    """The user's model with the elements found: Maxwell-slip's in the order of the start's slip
    deflections, GMS's in the order of their fractions ``alpha_i`` (held) by their slip forces."""
    from prefriction.identify.parameters import _build, _entries

    entries = [e for e in _entries(model) if e.field not in ("mass", "offset")]
    values = {e.name: e.value for e in entries}
    if kind == "MaxwellSlip":
        kk, W = np.asarray(model.stiffness, float), np.asarray(model.slip_force, float)
        order = np.argsort(W / kk)
        for slot, i in zip(order, np.argsort(widths)):
            for name, value in ((f"stiffness[{slot}]", k[i]), (f"slip_force[{slot}]", k[i] * widths[i])):
                if name in free:
                    values[name] = float(value)
    else:
        alpha = np.asarray(model.alpha, float)
        # element i slips at alpha_i S: the slip forces found go to the elements in the order of alpha
        for slot, i in zip(np.argsort(alpha, kind="stable"), np.argsort(k * widths, kind="stable")):
            if f"k[{slot}]" in free:
                values[f"k[{slot}]"] = float(k[i])
        Fc = float(np.sum(k * widths) / np.sum(alpha))
        if "Fc" in free:
            if "Fs" in free:
                values["Fs"] = float(model.Fs) * Fc / float(model.Fc)
            values["Fc"] = Fc
    try:
        return _build(model, entries, values)
    except ValueError:
        return None


def _changes(old: FrictionModel, new: FrictionModel, free: list[str]) -> list[tuple[str, float, float]]:
    from prefriction.identify.parameters import _entries

    before = {e.name: e.value for e in _entries(old)}
    after = {e.name: e.value for e in _entries(new)}
    return [(n, before[n], after[n]) for n in after if n in free and n in before and after[n] != before[n]]
