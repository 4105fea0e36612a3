"""Linear output feedback around the pre-sliding oscillator, for :func:`prefriction.simulate`.

A :class:`LinearFeedback` closes the loop ``m x'' = u - F`` with a linear controller in
state-space form, all in SI units:

- error ``e(t) = r(t) - x(t)`` [m], with ``r`` the position reference;
- force ``u = C xc + D e`` [N] (plus ``system.u(t)`` if the oscillator has an input force too);
- continuous controller (``Ts is None``): ``xc' = A xc + B e``, integrated together with the
  plant in the same CasADi right-hand side;
- optional force limit ``u_max`` with back-calculation anti-windup (continuous controllers):
  the output ``w = C xc + D e`` is clipped, ``u = clip(w, -u_max, u_max)``, and
  ``xc' = A xc + B e + k_aw (u - w)`` (Astrom and Hagglund);
- sampled-data controller (``Ts > 0``): ``xc[k+1] = A xc[k] + B e[k]`` with ``e[k] = e(k Ts)``,
  the force ``u[k] = C xc[k] + D e[k]`` held constant (zero-order hold) over
  ``[k Ts, (k+1) Ts)``; reversals inside a sample interval are located as in the open loop.

``simulate(system, v0, feedback=LinearFeedback(...), t_end=..., ...)`` returns, besides the
reversal table, samples ``t, x, v, F, u, xc`` at the requested sample times (``dense=``) and, for
a sampled controller, always at the sample instants ``k Ts``.

Example: proportional-derivative control is ``A = [[-1/tau]], B = [[1/tau]], C = [[-kd/tau]],
D = [[kp + kd/tau]]`` (a filtered derivative); a pure gain ``kp`` is ``A, B, C`` empty
(shapes (0, 0), (0, 1), (1, 0)) and ``D = [[kp]]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Union

import numpy as np

from prefriction._validation import check_positive, check_real_array

Reference = Union[float, Callable[[Any], Any], tuple]

MAX_SAMPLES = 10_000_000
"""Largest number of sample instants of a sampled loop: each costs microseconds (a minute at the
limit); more would appear to hang. Each also keeps its inputs and records (about 60 numbers for
a PID loop of a Dahl stage), so the memory limit (:data:`prefriction._memory.MAX_BYTES`) may
refuse a run below this count. Split a longer run, or sample less often."""


def sample_count(t_end: float, Ts: float, periods: float) -> int:
    """Number of sample instants ``min(k Ts, t_end)``, ``k = 0, 1, ...`` up to the first one at
    ``t_end`` (within a relative 1e-12), in any one time unit for ``t_end`` and ``Ts``.

    Parameters
    ----------
    t_end, Ts : float
        End time and sample period (same unit).
    periods : float
        ``t_end / Ts`` in SI, for the message.

    Raises
    ------
    ValueError
        If there would be more than :data:`MAX_SAMPLES` instants.
    """
    if not periods < MAX_SAMPLES - 1:
        raise ValueError(
            f"t_end / Ts = {periods:.6g} sample periods: at most {MAX_SAMPLES - 1} are allowed (MAX_SAMPLES = "
            f"{MAX_SAMPLES} sample instants; more would exhaust the memory or run for hours); increase Ts or "
            "split the run"
        )
    stop = t_end * (1 - 1e-12)
    k = max(int(math.ceil(stop / Ts)), 0)
    while k > 0 and (k - 1) * Ts >= stop:
        k -= 1
    while k * Ts < stop:
        k += 1
    return k + 1


def _as_matrix(name: str, value: Any, shape: tuple[int, int], why: str = "") -> np.ndarray:
    """Return ``value`` as a read-only float matrix of ``shape`` (an empty value: zeros of
    ``shape``); ``TypeError``/``ValueError`` naming ``name`` otherwise (``why`` explains the shape)."""
    arr = np.array(check_real_array(name, value), ndmin=2)
    if arr.size == 0:
        arr = np.zeros(shape)
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}{why}, got an array of shape {arr.shape}")
    arr.setflags(write=False)
    return arr


def _state_count(A: Any) -> int:
    """Number of controller states: the rows of ``A`` (0 if ``A`` is empty)."""
    arr = check_real_array("A", A)
    return 0 if arr.size == 0 else np.array(arr, ndmin=2).shape[0]


@dataclass(frozen=True, eq=False)
class LinearFeedback:
    """Linear position controller ``u = C xc + D e``, ``e = r - x`` (SI units), continuous or sampled.

    Parameters
    ----------
    A, B, C, D : array_like
        Controller matrices, shapes ``(n, n)``, ``(n, 1)``, ``(1, n)``, ``(1, 1)`` with ``n >= 0``
        controller states. Units: ``e`` in m, ``u`` in N, ``xc`` in any unit the matrices agree on.
        Continuous time (``Ts is None``): ``xc' = A xc + B e``. Sampled (``Ts > 0``):
        ``xc[k+1] = A xc[k] + B e[k]``.
    Ts : float or None, default None
        Sample period [s] of a discrete-time controller with zero-order hold on ``u``;
        ``None`` for a continuous-time controller.
    reference : float, Signal, callable or (t, r) samples, default 0.0
        Position reference ``r(t)`` [m]: a constant, a :class:`prefriction.signals.Signal`
        (compiled once per kind, numbers at run time), a callable of time ``t`` [s] that accepts
        a CasADi symbol (compiled once per function), or samples ``(t, r)`` interpolated
        linearly and held constant outside the sample range.
    xc0 : array_like or None, default None
        Initial controller state, shape ``(n,)``; zeros if ``None``.
    u_max : float or None, default None
        Force limit [N], ``0 < u_max < inf``, of a continuous controller: the plant receives
        ``clip(C xc + D e, -u_max, u_max)``. ``None``: no limit (the linear law).
    k_aw : array_like or None, default None
        Back-calculation gains [1/(N s)] per controller state, shape ``(n,)``, finite: ``xc' = A xc
        + B e + k_aw (u - w)`` with the clipped force ``u`` and the unclipped output ``w``. Zeros
        if ``None``; only with ``u_max``.

    Raises
    ------
    TypeError
        If a matrix, ``xc0`` or ``k_aw`` is not real numbers (``None``, strings, booleans,
        complex, ragged nesting), ``Ts`` or ``u_max`` is not a real number, or ``reference`` is
        of no accepted kind.
    ValueError
        If a matrix or ``xc0`` has the wrong shape or a non-finite entry, ``Ts`` is not
        positive, the reference samples are malformed, ``u_max`` is not finite and positive,
        ``k_aw`` has the wrong length or a non-finite entry, ``u_max`` or ``k_aw`` is given with
        a sampled controller (``Ts``; :func:`controllers.simulate_loop` limits sampled loops),
        or ``k_aw`` without ``u_max``.
    """

    A: Any = field(default_factory=lambda: np.zeros((0, 0)))
    B: Any = field(default_factory=lambda: np.zeros((0, 1)))
    C: Any = field(default_factory=lambda: np.zeros((1, 0)))
    D: Any = 0.0
    Ts: Optional[float] = None
    reference: Reference = 0.0
    xc0: Any = None
    u_max: Optional[float] = None
    k_aw: Any = None

    def __post_init__(self) -> None:
        n = _state_count(self.A)
        why = f" (A is {n} x {n}: n = {n} controller states)"
        object.__setattr__(self, "A", _as_matrix("A", self.A, (n, n)))
        object.__setattr__(self, "B", _as_matrix("B", self.B, (n, 1), why))
        object.__setattr__(self, "C", _as_matrix("C", self.C, (1, n), why))
        object.__setattr__(self, "D", _as_matrix("D", self.D, (1, 1)))
        if self.Ts is not None:
            object.__setattr__(self, "Ts", check_positive("Ts", self.Ts))
        from prefriction.signals import as_signal

        object.__setattr__(self, "reference", as_signal(self.reference, "reference", "m"))
        xc0 = np.zeros(n) if self.xc0 is None else check_real_array("xc0", self.xc0).reshape(-1)
        if xc0.shape != (n,):
            got = repr(xc0.tolist()) if xc0.size <= 8 else f"{xc0.size} entries"
            raise ValueError(f"xc0 must be a vector of length n = {n} (the controller states of A), got {got}")
        xc0.setflags(write=False)
        object.__setattr__(self, "xc0", xc0)
        self._check_limit(n)

    def _check_limit(self, n: int) -> None:
        """Validate ``u_max`` and ``k_aw`` (continuous controllers only) and store them."""
        if self.Ts is not None and (self.u_max is not None or self.k_aw is not None):
            raise ValueError(f"u_max and k_aw are for continuous controllers (Ts=None), got Ts={self.Ts!r}: "
                            "run a force-limited sampled loop with controllers.simulate_loop")
        if self.u_max is not None:
            object.__setattr__(self, "u_max", check_positive("u_max", self.u_max))
        elif self.k_aw is not None:
            raise ValueError(f"k_aw={self.k_aw!r} needs a force limit u_max (back-calculation acts on the clipped force)")
        k = np.zeros(n) if self.k_aw is None else check_real_array("k_aw", self.k_aw, "1/(N s)").reshape(-1)
        if k.shape != (n,):
            raise ValueError(f"k_aw must be a vector of length n = {n} (the controller states of A), got {self.k_aw!r}")
        k.setflags(write=False)
        object.__setattr__(self, "k_aw", k)

    @property
    def n_states(self) -> int:
        """Number of controller states ``n``."""
        return self.A.shape[0]

    def output(self, xc: Any, e: Any) -> Any:
        """Unclipped controller output ``w = C xc + D e`` [N].

        Parameters
        ----------
        xc : array_like
            Controller state, shape ``(n,)``, or states ``(k, n)`` at ``k`` times.
        e : float or array_like
            Error ``r - x`` [m], scalar or shape ``(k,)``.
        """
        xc = np.asarray(xc, dtype=float)
        return (xc @ self.C[0] if self.n_states else 0.0) + self.D[0, 0] * np.asarray(e, dtype=float)

    def force(self, xc: Any, e: Any) -> Any:
        """Controller force [N] ``clip(C xc + D e, -u_max, u_max)`` (no clip without ``u_max``);
        arguments as for :meth:`output`."""
        w = self.output(xc, e)
        return w if self.u_max is None else np.clip(w, -self.u_max, self.u_max)

    @property
    def sampled(self) -> bool:
        """True for a sampled-data (discrete-time, zero-order hold) controller."""
        return self.Ts is not None
