"""The reversal table of a run with its energies computed on first use.

The energies of a :class:`~prefriction.ReversalTable` (``E_p`` (3.9), ``E_d`` (2.10), ``E_0``)
take the model's branch energy of every reversal force: on the native driver that was a third
of a 50-reversal run at ``rtol = 1e-4``. :class:`LazyReversalTable` is a
``ReversalTable`` whose ``t, x, F`` are set (and checked) at once and whose energies are
computed and checked the first time one of them is read, then kept. It pickles with its inputs
(the energies are computed where they are read); :meth:`LazyReversalTable.eager` gives the plain
table (sweeps pack plain tables, :mod:`prefriction.simulation.packed`).
"""

from __future__ import annotations

from typing import Any, Optional, Union

import numpy as np

from prefriction.models import Oscillator
from prefriction.reversals import ReversalTable
from prefriction.units import Scales

__all__ = ["LazyReversalTable", "energies", "reversal_table"]

_ENERGY_BLOCK = 4096  # reversals per branch_energy_of_force call: temporaries of ~2 MB (Dahl: 57 doubles each)


def energies(F_r: np.ndarray, W_r: np.ndarray, system: Oscillator, s0: float, v0: float,
             F0: float) -> tuple[np.ndarray, np.ndarray, float]:
    """``E_p``, ``E_d`` [J] per reversal and ``E_0`` [J] from the reversal forces ``F_r`` [N] and the
    input's work per half-cycle ``W_r`` [J]; the first branch has direction ``s0``, the initial
    velocity and force are ``v0`` [m/s], ``F0`` [N]. ``E_p`` is the branch potential (3.9) (NaN for
    a rate-dependent model, which stores none), ``E_d`` the balance (2.10)."""
    model, sc = system.friction, Scales.of(system)
    n = len(F_r)
    if not model.rate_independent:  # no stored branch energy: E_p is not defined (NaN), E_0 kinetic
        E_p = np.full(n, np.nan)
        E0 = 0.5 * system.mass * v0 * v0
    else:  # the start and every reversal, in blocks (each call costs ~50 us whatever its size)
        E = np.empty(n + 1)  # the start (F0, s0), then reversal k on the branch s0 (-1)^k
        for a in range(0, n + 1, _ENERGY_BLOCK):
            b = min(n + 1, a + _ENERGY_BLOCK)
            F = F_r[max(a - 1, 0):b - 1] / sc.F
            if a == 0:
                F = np.concatenate(([F0 / sc.F], F))
            E[a:b] = model.branch_energy_of_force(F, np.where(np.arange(a, b) % 2 == 0, s0, -s0)) * sc.E
        E0, E_p = 0.5 * system.mass * v0 * v0 + float(E[0]), E[1:]
    E_d = np.empty(n)
    if n:
        E_d[0] = E0 - E_p[0] + W_r[0]
        np.add(E_p[:-1], W_r[1:], out=E_d[1:])
        E_d[1:] -= E_p[1:]
    return E_p, E_d, E0


class LazyReversalTable(ReversalTable):
    """A :class:`~prefriction.ReversalTable` whose ``E_p``, ``E_d`` and ``E_0`` are computed on
    first use (:func:`energies`); ``t``, ``x``, ``F`` [s, m, N] are checked at once.

    Parameters
    ----------
    t, x, F, W : numpy.ndarray
        Reversal times [s], positions [m], forces [N] and the input's work over each half-cycle [J].
    system : Oscillator
        The simulated system.
    s0, v0, F0 : float
        Direction of the first branch, initial velocity [m/s] and force [N].
    """

    def __init__(self, t: np.ndarray, x: np.ndarray, F: np.ndarray, W: np.ndarray, system: Oscillator,
                 s0: float, v0: float, F0: float) -> None:  # noqa: D107 (no dataclass __init__: energies later)
        nan = np.full(len(t), np.nan)
        ReversalTable.__post_init__(_Columns(t, x, F, nan))  # the checks of t, x, F
        for name, col in (("t", t), ("x", x), ("F", F)):
            object.__setattr__(self, name, col)
        object.__setattr__(self, "_inputs", (W, system, s0, v0, F0))

    def _energies(self) -> tuple:
        done = self.__dict__.get("_done")
        if done is None:
            E_p, E_d, E0 = energies(self.F, *self._inputs)
            done = ReversalTable(t=self.t, x=self.x, F=self.F, E_p=E_p, E_d=E_d, E_0=E0)  # checks them
            object.__setattr__(self, "_done", done)
        return done

    @property
    def E_p(self) -> np.ndarray:  # type: ignore[override]
        """Potential energy at each reversal [J] (:class:`~prefriction.ReversalTable`)."""
        return self._energies().E_p

    @property
    def E_d(self) -> np.ndarray:  # type: ignore[override]
        """Energy dissipated in the half-cycle that ends at each reversal [J]."""
        return self._energies().E_d

    @property
    def E_0(self) -> float:  # type: ignore[override]
        """Energy of the initial state [J]."""
        return self._energies().E_0

    def eager(self) -> ReversalTable:
        """The plain table, energies computed."""
        return self._energies()


class _Columns:
    """The attributes ``ReversalTable.__post_init__`` checks (energies NaN: checked later)."""

    def __init__(self, t: Any, x: Any, F: Any, nan: np.ndarray) -> None:
        self.t, self.x, self.F, self.E_p, self.E_d, self.E_0 = t, x, F, nan, nan, 0.0


def reversal_table(rev: Union[list, tuple], system: Oscillator, s0: float, v0: float, F0: float,
                   sc: Optional[Scales] = None) -> tuple[ReversalTable, np.ndarray]:
    """The reversals as a :class:`ReversalTable` in SI (its energies ``E_p`` (3.9), ``E_d``
    (2.10), ``E_0`` computed on first use: :class:`LazyReversalTable`),
    and the input's work over each half-cycle [J].

    ``rev``: a list of ``(t~, x~, F~, W~)`` tuples, or the four columns
    (:meth:`~prefriction.simulation.reversal_log.ReversalLog.columns`; writable columns are
    converted to SI in place, so that a long run holds them once); ``sc``: the system's scales,
    if known."""
    sc = Scales.of(system) if sc is None else sc
    if isinstance(rev, list):
        R = np.array(rev, dtype=float).reshape(-1, 4)
        rev = (R[:, 0], R[:, 1], R[:, 2], R[:, 3])
    t_r, x_r, F_r, W_r = (np.multiply(col, unit, out=col if col.flags.writeable else None)
                          for col, unit in zip(rev, (sc.t, sc.x, sc.F, sc.E)))
    return LazyReversalTable(t_r, x_r, F_r, W_r, system, s0, v0, F0), W_r
