"""Measured data for :func:`prefriction.identify.fit`: force-displacement and motion records.

Both classes check their arrays on construction: 1-D, equal lengths, finite, strictly
increasing times, enough samples, signals that move. Every message names the argument, what
was found and what is allowed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_nonnegative, check_positive

__all__ = ["ForceDisplacement", "ForceVelocity", "HOLDS", "Motion", "MIN_SAMPLES", "MAX_SAMPLES"]

MIN_SAMPLES = 8
"""Fewest samples a data set may hold."""
HOLDS = ("zoh", "linear")
"""How :class:`Motion` holds the applied force between samples."""
MAX_SAMPLES = 200_000
"""Most samples a data set may hold (the fit builds one expression per sample interval)."""


def _samples(name: str, value: Any, unit: str) -> np.ndarray:
    """``value`` as a read-only 1-D float array of finite numbers, or raise naming ``name``."""
    if isinstance(value, (str, bytes, dict)) or value is None:
        raise TypeError(f"{name} must be a 1-D array of real numbers [{unit}], got {value!r} of type "
                        f"{type(value).__name__}")
    try:
        raw = np.asarray(value)
    except Exception as exc:  # ragged sequences
        raise TypeError(f"{name} must be a 1-D array of real numbers [{unit}], got {value!r}") from exc
    if raw.dtype == bool or not (np.issubdtype(raw.dtype, np.integer) or np.issubdtype(raw.dtype, np.floating)):
        raise TypeError(f"{name} must be a 1-D array of real numbers [{unit}], got dtype {raw.dtype}")
    arr = np.array(raw, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array [{unit}], got shape {arr.shape}")
    if not MIN_SAMPLES <= arr.size <= MAX_SAMPLES:
        raise ValueError(f"{name} must hold {MIN_SAMPLES} to {MAX_SAMPLES} samples, got {arr.size} "
                         f"(allowed: {MIN_SAMPLES} <= len({name}) <= {MAX_SAMPLES})")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{i}] must be finite, got {float(arr[i])!r} (allowed: finite numbers [{unit}])")
    arr.flags.writeable = False
    return arr


def _times(t: Any) -> np.ndarray:
    arr = _samples("t", t, "s")
    dt = np.diff(arr)
    if np.any(dt <= 0.0):
        i = int(np.flatnonzero(dt <= 0.0)[0])
        what = "repeated" if dt[i] == 0.0 else "decreasing"
        raise ValueError(f"t must be strictly increasing, got {what} times t[{i}] = {arr[i]!r}, "
                         f"t[{i + 1}] = {arr[i + 1]!r} (sort the samples and drop duplicates)")
    return arr


def _same_length(t: np.ndarray, name: str, arr: np.ndarray) -> None:
    if arr.size != t.size:
        raise ValueError(f"{name} must have one sample per time, got len({name}) = {arr.size} and len(t) = {t.size}")


def _moving(name: str, arr: np.ndarray, unit: str) -> None:
    span = float(arr.max() - arr.min())
    if not span > 1e-12 * max(float(np.abs(arr).max()), 1e-300):
        raise ValueError(f"{name} must vary, got a constant signal {name} = {float(arr[0])!r} [{unit}] "
                         f"(a fit needs motion and a changing force)")


@dataclass(frozen=True, eq=False)
class ForceDisplacement:
    """Friction force measured along a prescribed displacement (no mass involved).

    The displacement is taken as linear between samples, so its direction ``s = sign(dx)`` is
    known on every interval; the model's force is integrated along it.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, 8 to 200 000 samples.
    x : array_like
        Displacement [m] at the sample times (the prescribed motion).
    F : array_like
        Measured friction force [N] at the sample times.
    x_noise : float, default 0.0
        Standard deviation [m] of the noise on the measured ``x`` (``>= 0``).
    quantum : float, default 0.0
        Encoder step [m] of ``x`` (``>= 0``; 0: not quantised).

    Attributes
    ----------
    path : numpy.ndarray
        The displacement [m] the model is driven along: ``x`` itself when ``x_noise`` and
        ``quantum`` are 0, else the estimated true path
        (:func:`prefriction.identify.positions.denoise_path`: a local cubic fit with the window
        of least estimated risk, monotone between the reversals it shows), so that the noise does
        not add a spurious reversal at every sample (``docs/identify.md#positions``).
    path_window : int
        The smoothing window of :attr:`path` [samples] (1: ``path`` is ``x``).

    Raises
    ------
    TypeError
        If an argument is not an array of real numbers.
    ValueError
        If an array is not 1-D, holds NaN or inf, the lengths differ, there are too few or too
        many samples, the times are not strictly increasing (unsorted or repeated), ``x`` or
        ``F`` is constant, or ``x_noise`` or ``quantum`` is negative or not finite. The message
        names the argument.
    """

    t: Any
    x: Any
    F: Any
    x_noise: Any = 0.0
    quantum: Any = 0.0

    def __post_init__(self) -> None:
        t = _times(self.t)
        x = _samples("x", self.x, "m")
        F = _samples("F", self.F, "N")
        _same_length(t, "x", x)
        _same_length(t, "F", F)
        _moving("x", x, "m")
        _moving("F", F, "N")
        x_noise = check_nonnegative("x_noise", self.x_noise)
        quantum = check_nonnegative("quantum", self.quantum)
        path, window = x, 1
        if x_noise > 0.0 or quantum > 0.0:
            from prefriction.identify.positions import denoise_path  # scipy.signal only when needed

            path, window = denoise_path(x, x_noise, quantum)
        path.flags.writeable = False
        for name, val in (("t", t), ("x", x), ("F", F), ("x_noise", x_noise), ("quantum", quantum), ("path", path),
                          ("path_window", window)):
            object.__setattr__(self, name, val)

    @property
    def noisy_positions(self) -> bool:
        """True if ``x_noise`` or ``quantum`` was declared (the fit follows :attr:`path`)."""
        return bool(self.x_noise or self.quantum)

    def __len__(self) -> int:
        return int(self.t.size)

    def __repr__(self) -> str:
        noise = f", x_noise {self.x_noise:.3g} m, quantum {self.quantum:.3g} m" if self.noisy_positions else ""
        return (f"ForceDisplacement({len(self)} samples, t in [{self.t[0]:.4g}, {self.t[-1]:.4g}] s, "
                f"x in [{self.x.min():.4g}, {self.x.max():.4g}] m, F in [{self.F.min():.4g}, {self.F.max():.4g}] N"
                f"{noise})")


@dataclass(frozen=True, eq=False)
class Motion:
    """Positions of a mass moved by friction and a known applied force: ``m x'' + F = u``.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, 8 to 200 000 samples.
    x : array_like
        Measured position [m] at the sample times.
    u : float or array_like, default 0.0
        Applied force [N]: a constant (``0`` is a free decay) or one sample per time, held
        between the samples as ``hold`` says.
    mass : float or None, default None
        Moving mass [kg], ``0 < mass < inf``, if known; ``None`` fits it (give ``mass0`` to
        :func:`prefriction.identify.fit`). A free decay cannot tell the mass from the force
        scale: with ``u = 0``, ``m``, ``sigma`` and ``Fc`` scaled together give the same motion.
    hold : {"zoh", "linear"}, default "zoh"
        How ``u`` acts between samples ``t[k]`` and ``t[k+1]``: ``"zoh"`` holds ``u[k]`` (what a
        digital loop applies: its output changes at the samples and is held in between);
        ``"linear"`` interpolates linearly between ``u[k]`` and ``u[k+1]``.
    x_noise : float, default 0.0
        Standard deviation [m] of the noise on the measured ``x`` (``>= 0``), if known.
    quantum : float, default 0.0
        Encoder step [m] of ``x`` (``>= 0``), if known. A Motion fit is an output-error fit (the
        residual is the measured position minus the model's), consistent under position noise
        and rounding without them; declared, they let the residual diagnostics compare the
        residual level with the measurement's (``docs/identify.md#diagnostics``).

    Raises
    ------
    TypeError
        If an argument is not a real number or an array of them.
    ValueError
        As :class:`ForceDisplacement` for ``t``, ``x`` and sampled ``u``; also if ``mass`` is
        not finite and positive, or ``x_noise`` or ``quantum`` negative or not finite.
    """

    t: Any
    x: Any
    u: Any = 0.0
    mass: Any = None
    hold: str = "zoh"
    x_noise: Any = 0.0
    quantum: Any = 0.0

    def __post_init__(self) -> None:
        if self.hold not in HOLDS:
            raise ValueError(f"hold must be one of {HOLDS}, got {self.hold!r} ('zoh': u[k] held over each "
                             f"sample interval; 'linear': u linear between the samples)")
        t = _times(self.t)
        x = _samples("x", self.x, "m")
        _same_length(t, "x", x)
        _moving("x", x, "m")
        if np.ndim(self.u) == 0 and not isinstance(self.u, (str, bytes)) and self.u is not None:
            if isinstance(self.u, (bool, np.bool_)) or not isinstance(self.u, (int, float, np.integer, np.floating)):
                raise TypeError(f"u must be a real number [N] or one sample per time, got {self.u!r} of type "
                                f"{type(self.u).__name__}")
            u_val = float(self.u)
            if not np.isfinite(u_val):
                raise ValueError(f"u must be a finite number [N] or one sample per time, got {self.u!r}")
            u = np.full(t.size, u_val)
            u.flags.writeable = False
        else:
            u = _samples("u", self.u, "N")
            _same_length(t, "u", u)
        mass = None if self.mass is None else check_positive("mass", self.mass)
        x_noise = check_nonnegative("x_noise", self.x_noise)
        quantum = check_nonnegative("quantum", self.quantum)
        for name, val in (("t", t), ("x", x), ("u", u), ("mass", mass), ("x_noise", x_noise), ("quantum", quantum)):
            object.__setattr__(self, name, val)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def free_decay(self) -> bool:
        """True if no force is applied (``u = 0`` throughout)."""
        return not np.any(self.u)

    def __repr__(self) -> str:
        m = "free" if self.mass is None else f"{self.mass:.4g} kg"
        u = "u = 0 (free decay)" if self.free_decay else f"u in [{self.u.min():.4g}, {self.u.max():.4g}] N"
        return (f"Motion({len(self)} samples, t in [{self.t[0]:.4g}, {self.t[-1]:.4g}] s, "
                f"x in [{self.x.min():.4g}, {self.x.max():.4g}] m, {u}, mass {m}, hold {self.hold!r})")


@dataclass(frozen=True, eq=False)
class ForceVelocity:
    """Friction force measured in steady sliding at a set of velocities (a Stribeck curve).

    The data of a static friction map (:class:`prefriction.identify.StaticFriction`): each
    sample is one constant-velocity run, its velocity ``v`` and its friction force ``F``.

    Parameters
    ----------
    v : array_like
        Sliding velocities [m/s], 8 to 200 000 samples, any order, both signs allowed.
    F : array_like
        Measured friction force [N] at each velocity.

    Raises
    ------
    TypeError
        If an argument is not an array of real numbers.
    ValueError
        If an array is not 1-D, holds NaN or inf, the lengths differ, there are too few or too
        many samples, or ``v`` or ``F`` is constant. The message names the argument.
    """

    v: Any
    F: Any

    def __post_init__(self) -> None:
        v = _samples("v", self.v, "m/s")
        F = _samples("F", self.F, "N")
        if F.size != v.size:
            raise ValueError(f"F must have one sample per velocity, got len(F) = {F.size} and len(v) = {v.size}")
        _moving("v", v, "m/s")
        _moving("F", F, "N")
        object.__setattr__(self, "v", v)
        object.__setattr__(self, "F", F)

    def __len__(self) -> int:
        return int(self.v.size)

    def __repr__(self) -> str:
        return (f"ForceVelocity({len(self)} samples, v in [{self.v.min():.4g}, {self.v.max():.4g}] m/s, "
                f"F in [{self.F.min():.4g}, {self.F.max():.4g}] N)")
