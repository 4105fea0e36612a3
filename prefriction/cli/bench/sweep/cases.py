"""The three sweeps of ``prefriction bench --sweep`` and their constants (``docs/bench.md#sweep``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction.cli.bench.cases import table_error
from prefriction.models import Dahl, Oscillator
from prefriction.signals import Sine

SIGMA, FC, MASS = 1e4, 1.0, 1.0  # N/m, N, kg
V0_FREE = 1.0  # initial velocity of the unforced sweeps [m/s]
FREQUENCY = 5.0  # frequency of the Sine input [Hz]
N_REV = 50  # reversals per unforced run
T_END = 1.0  # duration of a forced run [s]
N_VALUES, QUICK_VALUES = 20, 4
LADDER = (1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)  # scipy rtol, loosest first
REF_RTOL = 1e-12  # scipy reference of the forced sweep
TARGET_ERROR = 1e-8
T1_RATIO = 20.0
WARM_REPEATS = 3
SCIPY_BUDGET = 6.0  # stop repeating a scipy sweep once the repeats took this long [s]


@dataclass(frozen=True)
class SweepCase:
    """One sweep: a parameter of one model structure over a set of values.

    Attributes
    ----------
    key : str
        Short identifier (``gamma_ge1``, ``gamma_lt1``, ``sine``).
    label : str
        Row label of the table.
    param : str
        The swept parameter, ``"gamma"`` or ``"amplitude"``.
    values : tuple of float
        The values of ``param``.
    forced : bool
        True for the Sine-forced sweep (``t_end = 1`` s), False for unforced (50 reversals).
    """

    key: str
    label: str
    param: str
    values: tuple[float, ...]
    forced: bool

    def system(self, value: float) -> Oscillator:
        """The oscillator of one value.

        Parameters
        ----------
        value : float
            Value of :attr:`param` (gamma, or the amplitude of the Sine input [N]).

        Returns
        -------
        Oscillator
            Dahl oscillator with ``sigma = 1e4`` N/m, ``Fc = 1`` N, ``m = 1`` kg.
        """
        if self.forced:
            return Oscillator(Dahl(SIGMA, FC, 1.0), mass=MASS, u=Sine(value, FREQUENCY))
        return Oscillator(Dahl(SIGMA, FC, value), mass=MASS)

    @property
    def v0(self) -> float:
        """Initial velocity [m/s]: 1 unforced, 0 (from rest) forced."""
        return 0.0 if self.forced else V0_FREE

    def gamma_of(self, value: float) -> float:
        """The gamma of the system of one value.

        Parameters
        ----------
        value : float
            Value of :attr:`param`.

        Returns
        -------
        float
            ``value`` for a gamma sweep, 1 for the forced sweep.
        """
        return 1.0 if self.forced else value

    def simulate_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`prefriction.sweep`: ``t_end`` forced, ``reversals`` unforced.

        Returns
        -------
        dict
            ``{"t_end": 1.0}`` or ``{"reversals": 50}`` (``rtol`` stays at its default 1e-8).
        """
        return {"t_end": T_END} if self.forced else {"reversals": N_REV}


def sweep_cases(n: int) -> list[SweepCase]:
    """The three sweeps of the benchmark with ``n`` values each.

    Parameters
    ----------
    n : int
        Values per sweep (20 in the full run, 4 with ``--quick``).

    Returns
    -------
    list of SweepCase
        gamma in [1, 3], gamma in [0.3, 0.9] (both unforced), Sine amplitude in [0.2, 2] N.
    """
    return [
        SweepCase("gamma_ge1", "gamma in [1, 3]", "gamma", _grid(1.0, 3.0, n), False),
        SweepCase("gamma_lt1", "gamma in [0.3, 0.9]", "gamma", _grid(0.3, 0.9, n), False),
        SweepCase("sine", f"Sine {FREQUENCY:g} Hz, A in [0.2, 2] N", "amplitude", _grid(0.2, 2.0, n), True),
    ]


def _grid(a: float, b: float, n: int) -> tuple[float, ...]:
    """``n`` equally spaced values from ``a`` to ``b`` as Python floats."""
    return tuple(float(v) for v in np.linspace(a, b, n))


def reversal_error(t: np.ndarray, x: np.ndarray, F: np.ndarray, ref_t: np.ndarray, ref_x: np.ndarray,
                   ref_F: np.ndarray, x_scale: float = FC / SIGMA) -> float:
    """:func:`prefriction.cli.bench.cases.table_error` with the sweeps' least position scale.

    The arguments are those of ``table_error`` (reversals [s, m, N] and the reference); only
    ``x_scale`` has a default, ``Fc / sigma = 1e-4`` m. Returns the largest relative error, or
    ``inf`` if the numbers of reversals differ or a value is not finite.
    """
    return table_error(t, x, F, ref_t, ref_x, ref_F, x_scale)


def exact_tables(case: SweepCase) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Reversals ``(t, x, F)`` of :func:`prefriction.exact_reversals` for every value (unforced)."""
    from prefriction.analysis.exact import exact_reversals

    out = []
    for value in case.values:
        ref = exact_reversals(case.system(value), case.v0, N_REV)
        out.append((ref.t, ref.x, ref.F))
    return out
