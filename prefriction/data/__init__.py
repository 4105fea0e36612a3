"""Measured records shipped with prefriction (``docs/identify.md#measured``).

- :func:`tribometer`: a reciprocating tribometer record (FrictionModels.jl
  ``examples/test_data_2.txt``, MIT licence, see ``prefriction/data/tribometer/README.md``):
  200 Hz, 213.8 s, 42,579 samples of time, normal load, position and friction force, in SI units.
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

__all__ = ["TribometerRecord", "tribometer"]

_FILE = "tribometer/test_data_2.txt.gz"


@dataclass(frozen=True, eq=False)
class TribometerRecord:
    """A measured friction record in SI units (read-only arrays of one length).

    Attributes
    ----------
    t : numpy.ndarray
        Time [s] (0 to 213.784 s; 5 ms steps, some of 10 ms).
    x : numpy.ndarray
        Stage position [m], tared to its first sample.
    F : numpy.ndarray
        Friction force [N], sign as in the upstream example (positive when ``x`` increases).
    normal : numpy.ndarray
        Normal load [N] (about 5 N from t = 6.19 s to t = 211.38 s).
    source : str
        Where the record comes from and its licence.
    """

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    normal: np.ndarray
    source: str

    def __len__(self) -> int:
        return int(self.t.size)

    def window(self, start: float, stop: float, *, step: int = 1):
        """The samples with ``start <= t <= stop`` as :class:`prefriction.identify.ForceDisplacement`.

        Parameters
        ----------
        start, stop : float
            Time window [s], ``0 <= start < stop``.
        step : int, default 1
            Keep every ``step``-th sample (decimation, ``1 <= step <= 100``).

        Returns
        -------
        prefriction.identify.ForceDisplacement
            The window's time [s], position [m] and friction force [N].

        Raises
        ------
        ValueError
            If the window is empty or reversed, or ``step`` is out of range.
        """
        from prefriction.identify.data import ForceDisplacement

        if not (np.isfinite(start) and np.isfinite(stop) and 0.0 <= start < stop):
            raise ValueError(f"start, stop must satisfy 0 <= start < stop [s], got start = {start!r}, stop = {stop!r}")
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)) or not 1 <= step <= 100:
            raise ValueError(f"step must be an integer in [1, 100], got {step!r}")
        keep = np.flatnonzero((self.t >= start) & (self.t <= stop))[::step]
        if keep.size < 8:
            raise ValueError(f"the window [{start!r}, {stop!r}] s with step {step} holds {keep.size} samples "
                             f"(allowed: at least 8; the record spans [0, {self.t[-1]:.6g}] s)")
        return ForceDisplacement(self.t[keep], self.x[keep], self.F[keep])

    def __repr__(self) -> str:
        return (f"TribometerRecord({len(self)} samples, t in [0, {self.t[-1]:.6g}] s, "
                f"x in [{self.x.min() * 1e3:.4g}, {self.x.max() * 1e3:.4g}] mm, "
                f"F in [{self.F.min():.3g}, {self.F.max():.3g}] N)")


@lru_cache(maxsize=1)
def tribometer() -> TribometerRecord:
    """The measured reciprocating tribometer record, in SI units.

    FrictionModels.jl ``examples/test_data_2.txt`` (J. Christopherson and contributors, MIT
    licence, kept with the data in ``prefriction/data/tribometer/``): 5 N normal load, a
    0.23 mm triangular stroke at about 0.26 mm/s, about 58 cycles and 117 reversals, friction
    about +-2.3 N in gross sliding. Columns converted from uN and mm: position tared to its
    first sample, the friction sign flipped as in the upstream example.

    Returns
    -------
    TribometerRecord
        ``t`` [s], ``x`` [m], ``F`` [N], ``normal`` [N] (42,579 samples).

    Examples
    --------
    >>> from prefriction.data import tribometer
    >>> rec = tribometer()
    >>> len(rec), round(float(rec.t[-1]), 3)
    (42579, 213.784)
    >>> data = rec.window(12.0, 60.0)   # a ForceDisplacement for identify.fit
    """
    with (resources.files(__name__) / _FILE).open("rb") as raw, gzip.open(raw, "rt") as text:
        d = np.loadtxt(text, skiprows=1)
    t, normal, x_mm, f_un = d.T
    arrays = [t.copy(), (x_mm - x_mm[0]) * 1e-3, -f_un * 1e-6, normal * 1e-6]
    for a in arrays:
        a.flags.writeable = False
    src = ("FrictionModels.jl examples/test_data_2.txt (commit e60a4bd), MIT licence, Copyright (c) 2021 "
           "Jason Christopherson and contributors")
    return TribometerRecord(*arrays, source=src)
