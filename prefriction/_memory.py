"""Size limits that count memory, not samples: :func:`check_memory`.

A limit on the number of samples alone let a model with many states ask for tens of GiB
(a 100-element Maxwell-slip model along 1e7 samples: 30 GiB), and let a sampled loop at its own
sample limit end in a raw ``MemoryError``. Each run that keeps a row of numbers per sample
counts its row and refuses, before any work, a run whose arrays would exceed :data:`MAX_BYTES`.
"""

from __future__ import annotations

__all__ = ["MAX_BYTES", "check_memory"]

MAX_BYTES = 4 * 2**30
"""Largest memory [bytes] the arrays of one run may take (4 GiB)."""


def check_memory(what: str, count: int, doubles: int, unit: str, remedy: str) -> None:
    """``ValueError`` if ``count`` rows of ``doubles`` float64 numbers each exceed :data:`MAX_BYTES`.

    Parameters
    ----------
    what : str
        The run, for the message (``"friction_along of MaxwellSlip (201 states and flags)"``).
    count : int
        Rows (samples, sample instants).
    doubles : int
        Float64 numbers kept per row at the peak of the run.
    unit : str
        What a row is (``"samples"``).
    remedy : str
        What helps (``"split the record"``).
    """
    need = 8 * int(count) * int(doubles)
    if need > MAX_BYTES:
        fit = MAX_BYTES // (8 * int(doubles))
        raise ValueError(
            f"{what}: {count:_} {unit} of about {doubles} numbers each would need {need / 2**30:.3g} GiB, more "
            f"than the limit of {MAX_BYTES / 2**30:g} GiB (prefriction._memory.MAX_BYTES); at most {fit:_} {unit} "
            f"fit: {remedy}")
