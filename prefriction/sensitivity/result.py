"""The result of :func:`prefriction.sensitivity.sensitivities`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np


@dataclass(frozen=True, eq=False)
class Sensitivities:
    """Reversal table, loop measures and their derivatives with respect to named parameters (SI).

    Attributes
    ----------
    parameters : tuple of str
        Column names: model fields, ``"mass"``, ``"v0"`` and PID gains ``kp, ki, kd, tau``.
    values : numpy.ndarray
        The parameters' values.
    t, x, F : numpy.ndarray
        Reversal times [s], positions [m] and forces [N] (after the model's reset), as integrated.
    dt, dx, dF : numpy.ndarray
        Derivatives, shape ``(n_reversals, n_parameters)``; entry ``[i, j]`` is
        ``d(t_i)/d(parameter j)`` in the units of the row over those of the parameter.
    t_end : float or None
        End of a loop run [s].
    residual_error : float or None
        ``r - x(t_end)`` [m] of a loop.
    d_residual_error : numpy.ndarray or None
        Its derivatives, shape ``(n_parameters,)``.
    settling_time : float or None
        Last time [s] at which ``|x - x(t_end)|`` equals ``band |x(t_end) - x0|`` (loops).
    d_settling_time : numpy.ndarray or None
        Its derivatives (the final value moves with the parameters too).
    """

    parameters: tuple
    values: np.ndarray
    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    dt: np.ndarray
    dx: np.ndarray
    dF: np.ndarray
    t_end: Optional[float] = None
    residual_error: Optional[float] = None
    d_residual_error: Optional[np.ndarray] = None
    settling_time: Optional[float] = None
    d_settling_time: Optional[np.ndarray] = None

    def relative(self, name: str) -> dict:
        """Logarithmic sensitivities ``(p / y) dy/dp`` of the rows with respect to one parameter."""
        j = self.parameters.index(name)
        p = self.values[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = {"t": p * self.dt[:, j] / self.t, "x": p * self.dx[:, j] / self.x, "F": p * self.dF[:, j] / self.F}
        if self.residual_error is not None:
            out["residual_error"] = p * self.d_residual_error[j] / self.residual_error
        if self.settling_time is not None:
            out["settling_time"] = p * self.d_settling_time[j] / self.settling_time
        return out

    def summary(self) -> str:
        """Compact text: sizes, the last reversal's derivatives, loop measures."""
        lines = [f"sensitivities of {len(self.t)} reversals with respect to {', '.join(self.parameters)}"]
        if len(self.t):
            lines.append(f"  last reversal t = {self.t[-1]:.6g} s, x = {self.x[-1]:.6g} m, F = {self.F[-1]:.6g} N")
            for name, row in (("dt", self.dt[-1]), ("dx", self.dx[-1]), ("dF", self.dF[-1])):
                lines.append(f"  {name:<3} " + "  ".join(f"{p}: {v: .4e}" for p, v in zip(self.parameters, row)))
        if self.residual_error is not None:
            lines.append(f"  residual error {self.residual_error: .6e} m at t_end = {self.t_end:.6g} s; d/dp "
                         + "  ".join(f"{p}: {v: .4e}" for p, v in zip(self.parameters, self.d_residual_error)))
        if self.settling_time is not None:
            lines.append(f"  settling time {self.settling_time:.6g} s; d/dp "
                         + "  ".join(f"{p}: {v: .4e}" for p, v in zip(self.parameters, self.d_settling_time)))
        return "\n".join(lines)

    def __repr__(self) -> str:
        extra = "" if self.residual_error is None else f", residual error {self.residual_error:.4e} m"
        return f"Sensitivities({len(self.t)} reversals x {len(self.parameters)} parameters{extra})"
