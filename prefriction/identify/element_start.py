"""Start values of Maxwell-slip and GMS Motion fits from the force balance along the measured motion.

A Maxwell-slip element of stiffness ``k_i`` and slip deflection ``d_i = W_i / k_i`` carries
``k_i p(x; d_i)``, ``p`` the play (stop) operator of half-width ``d_i`` applied to the position
from the virgin state: ``p_0 = 0``, ``p_(j+1) = clip(p_j + x_(j+1) - x_j, -d_i, d_i)``. For
given deflections the force balance (2.1) along the filtered motion,

    u = m a + F_off + sum_i k_i p(x; d_i),                                                   (1)

is linear in the mass, the offset and the stiffnesses: the deflections are searched on a grid
(every choice of ``N`` of :data:`GRID` log-spaced deflections), the rest solved by linear least
squares in each (the inverse-model filtering and decimation of
:mod:`prefriction.identify.derivatives`). No start value enters; the deflections come out
distinct and ordered, away from the saddle of equal deflections, where two elements can trade
stiffness and slip force without changing the force. The best grid point is refined by the
inverse-model fit of the model itself (:func:`prefriction.identify.fit_inverse`, the friction
along the filtered motion by :func:`prefriction.friction_along`). A GMS element sticks like a
Maxwell-slip element up to ``alpha_i S(v)``: its stiffnesses come from the same grid and its
Coulomb force from the slip forces, ``Fc = sum W_i / sum alpha_i``.

:func:`prefriction.identify.fit` starts from it only where its shooting segments follow the record
more closely than those of the user's start (:func:`prefriction.identify.shooting.start_error`;
the inverse model's own residual is biased by the filter and would replace even the truth), and
:attr:`prefriction.identify.FitResult.start` says what replaced what.
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction.identify.data import Motion
from prefriction.models.base import FrictionModel

__all__ = ["ElementStart", "element_start", "play"]

GRID = 16
"""Deflections of the grid search, log-spaced over three decades below half the record's travel."""
SHARPER = 2.0
"""The cut-off of the filter is this many times the inverse model's default (at most a fifth of the
sample rate) and the decimation a quarter of its default: the transients after the reversals,
which set the deflections, last a few samples (on the Maxwell-slip(3) records of
``tests/test_identify_motion_events.py`` the default filter put the grid's stiffnesses up to 8
times off, this one within 1.4 times)."""
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
    """A start of a Maxwell-slip or GMS Motion fit from the grid search (1) and the inverse model.

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
        ``None`` for another model, a free decay, too many elements for the grid, or a record too
        short for the filter.
    """
    from prefriction.identify.derivatives import derivatives

    kind = _kind(model)
    if kind is None or data.free_decay:
        return None
    n = len(model.stiffness if kind == "MaxwellSlip" else model.k)
    if math.comb(GRID, n) > COMBINATIONS:
        return None
    try:
        d0 = derivatives(data.t, data.x)
        fs = 1.0 / float(np.mean(np.diff(data.t)))
        d = derivatives(data.t, data.x, cutoff=min(SHARPER * d0.cutoff, 0.2 * fs), step=max(1, d0.step // 4))
    except ValueError:
        return None
    mass_free = data.mass is None and "mass" in free
    mass_known = float(data.mass) if data.mass is not None else float(mass0)
    found = _grid(d, data, n, mass_free, mass_known, offset and "offset" in free)
    if found is None:
        return None
    k, widths, mass, off = found
    if not mass_free:
        mass = mass0
    if not (offset and "offset" in free):
        off = offset0
    new = _assign(model, kind, k, widths, free)
    if new is None:
        return None
    new, mass, off, how = _refine(new, data, d, free, mass, off, offset, mass_free)
    ours = _inverse_rss(new, d, data, mass_known if mass is None else mass, off)
    changed = [f"{name} {a:.4g} -> {b:.4g}" for name, a, b in _changes(model, new, free)]
    if mass_free and mass0 is not None:
        changed.append(f"mass {mass0:.4g} -> {mass:.4g} kg")
    if offset and "offset" in free:
        changed.append(f"offset {offset0:.4g} -> {off:.4g} N")
    line = (f"element start (the force balance u = m a + F_off + sum k_i p(x; d_i) along the filtered motion, "
            f"{n} of {GRID} slip deflections by grid search, linear least squares; {how}; inverse-model "
            f"residual {math.sqrt(ours):.4g} N rms): " + ", ".join(changed))
    return ElementStart(new, mass if mass_free else mass0, float(off), line)


def _grid(d: Any, data: Motion, n: int, mass_free: bool, mass: float,
          offset: bool) -> tuple[np.ndarray, np.ndarray, float, float] | None:
    """The best deflections of the grid and the linear least squares of (1) at them."""
    half = 0.5 * float(np.ptp(d.x))
    if not half > 0.0:
        return None
    widths = np.geomspace(1e-3 * half, half, GRID)
    P = np.column_stack([d.regress(c) for c in play(d.x, widths).T])
    a = d.regress(d.a)
    y = d.regress(data.u) - (0.0 if mass_free else mass * a)
    base = ([a] if mass_free else []) + ([d.regress(np.ones_like(d.a))] if offset else [])
    B = np.column_stack(base) if base else np.zeros((y.size, 0))
    best, keep = np.inf, None
    for combo in itertools.combinations(range(GRID), n):
        M = np.column_stack([B, P[:, combo]])
        coef, *_ = np.linalg.lstsq(M, y, rcond=None)
        k = coef[B.shape[1]:]
        if np.any(k <= 0.0) or (mass_free and not coef[0] > 0.0):
            continue
        r = y - M @ coef
        rss = float(r @ r)
        if rss < best:
            best, keep = rss, (coef, combo)
    if keep is None:
        return None
    coef, combo = keep
    mass_est = float(coef[0]) if mass_free else mass
    off = float(coef[int(mass_free)]) if offset else 0.0
    return coef[B.shape[1]:], widths[list(combo)], mass_est, off


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


def _refine(model: FrictionModel, data: Motion, d: Any, free: list[str], mass: float | None, off: float,
            offset: bool, mass_free: bool) -> tuple[FrictionModel, float | None, float, str]:
    """The inverse-model fit of the model itself from the grid start (kept if it converges)."""
    from prefriction.identify.inverse import fit_inverse

    # the Maxwell-slip part only: the inverse model along a filtered motion does not see the
    # slip rate C and the Stribeck rise of a GMS (on the GMS(2) records of
    # tests/test_identify_motion_events.py they moved 600 times and to Fs = Fc)
    names = [f for f in free if f not in ("mass", "offset") and f.split("[")[0] in ("stiffness", "slip_force", "k", "Fc")]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = fit_inverse(model, data, offset=offset and "offset" in free, free=names,
                              mass0=mass if mass_free else None, offset0=off, deriv=d, max_iter=100)
    except (ValueError, ArithmeticError):
        return model, mass, off, "the inverse-model refinement failed: the grid's values"
    if not res.success:
        return model, mass, off, "the inverse-model refinement did not converge: the grid's values"
    est = dict(zip(res.names, res.estimates))
    return (res.model, est.get("mass", mass), est.get("offset", off),
            "refined by the inverse-model fit (friction_along)")


def _inverse_rss(model: FrictionModel, d: Any, data: Motion, mass: float, off: float) -> float:
    """Mean square of the inverse-model residual ``u - m a - F_off - F(x_f)`` [N^2]."""
    from prefriction.along import friction_along

    F = friction_along(model, d.t, d.x, v=d.v).F
    r = d.regress(data.u) - mass * d.regress(d.a) - off * d.regress(np.ones_like(d.a)) - d.regress(F)
    return float(np.mean(r * r))


def _changes(old: FrictionModel, new: FrictionModel, free: list[str]) -> list[tuple[str, float, float]]:
    from prefriction.identify.parameters import _entries

    before = {e.name: e.value for e in _entries(old)}
    after = {e.name: e.value for e in _entries(new)}
    return [(n, before[n], after[n]) for n in after if n in free and n in before and after[n] != before[n]]
