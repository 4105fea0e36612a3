"""Which route fits a driven-mass record: the open-loop Motion fit, the inverse model or the closed loop.

The open-loop :class:`prefriction.identify.Motion` fit integrates the recorded force through the
mass (multiple shooting chains its segments into one open-loop trajectory). On a record taken
under feedback that trajectory drifts: the force of a stiff loop holds the stage on its
reference, and a model error of a fraction of a percent integrates to millimetres over seconds,
while the positions hardly depend on the friction (the EMPS benchmark's description says so).
:func:`recommend` measures the drift without fitting anything: the closed-form inverse model
(:func:`prefriction.identify.inverse.static_inverse`: mass, Coulomb, viscous, offset) is
replayed open loop with the recorded force (semi-implicit Euler per sample, sticking when the
force stays inside the Coulomb band), and the *horizon* is the number of samples before the
replay leaves the measured positions by more than the tolerance ``10 s_x + 1e-3 ptp(x)``
(``s_x`` the position noise). A horizon shorter than an eighth of the record marks a record
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
    """Open-loop positions [m] of ``m a + b v + Fc sign(v) + F_off = u`` (semi-implicit Euler, sticking)."""
    m, b, Fc, off = est["mass"], max(est["b"], 0.0), max(est["Fc"], 0.0), est["offset"]
    x = np.empty(t.size)
    x[0], v = x0, 0.0
    dt = np.diff(t)
    for k in range(t.size - 1):
        f = u[k] - off
        if v == 0.0 and abs(f) <= Fc:
            x[k + 1] = x[k]
            continue
        s = np.sign(v) if v != 0.0 else np.sign(f)
        vn = v + dt[k] * (f - b * v - Fc * s) / m
        if v != 0.0 and vn * v < 0.0:
            vn = 0.0
        v = vn
        x[k + 1] = x[k] + dt[k] * v
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
        d = derivatives(data.t, data.x)
    except ValueError as exc:
        return Recommendation("motion", f"the inverse model's filters do not apply ({exc})", n, n, 0.0)
    est = static_inverse(data, d)
    if not est["mass"] > 0.0:
        return Recommendation("motion", f"the closed-form inverse model gives a mass of {est['mass']:.4g} kg: "
                              f"the force does not accelerate the mass as measured", n, n, 0.0)
    tol = 10.0 * d.noise + 1e-3 * float(np.ptp(data.x))
    x = _replay(data.t, data.u, float(data.x[0]), est)
    out = np.flatnonzero(np.abs(x - data.x) > tol)
    horizon = int(out[0]) if out.size else n
    if horizon >= n // 8:
        return Recommendation("motion", f"the open-loop replay of the inverse model stays within {tol:.3g} m for "
                              f"{horizon} of {n} samples: the open-loop Motion fit", horizon, n, tol)
    route = "closed-loop" if controller_known else "inverse"
    call = ("identify.fit_closed_loop(model, data, loop, reference)" if controller_known
            else "identify.fit_inverse(model, data)")
    return Recommendation(route, f"an open-loop replay of the record's inverse model (mass {est['mass']:.4g} kg) "
                          f"leaves the measured positions by more than {tol:.3g} m after {horizon} of {n} samples: "
                          f"the recorded force does not carry the motion (a closed-loop record), and integrating "
                          f"it through the mass drifts. Fit the force balance instead: {call}", horizon, n, tol)
