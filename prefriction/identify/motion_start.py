"""Start values of a :class:`Motion` fit from a static least-squares fit of the measured force.

In sliding the friction of a dynamic model is close to its static map, so the record's force
balance ``u = m a + Fc sign(v) + b v + F_off`` (Coulomb, viscous and offset), integrated over
short windows that slide faster than a tenth of the largest speed (no acceleration estimate), is
linear in ``m``, ``Fc``, ``b`` and ``F_off``: ordinary least squares gives them without any
start value. A record that slides in one direction only cannot tell the offset
from ``Fc``: its offset starts at 0. These estimates fill in the start values the user did not
give (the mass, the offset) and are otherwise reported as checks beside the user's values, with
the pre-sliding stiffness from the transients after the reversals: the fit starts where the user
says, and :attr:`prefriction.identify.FitResult.start` says what set each start value.
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np
from scipy.signal import savgol_filter

from prefriction.identify.data import Motion
from prefriction.models.base import FrictionModel

__all__ = ["Start", "StaticStart", "data_start", "derivatives", "derivatives_of", "piece_edges", "secant",
           "start_values", "static_start", "stiffness_from_reversals"]

_RESOLVED = 8
"""Fewest samples in the first third of a reversal transient for a stiffness estimate."""
_SECANT = 2.0 / (3.0 * np.log(1.5))
"""Secant slope of the first third of a reversal transient in units of the stiffness (exponential
approach from the opposite sliding level: Dahl with ``gamma = 1``, LuGre at low speed);
:func:`secant` for any ``gamma``."""


def secant(gamma: float) -> float:
    """Secant slope of the first third of a Dahl reversal transient in units of ``sigma``.

    On the branch after a reversal the gap ``w = 1 - s F / Fc`` obeys ``dw/dx = -(sigma / Fc)
    w^gamma`` (Dahl (3.2)), so the travel from ``w = 2`` (the opposite sliding level) to ``w =
    4/3`` (a third of the change) is ``(Fc / sigma) int_{4/3}^{2} w^-gamma dw = (Fc / sigma)
    (2^(1 - gamma) - (4/3)^(1 - gamma)) / (1 - gamma)`` (``ln 1.5`` for ``gamma = 1``) while
    ``F`` changes by ``2 Fc / 3``: the secant slope is ``sigma (2/3) (1 - gamma) / (2^(1 - gamma)
    - (4/3)^(1 - gamma))``, 1.64 ``sigma`` at ``gamma = 1``, 2.67 ``sigma`` at ``gamma = 2``.

    Parameters
    ----------
    gamma : float
        Dahl's shape exponent, ``gamma >= 0``.
    """
    g = 1.0 - float(gamma)
    if abs(g) < 1e-9:
        return _SECANT
    return (2.0 / 3.0) * g / (2.0 ** g - (4.0 / 3.0) ** g)


def _shape_gamma(model: FrictionModel) -> float:
    """The ``gamma`` of the start model's Dahl term (1: no Dahl term, the exponential approach)."""
    from prefriction.models.dahl import Dahl

    for m in (model, *getattr(model, "models", ())):
        if isinstance(m, Dahl):
            return float(m.gamma)
    return 1.0
_WINDOW = 21
"""Samples of the Savitzky-Golay window (cubic) of the velocity and acceleration estimates."""
_V_WINDOW = 11
"""Samples of the Savitzky-Golay window of the velocities of the static balance."""
_SPAN = 10
"""Samples of each window over which the static balance is integrated."""


@dataclass(frozen=True)
class StaticStart:
    """Static least-squares estimates from a record: mass [kg] (``None`` if given), Coulomb
    force [N], viscous coefficient [N s/m] and force offset [N]."""

    mass: float | None
    Fc: float
    b: float
    offset: float


def derivatives(t: np.ndarray, x: np.ndarray, window: int = _WINDOW) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smoothed position [m], velocity [m/s] and acceleration [m/s^2] at the samples (cubic
    Savitzky-Golay over ``window`` samples, the mean sample interval)."""
    w = min(window, x.size - (1 - x.size % 2))
    h = float(np.mean(np.diff(t)))
    return (savgol_filter(x, w, 3), savgol_filter(x, w, 3, deriv=1, delta=h),
            savgol_filter(x, w, 3, deriv=2, delta=h))


def piece_edges(data: Motion) -> np.ndarray:
    """The first sample of every piece of ``data`` and, last, its length: the junctions of a
    :class:`prefriction.identify.pieces.Pieces` record (``[0, len(data)]`` for an ordinary one)."""
    return np.r_[0, np.asarray(getattr(data, "breaks", ()), dtype=int), len(data)]


def derivatives_of(data: Motion, window: int = _WINDOW) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`derivatives` of ``data``, of a :class:`prefriction.identify.pieces.Pieces` record
    within each piece: no smoothing window reaches across a junction."""
    edges = piece_edges(data)
    if edges.size == 2:
        return derivatives(data.t, data.x, window)
    parts = [derivatives(data.t[a:b], data.x[a:b], window) for a, b in zip(edges[:-1], edges[1:])]
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]


def _piece_index(data: Motion) -> np.ndarray:
    """The piece of every sample of ``data`` (0 throughout for an ordinary record)."""
    edges = piece_edges(data)
    return np.repeat(np.arange(edges.size - 1), np.diff(edges))


def static_start(data: Motion) -> StaticStart | None:
    """Least-squares Coulomb + viscous + offset (+ mass if ``data.mass`` is None) of a forced record.

    The balance is integrated over windows of :data:`_SPAN` samples in which every sample slides
    faster than a tenth of the top speed: ``m (v_j - v_i) = int u dt - Fc int sign(v) dt -
    b (x_j - x_i) - F_off (t_j - t_i)``, the force integrated exactly as held (or linear) between
    the samples, ``v`` from a cubic Savitzky-Golay fit over :data:`_V_WINDOW` samples. No
    acceleration is estimated: a smoothed second derivative lags a heavy stage's force by more
    than its Coulomb force (at 95 kg and 1 kHz it gave ``Fc`` of the wrong sign).

    Returns
    -------
    StaticStart or None
        ``None`` for a free decay (``u = 0``: the force balance has no scale), when fewer than 8
        windows slide, or when the estimates are not physical (a mass or ``Fc`` not positive: the
        record does not excite the balance enough). A negative viscous coefficient (a stage
        without viscous friction, and noise) is refitted without the viscous column: ``b = 0``.
    """
    if data.free_decay:
        return None
    _x, v, _a = derivatives_of(data, _V_WINDOW)
    piece = _piece_index(data)
    moving = np.abs(v) > 0.1 * float(np.max(np.abs(v)))
    dt = np.diff(data.t)
    held = data.u[:-1] if data.hold == "zoh" else 0.5 * (data.u[:-1] + data.u[1:])
    cu = np.r_[0.0, np.cumsum(held * dt)]
    cs = np.r_[0.0, np.cumsum(np.sign(v[:-1]) * dt)]
    i = np.arange(0, data.x.size - _SPAN, _SPAN // 2)
    i = i[[bool(np.all(moving[k:k + _SPAN + 1])) and piece[k] == piece[k + _SPAN] for k in i]]
    if i.size < 8:
        return None
    j = i + _SPAN
    dv, ds, dx, dtw, rhs = v[j] - v[i], cs[j] - cs[i], data.x[j] - data.x[i], data.t[j] - data.t[i], cu[j] - cu[i]
    both = min(np.count_nonzero(ds > 0), np.count_nonzero(ds < 0)) >= 0.1 * i.size
    cols = [ds, dx, dtw if both else np.zeros_like(dtw)]
    if data.mass is None:
        cols.insert(0, dv)
    else:
        rhs = rhs - data.mass * dv
    M = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(M, rhs, rcond=None)  # no offset column in one direction: 0
    if not coef[-2] >= 0.0:  # a stage without viscous friction: noise makes b < 0; b = 0 is its estimate
        col = len(cols) - 2
        M[:, col] = 0.0
        coef, *_ = np.linalg.lstsq(M, rhs, rcond=None)
        coef[col] = 0.0
    if data.mass is None:
        mass, coef = float(coef[0]), coef[1:]
    else:
        mass = None
    if (mass is not None and not mass > 0.0) or not coef[0] > 0.0:
        return None  # a record that does not excite the balance (e.g. one short move): no physical fit
    return StaticStart(mass, float(coef[0]), float(coef[1]), float(coef[2]))


@dataclass(frozen=True)
class Start:
    """Start values of a Motion fit and what set each of them (:func:`start_values`).

    Attributes
    ----------
    mass : float or None
        Start mass [kg] (``None``: the mass is known, ``data.mass``).
    offset : float
        Start offset [N].
    steps : tuple of str
        One line per step of the start pipeline: what was set, and from what.
    static : StaticStart or None
        The static least-squares estimates (:func:`static_start`).
    stiffness : float or None
        The pre-sliding stiffness [N/m] from the reversal transients (:func:`stiffness_from_reversals`).
    transients : int
        The number of reversal transients it comes from (the second start uses it from 2 on).
    """

    mass: float | None
    offset: float
    steps: tuple[str, ...]
    static: StaticStart | None = None
    stiffness: float | None = None
    transients: int = 0


def start_values(model: FrictionModel, data: Motion, mass0: float | None, offset0: float | None,
                 offset: bool) -> Start:
    """Start mass and offset of a Motion fit; the user's values are kept, the static estimates
    (:func:`static_start`) only fill in what the user did not give, and every step is reported.

    The start model's parameters are always the user's: the static Coulomb force, viscous
    coefficient and the pre-sliding stiffness (:func:`stiffness_from_reversals`) are reported as
    checks beside them.

    Raises
    ------
    ValueError
        If the mass is free, ``mass0`` is not given and the static fit finds no physical mass.
    """
    fit = static_start(data)
    steps = []
    if fit is None:
        why = ("a free decay (u = 0) has no force balance to fit" if data.free_decay
               else "the record does not excite the force balance (too few sliding samples, or a mass, Coulomb "
                    "force or viscous coefficient that comes out not positive)")
        steps.append(f"static least squares: none ({why})")
    else:
        steps.append("static least squares of u = m a + Fc sign(v) + b v + F_off over the sliding samples: "
                     + (f"mass {fit.mass:.4g} kg, " if fit.mass is not None else "")
                     + f"Fc {fit.Fc:.4g} N, b {fit.b:.4g} N s/m, offset {fit.offset:.4g} N")
    if data.mass is not None:
        steps.append(f"mass {data.mass:.6g} kg known (data.mass), not fitted")
    elif mass0 is not None:
        steps.append(f"mass {mass0:.6g} kg as given (mass0)" + _check(fit and fit.mass, "kg"))
    elif fit is not None and fit.mass is not None:
        mass0 = fit.mass
        steps.append(f"mass {mass0:.6g} kg from static least squares (no mass0 given)")
    else:
        raise ValueError(f"mass0 must be given when data.mass is None and the static least squares finds no mass "
                         f"({steps[0]}): the mass is fitted and needs a start value [kg], 0 < mass0 < inf")
    if offset:
        if offset0 is not None:
            steps.append(f"offset {offset0:.6g} N as given (offset0)" + _check(fit and fit.offset, "N"))
        elif fit is not None:
            offset0 = fit.offset
            steps.append(f"offset {offset0:.6g} N from static least squares (no offset0 given)"
                         + (" (the record slides one way only: 0)" if fit.offset == 0.0 else ""))
        else:
            offset0 = 0.0
            steps.append("offset 0 N (no offset0 given, no static estimate)")
    names = {p.name for p in type(model).parameters} | set(getattr(model, "parameter_names", ()))
    checks = []
    if fit is not None:
        checks.append(f"Fc {model.Fc:.4g} N (static: {fit.Fc:.4g} N)")
        if "sigma2" in names or "b" in names:
            b = getattr(model, "sigma2", None)
            if b is None:
                b = sum(getattr(m, "b", 0.0) for m in getattr(model, "models", ()))
            checks.append(f"viscous {b:.4g} N s/m (static: {fit.b:.4g} N s/m)")
    if data.mass is not None:
        m_data, off_data = data.mass, (fit.offset if fit is not None else offset0 or 0.0)
    elif fit is not None:  # the check and the second start (data_start) from the data alone
        m_data, off_data = fit.mass, fit.offset
    else:
        m_data, off_data = mass0, offset0 or 0.0
    k = stiffness_from_reversals(data, m_data, off_data, _shape_gamma(model))
    if k is not None:
        checks.append(f"stiffness {model.sigma:.4g} N/m (rough check from {k[1]} reversal transients: {k[0]:.4g} N/m)")
    steps.append("friction parameters as given by the start model" + (": " + ", ".join(checks) if checks else ""))
    return Start(mass0, float(offset0 or 0.0), tuple(steps), fit, None if k is None else k[0], 0 if k is None else k[1])


_STIFFNESS = ("sigma", "sigma0")
_VISCOUS = ("b", "sigma2")


def data_start(model: FrictionModel, free: list[str], start: Start) -> tuple[FrictionModel, float | None, float,
                                                                              str] | None:
    """A second start from the data alone, for a fit that failed from the user's start: every free
    Coulomb force at the static estimate (a free ``Fs`` moved with it, keeping the start's
    ``Fs / Fc``), a free viscous coefficient at the static one (if positive), a free stiffness at
    the one from the reversal transients (if two or more resolve it), the mass and the offset at
    the static ones.

    Returns
    -------
    tuple or None
        ``(model, mass0, offset0, line)``, ``line`` saying what was set; ``None`` without static
        estimates or when nothing would change.
    """
    from prefriction.identify.parameters import _build, _entries

    fit = start.static
    if fit is None:
        return None
    entries = [e for e in _entries(model) if e.field not in ("mass", "offset")]
    values = {e.name: e.value for e in entries}
    said = []
    for e in entries:
        base = e.name.rsplit(".", 1)[-1]
        if e.name not in free:
            continue
        if base == "Fc":
            values[e.name] = fit.Fc
        elif base == "Fs":
            values[e.name] = e.value * fit.Fc / float(model.Fc)
        elif base in _VISCOUS and fit.b > 0.0:
            values[e.name] = fit.b
        elif base in _STIFFNESS and start.stiffness is not None and start.transients >= 2:
            values[e.name] = start.stiffness
        else:
            continue
        said.append(f"{e.name} {values[e.name]:.4g}")
    mass0 = start.mass if fit.mass is None or "mass" not in free else fit.mass
    offset0 = fit.offset if "offset" in free else start.offset
    if mass0 != start.mass:
        said.append(f"mass {mass0:.4g} kg")
    if "offset" in free:
        said.append(f"offset {offset0:.4g} N")
    if not said:
        return None
    try:
        new = _build(model, entries, values)
    except ValueError:
        return None
    return new, mass0, offset0, "static least squares and reversal transients: " + ", ".join(said)


def _check(value: float | None, unit: str) -> str:
    return "" if value is None else f"; static least squares says {value:.4g} {unit} (a check only, not used)"


def stiffness_from_reversals(data: Motion, mass: float, offset: float,
                             gamma: float = 1.0) -> tuple[float, int] | None:
    """Pre-sliding stiffness [N/m] from the transients after the velocity reversals of a forced
    record, and the number of transients used.

    After a reversal the friction force ``F = u - m a - F_off`` (``a`` from the smoothed
    positions) moves from one sliding level to the other; its secant slope against the position
    over the first third of that change, divided by :func:`secant` of ``gamma`` (the start
    model's Dahl exponent; 1 for LuGre), is the pre-sliding stiffness: from the sliding level
    ``-s Fc`` the gap ``w = 1 - s F / Fc`` of Dahl (3.2) decays as ``dw/dx = -sigma w^gamma /
    Fc`` from 2 to ``4/3`` over the first third, a secant slope of ``2 sigma / (3 ln 1.5) = 1.64
    sigma`` for ``gamma = 1`` (and LuGre at low speed), ``8 sigma / 3`` for ``gamma = 2``
    (``dF/dx = sigma`` holds only from ``F = 0``). The median over the reversals is returned; ``None`` for a free
    decay or when no transient spans :data:`_RESOLVED` samples (at 1 kHz a stage's transient
    lasts a few samples and the smoothing spans it: the slope came out 50 times too stiff).
    """
    if data.free_decay:
        return None
    shape = secant(gamma)
    xs, v, a = derivatives_of(data)
    piece = _piece_index(data)
    F = data.u - mass * a - offset
    moving = np.abs(v) > 0.05 * float(np.max(np.abs(v)))
    sgn = np.sign(v)
    idx = np.flatnonzero((sgn[1:] * sgn[:-1] < 0.0) & (piece[1:] == piece[:-1]))
    slopes = []
    for k in idx:
        s = sgn[k + 1]
        last = int(np.flatnonzero(piece == piece[k])[-1])   # the transient ends in its own piece
        ahead = moving[k + 1:last + 1]
        end = k + 1 + int(np.argmax(ahead)) if np.any(ahead) else last
        seg = slice(k, max(end, k + 3))
        Fs, xseg = F[seg], xs[seg]
        if xseg.size < 4:
            continue
        span = float(np.ptp(Fs))
        near = np.abs(Fs - Fs[0]) <= span / 3.0
        if np.count_nonzero(near) < _RESOLVED or np.ptp(xseg[near]) <= 0.0:
            continue
        slope = np.polyfit(xseg[near], Fs[near], 1)[0] * s / shape
        if slope > 0.0:
            slopes.append(slope)
    if not slopes:
        return None
    return float(np.median(slopes)), len(slopes)
