"""The reversal table: the state of the oscillator at every velocity reversal."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
    """

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    E_p: np.ndarray
    E_d: np.ndarray
    E_0: float

    def __post_init__(self) -> None:
        n = len(self.t)
        for name in ("x", "F", "E_p", "E_d"):
            arr = getattr(self, name)
            if len(arr) != n:
                raise ValueError(f"ReversalTable.{name} has length {len(arr)}, expected {n}")

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
        idx = list(range(n)) if n <= max_rows else list(range(max_rows // 2)) + list(range(n - max_rows // 2, n))
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
