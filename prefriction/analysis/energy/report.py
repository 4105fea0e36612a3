"""The energy report of a rate-independent oscillator's trajectory (:class:`EnergyReport`), as
:func:`prefriction.energy.analyze_samples` and :func:`prefriction.energy.analyze_table` return it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from prefriction.analysis.energy.balance import BoundCheck


@dataclass(frozen=True, eq=False)
class EnergyReport:
    """Energy balance of a trajectory at its velocity reversals (paper section 2).

    Attributes
    ----------
    source : str
        ``"samples"`` or ``"reversal table"``.
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N], length n.
    direction : numpy.ndarray
        Sign of the velocity after each reversal (+1 or -1).
    E_p : numpy.ndarray
        Potential energy at each reversal [J]: the branch potential of the Dahl model,
        (3.9) for ``gamma = 1`` (samples), or the table's ``E_p``.
    E_d : numpy.ndarray
        Energy dissipated in the half-cycle that *ends* at reversal k [J], length n, as in
        :class:`prefriction.ReversalTable`: ``E_d[0]`` the first excursion from the initial
        state (``E_0 + W_u[0] - E_p[0]``, may include gross sliding), ``E_d[k] = E_p[k-1] +
        W_u[k] - E_p[k]`` (2.10) for ``k >= 1`` (samples; ``W_u`` the input's work, zero
        unforced) or the table's ``E_d``. Under forcing a reversal can occur before the force
        zero crossing; the Dahl branch potential then rises at the reversal and that ``E_d`` is
        negative (the Dahl model has no dissipation rate ``D >= 0``, paper after (2.3)).
    W_u : numpy.ndarray
        Work of the input force ``int u v dt`` in the half-cycle ending at reversal k [J],
        length n, ``W_u[0]`` the first excursion (the applied force: an input signal, a
        controller's force; zeros unforced).
    E_0 : float
        Energy of the initial state [J].
    series_partial, series_remainder : numpy.ndarray
        Truncated series (2.11) of ``E_d[1:]``, see :func:`series`.
    residual_2_10 : float
        The check of (2.10) against an independent computation, relative to ``max(E_p)``.
        Samples: ``max_k |E_d[k] - (E_p[k-1] + int F dx - E_p[k])|`` with ``int F dx`` the
        friction force's work over half-cycle k by quadrature of the samples ((2.5), (2.7);
        ``E_0`` less the kinetic energy for ``k = 0``): it fails when the input's work, the
        forces or the reversals are wrong (e.g. a controller's force left out). Table:
        ``max_k |E_p[k-1] + W_u[k] - E_d[k] - E_p[k]|``, the consistency of the table's columns
        only (a table computes ``E_d`` from ``E_p``; its independent check is ``E_p_check``).
    E_p_check : numpy.ndarray or None
        Independent estimate of ``E_p``: the peak kinetic energy in each complete unforced
        half-cycle (samples, length n - 1, paper's note after (3.9)), or the branch potential
        of the tabulated ``F_i`` (table, length n). ``None`` for forced samples.
    E_p_check_label : str
        What ``E_p_check`` is.
    E_p_check_max_rel_dev : float or None
        ``max |E_p_check - E_p| / max(E_p)`` over the entries compared.
    bound : BoundCheck
        The bound (2.12) and the initial energy.
    """

    source: str
    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    direction: np.ndarray
    E_p: np.ndarray
    E_d: np.ndarray
    W_u: np.ndarray
    E_0: float
    series_partial: np.ndarray
    series_remainder: np.ndarray
    residual_2_10: float
    E_p_check: Optional[np.ndarray]
    E_p_check_label: str
    E_p_check_max_rel_dev: Optional[float]
    bound: BoundCheck

    def __len__(self) -> int:
        return len(self.t)

    @property
    def E_p_decreasing(self) -> bool:
        """True if ``E_p`` strictly decreases from reversal to reversal (clockwise hysteresis)."""
        return bool(np.all(np.diff(self.E_p) < 0.0))

    def __repr__(self) -> str:
        last = f", E_p[-1]={self.E_p[-1]:.4g} J" if len(self) else ""
        return (f"EnergyReport({self.source}: {len(self)} reversals, E_0={self.E_0:.4g} J{last}, "
                f"residual (2.10)={self.residual_2_10:.2g}, bound {'holds' if self.bound.holds else 'VIOLATED'})")

    def summary(self) -> str:
        """The closing lines of :meth:`format`: balances, checks and the bound, without the table."""
        return self.format(max_rows=0).split("\n\n", 1)[1]

    def format(self, max_rows: int = 20) -> str:
        """Return the report as a readable text table and summary (at most ``max_rows`` rows)."""
        head = (
            f"{'i':>5} {'t [s]':>13} {'x [m]':>13} {'F [N]':>13} {'E_p [J]':>12} "
            f"{'E_d(i) [J]':>12} {'sum E_d(n>=i)':>13} {'E_p/bound':>10}"
        )
        n = len(self)
        first, last = (max_rows + 1) // 2, max_rows // 2  # max_rows rows: the first and last halves
        idx = list(range(n)) if n <= max_rows else list(range(first)) + list(range(n - last, n))
        lines = [f"Energy at reversals ({self.source}); E_d(i): half-cycle ending at reversal i", head, "-" * len(head)]
        prev = -1
        for i in idx:
            if i != prev + 1:
                lines.append(f"{'...':>5}")
            e_d = f"{self.E_d[i]:>12.5e}"
            lines.append(
                f"{i + 1:>5} {self.t[i]:>13.7g} {self.x[i]:>13.6g} {self.F[i]:>13.6g} {self.E_p[i]:>12.5e} "
                f"{e_d} {self.series_partial[i]:>13.5e} {self.E_p[i] / self.bound.bound:>10.6f}"
            )
            prev = i
        lines.append("")
        if n:
            lines.append(f"first excursion (initial state to reversal 1) dissipated {self.E_d[0]:.6e} J")
        if np.any(self.W_u != 0.0):
            lines.append(f"input work: {self.W_u[0]:.6e} J in the first excursion, "
                         f"{float(np.sum(self.W_u[1:])):.6e} J in the {self.W_u.size - 1} half-cycles")
        if n:
            lines.append(f"E_p strictly decreasing: {'yes' if self.E_p_decreasing else 'NO'}")
            check = "against int F dx of the samples" if self.source == "samples" else "of the table's columns"
            lines.append(f"(2.10) E_d(i) = E_p(i-1) + W_u(i) - E_p(i), {check}: max relative residual "
                         f"{self.residual_2_10:.3e}")
            lines.append(
                f"(2.11) E_p(i) = sum E_d(n>=i) + remainder; over {max(n - 1, 0)} half-cycles the remainder is E_p(last) = "
                f"{self.E_p[-1]:.4e} J = {self.E_p[-1] / self.E_p[0] if self.E_p[0] > 0 else 0.0:.3e} E_p(first)"
            )
        if self.E_p_check_max_rel_dev is not None:
            lines.append(f"E_p vs {self.E_p_check_label}: max relative deviation {self.E_p_check_max_rel_dev:.3e}")
        lines.append(self.bound.format())
        return "\n".join(lines)


def _rel_residual(values: np.ndarray, scale: float) -> float:
    """``max |values|`` relative to ``scale`` (absolute if ``scale`` is 0); 0 for no values."""
    if values.size == 0:
        return 0.0
    return float(np.max(np.abs(values)) / scale) if scale > 0 else float(np.max(np.abs(values)))
