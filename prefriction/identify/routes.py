"""Which route fits a driven-mass record: the open-loop Motion fit, the inverse model or the closed loop.

The open-loop :class:`prefriction.identify.Motion` fit integrates the recorded force through the
mass (multiple shooting chains its segments into one open-loop trajectory). On a record taken
under feedback that trajectory drifts: the force of a stiff loop holds the stage on its
reference, and a model error of a fraction of a percent integrates to millimetres over seconds,
while the positions hardly depend on the friction (the EMPS benchmark's description says so).
:func:`recommend` measures the drift without fitting anything: the closed-form inverse model
(:func:`prefriction.identify.inverse.static_inverse`: mass, Coulomb, viscous, offset) is
replayed open loop with the recorded force held over each sample (each interval in closed form,
sticking when the force stays inside the Coulomb band), and the *horizon* is the number of samples before the
replay leaves the measured positions by more than the tolerance ``10 s_x + 1e-3 ptp(x)``
(``s_x`` the position noise). A horizon shorter than an eighth of the record, or a closed-form
mass that is not positive (horizon 0: no positive mass replays the record), marks a record
whose force does not carry its motion: fit the force balance
(:func:`prefriction.identify.inverse.fit_inverse`), or the loop
(:func:`prefriction.identify.closed_loop_fit.fit_closed_loop`) when the controller is known.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from prefriction.identify.data import Motion

__all__ = ["Recommendation", "recommend"]

MIN_SAMPLES = 500
"""Records shorter than this are left to the open-loop Motion fit (too short to drift far, and
too short for the inverse model's filter and decimation)."""


@dataclass(frozen=True)
class Recommendation:
    """The route :func:`recommend` advises for a record.

    Attributes
    ----------
    route : {"motion", "inverse", "closed-loop"}
        ``"motion"``: :func:`prefriction.identify.fit` (open loop); ``"inverse"``:
        :func:`prefriction.identify.fit_inverse`; ``"closed-loop"``:
        :func:`prefriction.identify.fit_closed_loop`.
    reason : str
        Why, with the numbers.
    horizon : int
        Samples the open-loop replay of the closed-form inverse model stays within ``tolerance``
        (the record's length if it never leaves it).
    samples : int
        The record's length.
    tolerance : float
        The drift tolerance [m].
    """

    route: str
    reason: str
    horizon: int
    samples: int
    tolerance: float

    def __str__(self) -> str:
        return f"{self.route}: {self.reason}"


def _replay(t: np.ndarray, u: np.ndarray, x0: float, est: dict[str, float]) -> np.ndarray:
    """Open-loop positions [m] of ``m a + b v + Fc sign(v) + F_off = u``, ``u`` held over each sample.

    Each interval in closed form, ``v(h) = v0 e^(-b h / m) + (f / m) phi(h)`` with
    ``phi(h) = (1 - e^(-b h / m)) m / b`` (``h`` for ``b = 0``), ``f = u - F_off - Fc s``; a
    velocity that would change sign stops at zero (the mass sticks while ``|u - F_off| <= Fc``).
    """
    m, b, Fc, off = est["mass"], max(est["b"], 0.0), max(est["Fc"], 0.0), est["offset"]
    a = b / m
    x = np.empty(t.size)
    x[0], v = x0, 0.0

    def phis(h: float) -> tuple[float, float]:
        phi = -np.expm1(-a * h) / a if a > 0.0 else h
        return phi, ((h - phi) / a if a > 0.0 else 0.5 * h * h)

    for k in range(t.size - 1):
        h, drive, pos = float(t[k + 1] - t[k]), float(u[k]) - off, float(x[k])
        for _ in range(2):   # a stop inside the interval, then the rest of it
            if v == 0.0 and abs(drive) <= Fc:
                break
            s = np.sign(v) if v != 0.0 else np.sign(drive)
            f = (drive - Fc * s) / m
            phi, psi = phis(h)
            v1 = v * np.exp(-a * h) + f * phi
            if v1 * s >= 0.0:
                pos, v = pos + v * phi + f * psi, v1
                break
            tau = np.log1p(-v * a / f) / a if a > 0.0 else -v / f   # the closed form's stop time
            tau = min(max(float(tau), 0.0), h) if np.isfinite(tau) else 0.0
            phi, psi = phis(tau)
            pos, v, h = pos + v * phi + f * psi, 0.0, h - tau
        x[k + 1] = pos
    return x


def recommend(data: Motion, *, controller_known: bool = False) -> Recommendation:
    """Advise the route for a :class:`Motion` record (module docstring).

    Parameters
    ----------
    data : Motion
        Positions and the applied force.
    controller_known : bool, default False
        Whether the record's controller is known (a closed-loop record then gets ``"closed-loop"``
        rather than ``"inverse"``).

    Returns
    -------
    Recommendation

    Examples
    --------
    >>> import numpy as np
    >>> from prefriction import identify
    >>> t = np.arange(200) * 1e-3
    >>> identify.recommend(identify.Motion(t, 1e-3 * np.sin(20 * t), 50.0 * np.cos(20 * t), 1.0)).route
    'motion'
    """
    if not isinstance(data, Motion):
        raise TypeError(f"data must be prefriction.identify.Motion, got {type(data).__name__}")
    n = len(data)
    if data.free_decay or n < MIN_SAMPLES:
        why = "a free decay" if data.free_decay else f"{n} samples (< {MIN_SAMPLES})"
        return Recommendation("motion", f"{why}: the open-loop Motion fit", n, n, 0.0)
    from prefriction.identify.derivatives import derivatives
    from prefriction.identify.inverse import static_inverse

    try:
        d0 = derivatives(data.t, data.x)
        d = derivatives(data.t, data.x, tail=d0.border)
    except ValueError as exc:
        return Recommendation("motion", f"the inverse model's filters do not apply ({exc})", n, n, 0.0)
    est = static_inverse(data, d)
    tol = 10.0 * d.noise + 1e-3 * float(np.ptp(data.x))
    route = "closed-loop" if controller_known else "inverse"
    call = ("identify.fit_closed_loop(model, data, loop, reference)" if controller_known
            else "identify.fit_inverse(model, data) (or identify.fit_closed_loop(model, data, loop, reference) "
                 "with the record's controller)")
    if not (np.isfinite(est["mass"]) and est["mass"] > 0.0):
        return Recommendation(route, f"the closed-form inverse model of the record gives a mass of {est['mass']:.4g} "
                              f"kg (not physical): the recorded force does not accelerate the mass as measured, as "
                              f"under a stiff loop that holds the stage on its reference (a closed-loop record), "
                              f"and an open-loop Motion fit would integrate that force through the mass and drift. "
                              f"Fit the force balance or the loop instead: {call}", 0, n, tol)
    x = _replay(data.t, data.u, float(data.x[0]), est)
    out = np.flatnonzero(np.abs(x - data.x) > tol)
    horizon = int(out[0]) if out.size else n
    if horizon >= n // 8:
        return Recommendation("motion", f"the open-loop replay of the inverse model stays within {tol:.3g} m for "
                              f"{horizon} of {n} samples: the open-loop Motion fit", horizon, n, tol)
    return Recommendation(route, f"an open-loop replay of the record's inverse model (mass {est['mass']:.4g} kg) "
                          f"leaves the measured positions by more than {tol:.3g} m after {horizon} of {n} samples: "
                          f"the recorded force does not carry the motion (a closed-loop record), and integrating "
                          f"it through the mass drifts. Fit the force balance instead: {call}", horizon, n, tol)
