"""The LuGre friction observer of Canudas de Wit, Olsson, Astrom and Lischinsky (1995), section V."""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import control
import numpy as np

from prefriction._validation import check_positive
from prefriction.models import LuGre

from ._base import Compensator

__all__ = ["LuGreObserver"]


@dataclass(frozen=True)
class _Structure:
    n_state: int = 3
    n_param: int = 8

    def function(self) -> ca.Function:
        c, meas, ref, p = ca.SX.sym("c", 3), ca.SX.sym("meas", 2), ca.SX.sym("ref", 4), ca.SX.sym("par", 8)
        z, y_prev, e_prev = c[0], c[1], c[2]
        sigma0, sigma1, sigma2, Fc, Fs, vs, k, Ts = (p[i] for i in range(8))
        y = meas[0]
        e = y - ref[0]  # the paper's e = x - x_d (measured)
        v = (y - y_prev) / Ts  # the velocity of the last period, from the encoder
        g = Fc + (Fs - Fc) * ca.exp(-(v / vs) ** 2)
        a = sigma0 * ca.fabs(v) / g
        # z' = v - a z - k e over the period, v, a and the mean error held: exact solution
        phi = ca.if_else(a * Ts > 1e-9, -ca.expm1(-a * Ts) / ca.fmax(a, 1e-300), Ts * (1.0 - 0.5 * a * Ts))
        b = v - k * 0.5 * (e + e_prev)
        z_next = z * ca.exp(-a * Ts) + b * phi
        dz = v - a * z_next - k * e
        force = sigma0 * z_next + sigma1 * dz + sigma2 * v
        return ca.Function("lugre_observer", [c, meas, ref, p], [ca.vertcat(z_next, y, e), force])


@dataclass(frozen=True)
class LuGreObserver(Compensator):
    """The observer-based friction compensation of Canudas de Wit et al. (1995), section V.

    C. Canudas de Wit, H. Olsson, K. J. Astrom and P. Lischinsky, "A new model for control of
    systems with friction", IEEE Transactions on Automatic Control 40(3), 419-425, 1995. With the
    LuGre model (1)-(3) of the stage's friction, the observer of the bristle state and the
    friction estimate are

        z^' = v - sigma0 |v| z^ / g(v) - k e,        F^ = sigma0 z^ + sigma1 z^' + sigma2 v,

    with ``e = x - x_d`` the position error and ``k`` the observer gain; ``F^`` is added to the
    controller's force. The estimation error ``z~ = z - z^`` obeys ``z~' = -sigma0 |v| z~ / g(v)
    + k e``: the map from ``e`` to ``z~`` is passive (storage ``z~^2 / (2k)``), so the loop is
    stable when ``k > 0`` and the linear part from the friction error to ``-e``,

        H(s) = (sigma1 s + sigma0) / (m s^2 + C(s)),

    is strictly positive real (``C`` the controller, :meth:`gain_condition`; for an unfiltered
    PID ``Re H(jw)`` has the sign of ``sigma0 kp - sigma1 ki + (sigma1 kd - m sigma0) w^2``, so
    the condition is ``sigma0 kp >= sigma1 ki`` and ``sigma1 kd >= m sigma0``; a derivative
    filter ``tau`` can break it at high frequency). ``z~`` then goes
    to zero while the stage moves (``|v| > 0``); at rest it is constant.

    In the sampled loop the velocity is the encoder difference of the last period,
    ``v = (y_k - y_{k-1}) / Ts``, and ``z^`` is advanced over the period by the exact solution
    of the linear equation above with ``v`` and the mean error held; the estimate ``F^_k``
    (with ``z^'`` at ``t_k``) is held over the next period. It uses ``z^`` only (not the plant's
    ``z``: the mistake of auralius/LuGre pull request #3).

    Parameters
    ----------
    model : prefriction.LuGre
        The model of the stage's friction (SI).
    gain : float
        Observer gain ``k`` [1/s], ``0 < k < inf`` (``z`` in m, ``e`` in m).

    Examples
    --------
    >>> import prefriction as pf
    >>> from prefriction import controllers
    >>> obs = controllers.LuGreObserver(pf.LuGre(sigma0=1e6, sigma1=100.0, sigma2=0.0, Fc=1.0, Fs=1.3,
    ...                                          vs=1e-4), gain=1e3)
    >>> obs.gain_condition(controllers.PID(kp=2e6, ki=1e8, kd=2e4, tau=1e-7), mass=1.0)[0]
    True
    >>> obs.gain_condition(controllers.PID(kp=2e6, ki=1e8, kd=2e3, tau=1e-7), mass=1.0)[0]  # sigma1 kd < m sigma0
    False
    """

    model: LuGre
    gain: float

    def __post_init__(self) -> None:
        if not isinstance(self.model, LuGre):
            raise TypeError(f"model must be a prefriction.LuGre model, got {self.model!r} of type "
                            f"{type(self.model).__name__}")
        object.__setattr__(self, "gain", check_positive("gain", self.gain))

    def structure(self) -> _Structure:
        """The compiled structure (one for every LuGre observer)."""
        return _Structure()

    def numbers(self, mass: float, Ts: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
        """``params = [sigma0, sigma1, sigma2, Fc, Fs, vs, k, Ts]``; state ``[z^, y_{k-1}, e_{k-1}]``
        starting at ``[0, x0, 0]``."""
        m = self.model
        return (np.array([m.sigma0, m.sigma1, m.sigma2, m.Fc, m.Fs, m.vs, self.gain, Ts]),
                np.array([0.0, x0, 0.0]))

    def gain_condition(self, controller: "control.LTI | object", mass: float,
                       n_freq: int = 20_000) -> tuple[bool, float]:
        """Check ``k > 0`` and that ``H(s) = (sigma1 s + sigma0) / (m s^2 + C(s))`` is strictly
        positive real (section V's condition for the observer-based loop).

        Parameters
        ----------
        controller : controllers.PID or control.TransferFunction
            The continuous controller ``C(s)`` (error to force).
        mass : float
            Moving mass [kg].
        n_freq : int, default 20000
            Frequencies (log-spaced, 1e-3 to 1e3 times ``sqrt(sigma0 / m)``) on which
            ``Re H(jw) > 0`` is checked.

        Returns
        -------
        (bool, float)
            Whether the condition holds (``k > 0``, ``H`` stable, of relative degree one with a
            positive high-frequency gain, ``Re H(jw) > 0`` on the grid), and ``min Re H(jw)``
            on the grid [m/N]. With ``sigma1 = 0`` ``H`` has relative degree two and is never
            strictly positive real.
        """
        mass = check_positive("mass", mass)
        C = controller.tf() if hasattr(controller, "tf") else control.tf(controller)
        num_c, den_c = np.atleast_1d(np.squeeze(C.num[0][0])), np.atleast_1d(np.squeeze(C.den[0][0]))
        m = self.model
        num = np.polymul([m.sigma1, m.sigma0], den_c)
        den = np.polyadd(np.polymul([mass, 0.0, 0.0], den_c), num_c)
        stable = bool(np.all(np.real(np.roots(den)) < 0.0))
        w = math.sqrt(m.sigma0 / mass) * np.logspace(-3, 3, n_freq)
        H = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
        lead = num[np.flatnonzero(num)[0]] / den[0] if np.any(num) else 0.0
        degree_one = len(np.trim_zeros(den, "f")) - len(np.trim_zeros(num, "f")) == 1 and lead > 0.0
        low = float(np.min(H.real))
        return bool(self.gain > 0.0 and stable and low > 0.0 and degree_one), low

    def require_gain_condition(self, controller: "control.LTI | object", mass: float) -> None:
        """Raise ``ValueError`` saying why, if :meth:`gain_condition` does not hold for ``controller``.

        The message names what fails (for a :class:`controllers.PID`: ``sigma1 kd >= m sigma0``,
        ``sigma0 kp >= sigma1 ki``, and the derivative filter, with which ``Re H(jw) < 0`` at high
        frequency for any ``tau > 0``) and the alternatives: :class:`controllers.FrictionObserver`,
        whose error dynamics do not involve the controller, or :class:`controllers.Feedforward`.

        Parameters
        ----------
        controller : controllers.PID or control.TransferFunction
            The continuous controller ``C(s)``.
        mass : float
            Moving mass [kg].

        Raises
        ------
        ValueError
            If the condition does not hold.
        """
        ok, low = self.gain_condition(controller, mass)
        if ok:
            return
        m = self.model
        why = [f"H(s) = (sigma1 s + sigma0) / (m s^2 + C(s)) is not strictly positive real (min Re H(jw) = "
               f"{low:.3g} m/N)"]
        kd, kp, ki, tau = (getattr(controller, n, None) for n in ("kd", "kp", "ki", "tau"))
        if kd is not None:
            if m.sigma1 * kd < mass * m.sigma0:
                why.append(f"kd = {kd:.4g} N s/m < m sigma0 / sigma1 = "
                           f"{mass * m.sigma0 / m.sigma1 if m.sigma1 > 0 else math.inf:.4g} N s/m")
            if m.sigma0 * kp < m.sigma1 * ki:
                why.append(f"sigma0 kp = {m.sigma0 * kp:.4g} < sigma1 ki = {m.sigma1 * ki:.4g}")
            if kd > 0.0 and tau is not None:
                why.append(f"the derivative filter tau = {tau:.3g} s makes Re H(jw) < 0 at high frequency (as any "
                           f"filter does)")
        raise ValueError(f"the LuGre observer's gain condition (Canudas de Wit et al. 1995, section V) fails for "
                         f"this controller with mass = {mass:g} kg: {'; '.join(why)}. Its stability proof does not "
                         f"cover this loop (simulate_loop still runs it; the condition is sufficient, not necessary). "
                         f"Alternatives: controllers.FrictionObserver(model, pole), whose error dynamics "
                         f"e' = M(t) e do not involve the controller, or controllers.Feedforward(model) "
                         f"(docs/compensation.md#lugre-observer)")

    def __str__(self) -> str:
        return f"LuGreObserver(k={self.gain:.4g})"
