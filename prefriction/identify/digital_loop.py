"""The known controller of a closed-loop record: :class:`DigitalLoop`.

Two forms of the force computed at sample ``k`` from the measured positions ``x``, the reference
``r`` and an optional recorded additive force ``e`` (pulses):

    PID on the measurement: u_k = Kp (r_k - x_k) + Ki dt sum_{j<=k} (r_j - x_j)
                                  - Kd sum_j c_j (x_{k-j} - x_{k-j-1}) / dt + e_k              (1)
    LTI on the error:       a_0 u_k = sum_j b_j eps_{k-j} - sum_{j>=1} a_j u_{k-j},  eps = r - x  (2)

(2) is any discrete transfer function ``b(z^-1) / a(z^-1)`` from the error [m] to the force [N]
(:meth:`DigitalLoop.from_controller`: a :class:`prefriction.controllers.PID` or a python-control
system, discretised with a zero-order hold). Either is saturated at ``limit`` and applied
``delay`` samples later, held over the sample interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_count, check_positive

__all__ = ["DigitalLoop"]


@dataclass(frozen=True)
class DigitalLoop:
    """A sampled position loop: PID on the measured position (1) or a linear law on the error (2).

    Parameters
    ----------
    dt : float
        Sample interval [s].
    Kp : float
        Position gain [N/m] of (1).
    Kd : float
        Velocity gain [N s/m] of (1).
    taps : tuple of float, default (1.0,)
        Velocity filter of (1): ``v_k = sum_j taps[j] (x_{k-j} - x_{k-j-1}) / dt`` (EMPS: ``(0.5, 0.5)``).
    delay : int, default 0
        Samples between computing a force and applying it (0 to 4).
    limit : float, default inf
        Saturation of the force [N].
    Ki : float, default 0.0
        Integral gain [N/(m s)] of (1) (the rectangle rule, the sample's own error included).
    num, den : tuple of float, default ()
        Coefficients ``b_0, b_1, ...`` and ``a_0, a_1, ...`` of (2) in powers of ``z^-1`` (up to
        9 each, ``a_0 != 0``); when given, (2) replaces (1).

    Raises
    ------
    ValueError
        For a value out of range (named).

    Examples
    --------
    >>> from prefriction.identify import DigitalLoop
    >>> loop = DigitalLoop.emps(kp=160.18, kv=243.45, gtau=35.15)
    >>> round(loop.Kp), round(loop.Kd, 1), loop.taps
    (1370703, 8557.3, (0.5, 0.5))
    """

    dt: float
    Kp: float = 0.0
    Kd: float = 0.0
    taps: tuple[float, ...] = (1.0,)
    delay: int = 0
    limit: float = math.inf
    num: tuple[float, ...] = ()
    den: tuple[float, ...] = ()
    Ki: float = 0.0

    def __post_init__(self) -> None:
        check_positive("dt", self.dt)
        for name in ("Kp", "Kd", "Ki"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0.0):
                raise ValueError(f"{name} must be finite and >= 0, got {getattr(self, name)!r}")
        if not 1 <= len(self.taps) <= 8 or not all(math.isfinite(c) for c in self.taps):
            raise ValueError(f"taps must hold 1 to 8 finite numbers, got {self.taps!r}")
        object.__setattr__(self, "taps", tuple(float(c) for c in self.taps))
        check_count("delay", self.delay, 0, 4, "samples")
        if not self.limit > 0.0:
            raise ValueError(f"limit must be > 0 (inf: no saturation), got {self.limit!r}")
        num, den = tuple(float(c) for c in self.num), tuple(float(c) for c in self.den)
        if bool(num) != bool(den) or len(num) > 9 or len(den) > 9 or not all(map(math.isfinite, num + den)) \
                or (den and den[0] == 0.0):
            raise ValueError(f"num and den must both hold 1 to 9 finite coefficients with den[0] != 0 (or both be "
                             f"empty), got num={self.num!r}, den={self.den!r}")
        object.__setattr__(self, "num", num)
        object.__setattr__(self, "den", den)

    @property
    def linear(self) -> bool:
        """True for the LTI law on the error (2)."""
        return bool(self.num)

    @classmethod
    def emps(cls, kp: float, kv: float, gtau: float, dt: float = 1e-3, volts: float = 10.0) -> "DigitalLoop":
        """The EMPS loop: ``vir = kv (kp (qg - qm) - v)`` [V], ``u = gtau vir`` [N], ``|vir| <= 10`` V, the
        velocity the mean of the last two backward differences (Janot et al. 2019; the Simulink
        model's ``filterq1 = [0.5 0.5]``)."""
        return cls(dt, gtau * kv * kp, gtau * kv, (0.5, 0.5), 0, gtau * volts)

    @classmethod
    def from_controller(cls, controller: Any, dt: float, *, delay: int = 0, limit: float | None = None
                        ) -> "DigitalLoop":
        """The law (2) of a linear controller from the error ``r - x`` [m] to the force [N].

        Parameters
        ----------
        controller : prefriction.controllers.PID or control.LTI
            A PID (discretised by its ``c2d``, zero-order hold) or a SISO python-control system,
            continuous (discretised with a zero-order hold) or discrete with sample time ``dt``.
        dt : float
            Sample interval [s].
        delay : int, default 0
            Samples between computing a force and applying it.
        limit : float, optional
            Saturation [N]; default the PID's ``u_max`` if it has one, else none.

        Raises
        ------
        TypeError
            If ``controller`` is neither.
        ValueError
            If it is not SISO or is discrete with another sample time.
        """
        import control

        from prefriction.controllers import PID

        dt = check_positive("dt", dt)
        if isinstance(controller, PID):
            if limit is None and controller.u_max is not None:
                limit = float(controller.u_max)
            sys = controller.c2d(dt)
        elif isinstance(controller, control.LTI):
            if controller.ninputs != 1 or controller.noutputs != 1:
                raise ValueError(f"controller must be SISO (error in, force out), got {controller.ninputs} inputs "
                                 f"and {controller.noutputs} outputs")
            if controller.dt in (0, None):
                sys = control.c2d(controller, dt, method="zoh")
            elif controller.dt is True or not math.isclose(float(controller.dt), dt, rel_tol=1e-9):
                raise ValueError(f"controller is discrete with sample time {controller.dt!r}, not dt = {dt!r}")
            else:
                sys = controller
        else:
            raise TypeError(f"controller must be a prefriction.controllers.PID or a python-control system, got "
                            f"{type(controller).__name__}")
        tf = control.tf(sys)
        b = np.atleast_1d(np.squeeze(np.asarray(tf.num[0][0], dtype=float)))
        a = np.atleast_1d(np.squeeze(np.asarray(tf.den[0][0], dtype=float)))
        if b.size > a.size:
            raise ValueError("controller must be proper (no more zeros than poles)")
        b = np.concatenate((np.zeros(a.size - b.size), b))   # powers of z^-1 after dividing by z^n
        return cls(dt, delay=delay, limit=math.inf if limit is None else float(limit), num=tuple(b), den=tuple(a))

    def force(self, r: np.ndarray, x: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """The loop's force [N] from recorded positions ``x`` (before any delay); before the record
        the positions are the first one, the errors and forces 0."""
        r, x = np.asarray(r, dtype=float), np.asarray(x, dtype=float)
        if self.linear:
            from scipy.signal import lfilter

            u = lfilter(self.num, self.den, r - x)
        else:
            n = len(self.taps)
            xp = np.concatenate((np.full(n, x[0]), x))
            v = sum(c * (xp[n - j:xp.size - j] - xp[n - j - 1:xp.size - j - 1])
                    for j, c in enumerate(self.taps)) / self.dt
            u = self.Kp * (r - x) + self.Ki * self.dt * np.cumsum(r - x) - self.Kd * v
        u = u + (0.0 if extra is None else extra)
        return np.clip(u, -self.limit, self.limit)
