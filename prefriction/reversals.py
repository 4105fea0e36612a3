"""The reversal table: the state of the oscillator at every velocity reversal."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_nonnegative


@dataclass(frozen=True, eq=False)
class ReversalTable:
    """States at the velocity reversals ``x'(t_i) = 0`` of a trajectory, in SI units.

    Attributes
    ----------
    t : numpy.ndarray
        Reversal times ``t_i`` [s], strictly increasing.
    x : numpy.ndarray
        Positions ``x_i`` [m].
    F : numpy.ndarray
        Friction forces ``F_i`` [N] at the reversals.
    E_p : numpy.ndarray
        Potential energy at each reversal [J]: the energy the new branch returns as kinetic
        energy until its force zero crossing, (3.9) for the Dahl model with gamma = 1.
    E_d : numpy.ndarray
        Energy dissipated [J] in the half-cycle that ends at each reversal:
        ``E_d[0] = E_0 - E_p[0]`` with ``E_0`` the energy of the initial state, and
        ``E_d[k] = E_p[k-1] - E_p[k]`` for ``k >= 1``, which is (2.10).
    E_0 : float
        Energy of the initial state [J]: kinetic energy plus the potential energy of the
        initial force on the initial branch.

    Raises
    ------
    TypeError
        If a column is not an array of real numbers or ``E_0`` not a real number.
    ValueError
        If a column is not 1-D or its length differs from that of ``t``, ``t`` is not finite
        and strictly increasing, ``x`` or ``F`` has a non-finite entry, ``E_p`` or ``E_d`` an
        infinite one (NaN marks them undefined, as for rate-dependent models), or ``E_0`` is
        not finite and ``>= 0``.
    """

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    E_p: np.ndarray
    E_d: np.ndarray
    E_0: float

    def __post_init__(self) -> None:
        t = _column("t", self.t, finite=True)
        if np.any(np.diff(t) <= 0.0):
            i = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
            raise ValueError(f"table.t must be strictly increasing, got t[{i + 1}] = {float(t[i + 1])!r} "
                             f"<= t[{i}] = {float(t[i])!r}")
        object.__setattr__(self, "t", t)
        for name, finite in (("x", True), ("F", True), ("E_p", False), ("E_d", False)):
            arr = _column(name, getattr(self, name), finite=finite)
            if arr.size != t.size:
                raise ValueError(f"table.{name} has length {arr.size} and table.t has length {t.size}: "
                                 "every column needs one entry per reversal")
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "E_0", check_nonnegative("E_0", self.E_0))

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        if not len(self):
            return f"ReversalTable(0 reversals, E_0 = {self.E_0:.6g} J)"
        return (f"ReversalTable({len(self)} reversals in [{self.t[0]:.6g}, {self.t[-1]:.6g}] s, "
                f"last x = {self.x[-1]:.6g} m, F = {self.F[-1]:.6g} N, E_0 = {self.E_0:.6g} J)")

    def summary(self) -> str:
        """A few lines: the number of reversals, their time span, the first and the last reversal,
        the initial energy, the last stored energy and the energy dissipated in all half-cycles.

        Returns
        -------
        str
            Text without arrays, e.g. ``"50 reversals in [0.0314, 1.59] s"`` and three more lines.
        """
        n = len(self)
        if not n:
            return f"0 reversals; initial energy E_0 = {self.E_0:.6g} J"
        stored = not np.all(np.isnan(self.E_p))  # NaN: no stored branch energy (rate-dependent model)
        lines = [f"{n} reversals in [{self.t[0]:.9g}, {self.t[-1]:.9g}] s"]
        for name, i in (("first", 0), ("last", n - 1)):
            lines.append(f"{name}: t = {self.t[i]:.9g} s, x = {self.x[i]:.9g} m, F = {self.F[i]:.9g} N"
                         + (f", E_p = {self.E_p[i]:.6g} J" if stored else ""))
        lines.append(f"energy: E_0 = {self.E_0:.6g} J, " + (
            f"dissipated over the {n} half-cycles {float(np.sum(self.E_d)):.6g} J" if stored
            else "E_p and E_d not defined (no stored branch energy)"))
        return "\n".join(lines)

    def format(self, max_rows: int = 20) -> str:
        """Return the table as aligned text, at most ``max_rows`` rows (first and last half)."""
        head = f"{'i':>5} {'t [s]':>14} {'x [m]':>14} {'F [N]':>14} {'E_p [J]':>12} {'E_d [J]':>12}"
        n = len(self)
        first, last = (max_rows + 1) // 2, max_rows // 2  # max_rows rows: the first and last halves
        idx = list(range(n)) if n <= max_rows else list(range(first)) + list(range(n - last, n))
        lines = [head, "-" * len(head)]
        prev = -1
        for i in idx:
            if i != prev + 1:
                lines.append(f"{'...':>5}")
            lines.append(
                f"{i + 1:>5} {self.t[i]:>14.8g} {self.x[i]:>14.7g} {self.F[i]:>14.7g} "
                f"{self.E_p[i]:>12.5e} {self.E_d[i]:>12.5e}"
            )
            prev = i
        return "\n".join(lines)


def _column(name: str, values: Any, *, finite: bool) -> np.ndarray:
    """``values`` as a 1-D float array; ``TypeError`` unless real numbers, ``ValueError`` for a
    non-finite entry (``finite``) or an infinite one (NaN allowed: the quantity is not defined)."""
    allowed = "a 1-D array of real numbers"
    if isinstance(values, np.ndarray) and values.dtype.kind == "f" and values.ndim == 1:
        bad = ~np.isfinite(values) if finite else np.isinf(values)
        if not bad.any():  # the simulator's and the exact reference's columns: no copy, no message
            return values.astype(float)
    text = _short(values)
    if values is None or isinstance(values, (str, bytes, dict, set)):
        raise TypeError(f"table.{name} must be {allowed}, got {text} of type {type(values).__name__}")
    try:
        raw = np.asarray(values)
    except (ValueError, TypeError):  # ragged nesting
        raise TypeError(f"table.{name} must be {allowed}, got {text} (ragged or mixed nesting)") from None
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"table.{name} must be {allowed}, got {text} (an array of dtype {raw.dtype})")
    if raw.ndim != 1:
        raise ValueError(f"table.{name} must be {allowed}, got an array of shape {raw.shape}")
    arr = raw.astype(float)
    bad = ~np.isfinite(arr) if finite else np.isinf(arr)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        kind = "finite" if finite else "finite or NaN (not defined)"
        raise ValueError(f"table.{name} must be {kind}, got a non-finite entry at index {i} (reversal {i + 1}): "
                         f"{float(arr[i])!r}")
    return arr


def _short(values: Any) -> str:
    """``repr(values)`` cut to 80 characters (formatted only when a message needs it)."""
    text = repr(values)
    return text if len(text) <= 80 else text[:77] + "..."
