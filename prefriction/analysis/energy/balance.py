"""Energy balance at the reversals: the Dahl branch potential (3.9), the dissipation per
half-cycle (2.10), the dissipation series (2.11) and the bound (2.12)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from prefriction._validation import check_nonnegative
from prefriction.analysis.energy.checks import ROUNDING, check_model, first_bad, real_array, value_array
from prefriction.models import FrictionModel


def branch_energy(F: Any, direction: Any, *, friction: FrictionModel) -> np.ndarray:
    """Energy stored on a branch relative to its force zero crossing [J].

    For any rate-independent model whose branch energy depends on the force alone
    (:meth:`prefriction.FrictionModel.branch_energy_of_force`); for Dahl:

    ``E = (Fc^2 / sigma) H_gamma(s F / Fc)`` with ``H_gamma(f) = int_0^f phi (1 - phi)^-gamma dphi``
    and ``s`` the direction of motion on the branch. At a reversal, with ``s`` the *new*
    direction, this is the potential energy ``E_p`` of the paper, (3.9) for ``gamma = 1``:
    ``(Fc^2/sigma) (a - ln(1 + a))`` with ``a = |F_i| / Fc``.

    Parameters
    ----------
    F : array_like
        Friction forces [N], ``|F| <= Fc``, at least one.
    direction : array_like
        Direction of motion on the branch, +1 or -1 (broadcast against ``F``).
    friction : FrictionModel
        The friction model, e.g. :class:`prefriction.Dahl` (``sigma`` [N/m], ``Fc`` [N], ``gamma``).

    Returns
    -------
    numpy.ndarray
        Stored energy [J], >= 0, finite.

    Raises
    ------
    ValueError
        ``|F| > Fc``, NaN, a direction other than +-1, or a force at the saturation force in
        the direction of motion for a model whose energy is unbounded there (Dahl with
        ``gamma >= 1``: ``H_gamma(1) = inf``; in deep gross sliding the force rounds to ``Fc``).
    TypeError
        Non-real ``F`` or ``direction``, or a model the analysis does not cover.
    """
    friction = check_model(friction)
    F = real_array("F", F, what="a number or an array of real numbers")
    s = real_array("direction", direction, what="+1 or -1 or an array of them")
    if F.size == 0:
        raise ValueError(f"F must hold at least 1 value, got an empty array of shape {F.shape}")
    if not np.all(np.abs(s) == 1.0):
        bad = s[np.abs(s) != 1.0].flat[0]
        raise ValueError(f"direction must be +1 or -1 (every entry), got {float(bad)!r}")
    try:
        F, s = np.broadcast_arrays(F, s)
    except ValueError:
        raise ValueError(f"direction has shape {s.shape}, which does not broadcast against F of shape {F.shape}") from None
    Fc = friction.Fc
    first_bad("F", F, ~(np.abs(F) <= Fc * (1.0 + ROUNDING)), f"finite and in [-Fc, Fc] = [{-Fc!r}, {Fc!r}]")
    E = (Fc * Fc / friction.sigma) * friction.branch_energy_of_force(np.clip(F / Fc, -1.0, 1.0), s)
    infinite = ~np.isfinite(E)
    if np.any(infinite):
        i = np.unravel_index(int(np.flatnonzero(infinite)[0]), E.shape)
        raise ValueError(
            f"the branch energy is infinite at F{[int(k) for k in i] if E.ndim else ''} = {float(F[i])!r} N in direction "
            f"{int(s[i]):+d}: the force has reached (or rounded to) the saturation force s Fc, where this model "
            f"({type(friction).__name__}) stores unbounded energy and the force no longer determines it; "
            "allowed: s F < Fc on the loading side (deep gross sliding cannot be analysed from the force)"
        )
    return E


def dissipation(E_p: Any, *, input_work: Any = None) -> np.ndarray:
    """Energy dissipated in each half-cycle between reversals [J] (2.10).

    ``out[k] = E_p[k] - E_p[k + 1]`` (+ ``input_work[k]``, the work of an external force over
    the half-cycle, for forced motion).

    Parameters
    ----------
    E_p : array_like
        Potential energy at consecutive reversals [J], length n >= 1, each finite and >= 0.
    input_work : array_like, optional
        Work of the external force in each half-cycle [J], length n - 1, finite (either sign).

    Raises
    ------
    TypeError
        ``None``, strings, complex or other non-real entries (naming the argument).
    ValueError
        NaN, inf or a negative ``E_p``, an empty ``E_p``, or ``input_work`` of the wrong length.

    Returns
    -------
    numpy.ndarray
        Length n - 1: the half-cycles between reversals (``report.E_d[1:]`` of an energy report).
    """
    E_p = value_array("E_p", E_p, nonnegative=True)
    E_p = np.atleast_1d(E_p)
    E_d = E_p[:-1] - E_p[1:]
    if input_work is not None:
        w = np.atleast_1d(value_array("input_work", input_work, min_size=0))
        if w.shape != E_d.shape:
            raise ValueError(f"input_work has {w.size} values, expected len(E_p) - 1 = {E_d.size} (one per half-cycle)")
        E_d = E_d + w
    return E_d


def series(E_p: Any, E_d: Any) -> tuple[np.ndarray, np.ndarray]:
    """Partial sums of the dissipation series (2.11), ``E_p(i) = sum_{n >= i} E_d(n)``.

    With n reversals the data hold ``E_d(i)`` for ``i < n - 1`` only, so the series is
    truncated: ``S[i] = sum_{j=i}^{n-2} E_d[j]`` and the remainder ``R[i] = E_p[i] - S[i]``
    is the part of the series not yet dissipated. If (2.10) holds, ``R[i] = E_p[n-1]`` for
    every ``i`` (to rounding), and (2.11) states ``R -> 0`` as more reversals are added.

    Parameters
    ----------
    E_p : array_like
        Potential energy at the reversals [J], length n >= 1, each finite and >= 0.
    E_d : array_like
        Dissipation per half-cycle between reversals [J], length n - 1 (entry k from reversal k to
        k + 1: ``report.E_d[1:]`` or ``table.E_d[1:]``),
        finite (negative under forcing, see the module notes).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Partial sums ``S`` and remainders ``R``, each of length n [J].
    """
    E_p = np.atleast_1d(value_array("E_p", E_p, nonnegative=True))
    E_d = np.atleast_1d(value_array("E_d", E_d, min_size=0))
    if E_d.shape != (E_p.size - 1,):
        raise ValueError(f"E_d must hold len(E_p) - 1 = {E_p.size - 1} values, got {E_d.size} (shape {E_d.shape})")
    S = np.concatenate((np.cumsum(E_d[::-1])[::-1], [0.0]))
    return S, E_p - S


DEFAULT_LABEL = "(2.12) E_p <= Fc^2/(2 k_min)"


@dataclass(frozen=True)
class BoundCheck:
    """How far the potential energy at the reversals stays below the bound (2.12).

    Attributes
    ----------
    bound : float
        The paper's bound ``Fc^2 / (2 k_min)`` [J] with ``k_min = sigma``, the least tangent
        stiffness of the Dahl model on an unloading branch (any ``gamma >= 0``).
    bound_sharp : float
        The least upper bound for this ``gamma``, ``(Fc^2/sigma) H_gamma(-1)`` [J]
        (``(1 - ln 2) Fc^2/sigma`` for ``gamma = 1``; equal to ``bound`` for ``gamma = 0``).
    max_E_p : float
        Largest potential energy at a reversal [J].
    index : int
        Reversal at which it occurs.
    ratio : float
        ``max_E_p / bound`` (<= 1 when (2.12) holds).
    margin : float
        ``bound - max_E_p`` [J] (>= 0 when (2.12) holds).
    ratio_sharp : float
        ``max_E_p / bound_sharp``.
    holds : bool
        ``max_E_p <= bound`` up to rounding. (2.12) is stated strictly; equality is reached
        by ``gamma = 0`` after saturation, see ``strict``.
    strict : bool
        ``max_E_p < bound``.
    holds_sharp : bool
        ``max_E_p <= bound_sharp`` up to rounding.
    E_0 : float or None
        Energy of the initial state [J], if known. The first excursion from the initial
        velocity is not bounded by (2.12) (gross sliding), so it is reported, not checked.
    initial_ratio : float or None
        ``E_0 / bound``; > 1 means the first excursion starts in gross sliding.
    bound_label : str
        Which bound: (2.12) for rate-independent models; for LuGre the bristle bound
        ``E_p <= Fs^2 / (2 sigma0)`` (``|z| <= Fs / sigma0``, Canudas de Wit et al. 1995).
    """

    bound: float
    bound_sharp: float
    max_E_p: float
    index: int
    ratio: float
    margin: float
    ratio_sharp: float
    holds: bool
    strict: bool
    holds_sharp: bool
    E_0: Optional[float]
    initial_ratio: Optional[float]
    bound_label: str = DEFAULT_LABEL

    def format(self) -> str:
        """Readable summary of the check, one line per bound."""
        lines = [
            f"{self.bound_label} = {self.bound:.6e} J: "
            f"{'holds' if self.holds else 'VIOLATED'}{'' if self.strict or not self.holds else ' (with equality)'}, "
            f"max E_p = {self.max_E_p:.6e} J at reversal {self.index + 1}, ratio {self.ratio:.6f}, margin {self.margin:.3e} J",
        ]
        if self.bound_label == DEFAULT_LABEL:
            lines.append(
                f"sharp bound (Fc^2/sigma) H_gamma(-1) = {self.bound_sharp:.6e} J: "
                f"{'holds' if self.holds_sharp else 'VIOLATED'}, ratio {self.ratio_sharp:.6f}"
            )
        if self.E_0 is not None:
            note = "gross sliding in the first excursion, not covered by (2.12)" if self.initial_ratio > 1 else "within the bound"
            lines.append(f"initial energy E_0 = {self.E_0:.6e} J = {self.initial_ratio:.4g} x bound ({note})")
        return "\n".join(lines)


def bound_check(E_p: Any, *, friction: FrictionModel, E_0: Optional[float] = None) -> BoundCheck:
    """Check the bound (2.12) ``E_p(i) < Fc^2 / (2 k_min)`` and report by how much it holds.

    For the Dahl model (3.2) with ``gamma >= 0`` the tangent stiffness on an unloading branch
    (``s F <= 0``) is ``sigma (1 - f)^gamma >= sigma``, so ``k_min = sigma``. The sharp bound
    is the potential energy of a reversal at full saturation, ``(Fc^2/sigma) H_gamma(-1)``,
    ``(1 - ln 2) Fc^2/sigma = 0.306853 Fc^2/sigma`` for ``gamma = 1`` (paper, after (3.9)).

    Parameters
    ----------
    E_p : float or array_like
        Potential energy at the reversals [J], length >= 1, each finite and >= 0.
    friction : FrictionModel
        The (rate-independent) friction model; ``k_min`` is its least unloading stiffness.
    E_0 : float, optional
        Energy of the initial state [J], finite and >= 0; reported (ratio to the bound),
        never checked.

    Raises
    ------
    TypeError
        ``E_p`` or ``E_0`` not real numbers (``None`` is allowed for ``E_0`` only), or
        ``friction`` not a rate-independent model.
    ValueError
        NaN, inf, negative or empty ``E_p``; NaN, inf or negative ``E_0``.

    Returns
    -------
    BoundCheck
    """
    friction = check_model(friction)
    E_p = np.atleast_1d(value_array("E_p", E_p, nonnegative=True))
    E_0 = None if E_0 is None else check_nonnegative("E_0", E_0)
    scale = friction.Fc**2 / friction.sigma
    bound = 0.5 * friction.Fc**2 / friction.k_min
    sharp = scale * float(friction.branch_energy_of_force(np.array([-1.0]), 1.0)[0])
    i = int(np.argmax(E_p))
    top = float(E_p[i])
    e0 = None if E_0 is None else float(E_0)
    return BoundCheck(
        bound=bound,
        bound_sharp=sharp,
        max_E_p=top,
        index=i,
        ratio=top / bound,
        margin=bound - top,
        ratio_sharp=top / sharp,
        holds=top <= bound * (1.0 + ROUNDING),
        strict=top < bound,
        holds_sharp=top <= sharp * (1.0 + ROUNDING),
        E_0=e0,
        initial_ratio=None if e0 is None else e0 / bound,
    )
