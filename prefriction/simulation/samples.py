"""The samples of a run: a growable column store, and their conversion to SI.

The samples go into a :class:`SampleBuffer`: one preallocated float column per quantity, grown
in place (``ndarray.resize``) to an estimate of the final count and trimmed in place at the end,
so a run's memory stays close to the arrays it returns (no Python float or tuple per sample).
Every driver of a run that samples (the dense-output loop of
:mod:`prefriction.simulation.dense`, the forced native driver, the sampled-controller loop of
:mod:`prefriction.simulation.drive`) fills one; :func:`samples_si` turns it into the fields of
the result.
"""

from __future__ import annotations

import math
from typing import Iterator, Optional, Sequence

import numpy as np

from prefriction.simulation.run_state import RunState

__all__ = ["DENSE_STEP", "N_DENSE", "SampleBuffer", "samples_si"]

DENSE_STEP = 2.0 * np.pi / 64.0
"""Normalised spacing of ``dense=True`` samples (64 per small cycle)."""
N_DENSE = 16
"""Output times per call of the dense-output integrator."""

_MIN_CAPACITY = 1024
_GROWTH = 1.25  # least growth of a full buffer (the estimate of the final count usually decides)


class SampleBuffer:
    """Samples ``(t~, x~, v~, F~, E_f~, xc)`` of a run (normalised units) in growable columns.

    Parameters
    ----------
    width : int
        Number of controller states ``xc`` per sample (0 without a controller).
    capacity : int, optional
        Initial capacity (samples).

    Notes
    -----
    Each column is one contiguous float array that grows in place; :meth:`columns` trims
    them in place and hands them out, after which the buffer is empty.
    """

    def __init__(self, width: int, capacity: int = _MIN_CAPACITY) -> None:
        self.width = int(width)
        self.n = 0
        cap = max(int(capacity), 1)
        self._cols = [np.empty(cap) for _ in range(5)]  # t, x, v, F, E_f
        self._xc = np.empty((cap, self.width))

    @property
    def capacity(self) -> int:
        """Samples the columns hold before they grow."""
        return len(self._cols[0])

    def __len__(self) -> int:
        return self.n

    def __repr__(self) -> str:
        return f"SampleBuffer({self.n} samples, capacity {self.capacity}, {self.width} controller states)"

    def reserve(self, total: int) -> None:
        """Grow every column in place to hold at least ``total`` samples."""
        if total <= self.capacity:
            return
        total = int(total)
        for col in self._cols:
            col.resize(total, refcheck=False)  # realloc: the first n entries are kept
        self._xc.resize((total, self.width), refcheck=False)

    def _room(self, k: int) -> None:
        """Make room for ``k`` more samples (at least :data:`_GROWTH` times the capacity)."""
        if self.n + k > self.capacity:
            self.reserve(max(self.n + k, math.ceil(_GROWTH * self.capacity)))

    def append(self, sample: Sequence) -> None:
        """Add one sample ``(t~, x~, v~, F~, E_f~, xc)`` (as returned by :meth:`~prefriction.simulation.run_state.RunState.sample`)."""
        self._room(1)
        i = self.n
        for col, value in zip(self._cols, sample[:5]):
            col[i] = value
        if self.width:
            self._xc[i] = sample[5]
        self.n = i + 1

    def extend(self, t: np.ndarray, x: np.ndarray, v: np.ndarray, F: np.ndarray, Ef: np.ndarray,
               xc: Optional[np.ndarray]) -> None:
        """Add ``len(t)`` samples; ``Ef`` may be a scalar, ``xc`` has shape ``(len(t), width)`` or
        ``(width,)`` (the same for every sample); ``F`` may be a list."""
        k = len(t)
        self._room(k)
        i, j = self.n, self.n + k
        for col, values in zip(self._cols, (t, x, v, F, Ef)):
            col[i:j] = values
        if self.width:
            self._xc[i:j] = xc
        self.n = j

    def __iter__(self) -> Iterator[tuple]:
        """The samples one by one as tuples ``(t~, x~, v~, F~, E_f~, xc)``."""
        t, x, v, F, Ef = (col[: self.n].tolist() for col in self._cols)
        for i in range(self.n):
            yield t[i], x[i], v[i], F[i], Ef[i], self._xc[i].copy()

    def columns(self) -> tuple[np.ndarray, ...]:
        """The columns ``t~, x~, v~, F~, E_f~`` (length ``n``) and ``xc`` (``(n, width)``),
        trimmed in place; the buffer is empty afterwards."""
        n = self.n
        for col in self._cols:
            col.resize(n, refcheck=False)
        self._xc.resize((n, self.width), refcheck=False)
        out = (*self._cols, self._xc)
        self.__init__(self.width, 1)
        return out


def samples_si(run: RunState, samples: "SampleBuffer | Sequence[tuple]", u_hist: Sequence[float],
               times_si: Optional[np.ndarray], n_user: int) -> dict:
    """The samples of ``run`` as the SI fields of :class:`~prefriction.simulation.result.SimulationResult`.

    The columns of a :class:`SampleBuffer` are converted in place (the buffer is emptied), so
    the memory stays that of the returned arrays.

    Parameters
    ----------
    run : RunState
        The finished run (its system, feedback, scales and plant).
    samples : SampleBuffer or sequence of tuple
        Samples ``(t~, x~, v~, F~, E_f~, xc)`` in normalised units.
    u_hist : sequence of float
        Total applied force [N] at the samples of a sampled loop (empty otherwise).
    times_si : numpy.ndarray or None
        The requested sample times [s] (None: every ``DENSE_STEP``).
    n_user : int
        Controller states of the user's feedback (the padded ones are dropped).

    Returns
    -------
    dict
        ``t, x, v, F, E_k`` [s, m, m/s, N, J] and, where defined, ``E_f`` [J], ``u`` [N], ``xc``.
    """
    system, feedback, sc = run.system, run.fb, run.sc
    if not isinstance(samples, SampleBuffer):
        buf = SampleBuffer(len(samples[0][5]) if len(samples) else 0, max(len(samples), 1))
        for sample in samples:
            buf.append(sample)
        samples = buf
    t, x, v, F, Ef, xc = samples.columns()
    n = len(t)
    if run.spec.energy and times_si is not None:
        t = times_si[:n].copy()  # the requested times exactly (no unit round trip)
    else:
        t *= sc.t
    x *= sc.x
    v *= sc.v
    F *= sc.F
    E_k = np.square(v)
    E_k *= 0.5 * system.mass
    extra = {"t": t, "x": x, "v": v, "F": F, "E_k": E_k}
    if run.spec.energy:
        Ef *= sc.E
        extra["E_f"] = Ef
    if system.forced or feedback is not None:
        if feedback is not None and feedback.sampled:
            extra["u"] = np.array(u_hist, dtype=float)
        else:
            u = np.asarray(system.u(t), dtype=float) if system.forced else np.zeros(n)
            if feedback is not None:
                e = np.asarray(feedback.reference(t), dtype=float) - x
                u = u + feedback.force(xc, e)
            extra["u"] = u
    if feedback is not None:
        extra["xc"] = xc[:, :n_user]
    return extra
