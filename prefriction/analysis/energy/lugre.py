"""Energy balance of a LuGre oscillator: stored bristle energy, viscous and hysteretic
dissipation per half-cycle (Canudas de Wit, Olsson, Astrom, Lischinsky 1995).

The derivation is in ``docs/mathematics.md#lugre-energy``. With the bristle deflection ``z``,
``z' = v - sigma0 |v| z / g(v)`` and ``F = sigma0 z + sigma1 z' + sigma2 v``, the friction power
splits as

    F v = d/dt (sigma0 z^2 / 2) + sigma0 z (v - z') + (sigma1 z' + sigma2 v) v,

so over a half-cycle ``E_p(i) + W_u(i) - E_p(i+1) = D_hysteretic(i) + D_viscous(i)`` with the
stored energy ``E_p = sigma0 z^2 / 2`` at a reversal (``v = 0``, ``z' = 0``: ``F = sigma0 z``),
the hysteretic dissipation ``int sigma0 z (v - z') dt = int sigma0^2 |v| z^2 / g(v) dt >= 0``
and the viscous dissipation ``int (sigma1 z' + sigma2 v) v dt``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from prefriction.analysis.energy.balance import BoundCheck
from prefriction.analysis.energy.checks import check_samples
from prefriction.analysis.energy.sampled_reversals import SampledReversals
from prefriction.analysis.energy.work import split_integrals
from prefriction.models import LuGre

CONDITION_MIN = 1e-3
"""Least ``|1 - sigma1 |v| / g(v)|`` at which the deflection is solved from the force; below it
the sample's deflection is interpolated in time from its neighbours (see :func:`bristle_deflection`)."""


def _stribeck(friction: LuGre, v: np.ndarray) -> np.ndarray:
    """``g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2)`` [N] (1995, (3))."""
    return friction.Fc + (friction.Fs - friction.Fc) * np.exp(-((v / friction.vs) ** 2))


def _deflection(t: np.ndarray, v: np.ndarray, F: np.ndarray, friction: LuGre) -> tuple[np.ndarray, np.ndarray, int]:
    """Deflection ``z`` [m], its rate ``z'`` [m/s] and the number of interpolated samples."""
    g = _stribeck(friction, v)
    den = 1.0 - friction.sigma1 * np.abs(v) / g
    good = np.abs(den) >= CONDITION_MIN
    if not np.any(good):
        raise ValueError(
            f"the bristle deflection cannot be solved from F at any of the {t.size} samples: "
            f"|1 - sigma1 |v| / g(v)| < {CONDITION_MIN:g} everywhere (sigma1 = {friction.sigma1!r} N s/m); "
            "sample a trajectory that passes through slower motion"
        )
    z = np.empty_like(v)
    z[good] = (F[good] - (friction.sigma1 + friction.sigma2) * v[good]) / (friction.sigma0 * den[good])
    if not np.all(good):
        z[~good] = np.interp(t[~good], t[good], z[good])
    zd = v - friction.sigma0 * np.abs(v) * z / g
    return z, zd, int(np.count_nonzero(~good))


def bristle_deflection(t: Any, v: Any, F: Any, *, friction: LuGre) -> np.ndarray:
    """Bristle deflection ``z`` [m] of a LuGre model from sampled velocity and friction force.

    Eliminating ``z'`` from ``F = sigma0 z + sigma1 z' + sigma2 v`` with
    ``z' = v - sigma0 |v| z / g(v)`` (Canudas de Wit et al. 1995, (1)-(3)) gives

        ``z = (F - (sigma1 + sigma2) v) / (sigma0 (1 - sigma1 |v| / g(v)))``,

    exact at every sample. Where ``|1 - sigma1 |v| / g(v)| < 1e-3`` (:data:`CONDITION_MIN`;
    sliding at ``|v|`` near ``g / sigma1``) the division would amplify the force's error by more
    than 1000, and the deflection is interpolated linearly in time from the other samples.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, length N >= 2.
    v : array_like
        Velocities [m/s], length N.
    F : array_like
        Friction forces [N] at the same times (the force at ``t[0]`` with the initial
        velocity, not the bristle force alone).
    friction : LuGre
        The model.

    Returns
    -------
    numpy.ndarray
        ``z`` [m] at every sample.
    """
    friction = _check_lugre(friction)
    t, v, F = check_samples(t=t, v=v, F=F)
    return _deflection(t, v, F, friction)[0]


def _check_lugre(friction: Any) -> LuGre:
    if not isinstance(friction, LuGre):
        raise TypeError(f"friction must be a prefriction.LuGre model, got {friction!r} of type {type(friction).__name__}")
    return friction


def lugre_bound(E_p: np.ndarray, friction: LuGre, E_0: float) -> BoundCheck:
    """The LuGre analogue of (2.12): ``|z| <= Fs / sigma0`` for all time if it holds at the start
    (1995, property 1), so ``E_p = sigma0 z^2 / 2 <= Fs^2 / (2 sigma0)`` at every reversal."""
    bound = 0.5 * friction.Fs**2 / friction.sigma0
    i = int(np.argmax(E_p))
    top = float(E_p[i])
    slack = 1.0 + 64 * np.finfo(float).eps
    return BoundCheck(
        bound=bound, bound_sharp=bound, max_E_p=top, index=i, ratio=top / bound, margin=bound - top,
        ratio_sharp=top / bound, holds=top <= bound * slack, strict=top < bound, holds_sharp=top <= bound * slack,
        E_0=E_0, initial_ratio=E_0 / bound, bound_label="LuGre |z| <= Fs/sigma0: E_p <= Fs^2/(2 sigma0)",
    )


def half_cycle_split(
    t: np.ndarray, v: np.ndarray, F: np.ndarray, rev: SampledReversals, friction: LuGre, method: str
) -> dict[str, Any]:
    """The dissipation terms of the LuGre oscillator over the first excursion and each half-cycle:
    rows ``int sigma2 v^2``, ``int sigma1 z' v`` and ``int sigma0 z (v - z')`` [J]."""
    z, zd, n_interp = _deflection(t, v, F, friction)
    p_s2 = friction.sigma2 * v * v
    p_s1 = friction.sigma1 * zd * v
    p_h = friction.sigma0 * z * (v - zd)
    D = split_integrals(t, np.vstack((p_s2, p_s1, p_h)), rev, method)
    return {"z": z, "z_rev": _hermite(t, z, zd, rev), "interpolated": n_interp, "first": D[:, 0], "half": D[:, 1:]}


def _hermite(t: np.ndarray, z: np.ndarray, zd: np.ndarray, rev: SampledReversals) -> np.ndarray:
    """Deflection at the reversals by cubic Hermite interpolation of ``(z, z')`` in time between
    the samples around each (third order; the force is no function of ``x`` near a reversal,
    ``F' = sigma0 v + (sigma1 + sigma2) v'`` while ``x' = 0``, so it is not extrapolated in ``x``)."""
    a = rev.index
    b = a + 1
    h = t[b] - t[a]
    s = (rev.t - t[a]) / h
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * z[a] + h10 * h * zd[a] + h01 * z[b] + h11 * h * zd[b]
