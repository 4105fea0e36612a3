"""What an export wrote: :class:`CSource` (the paths of ``<name>.h`` and ``<name>.c`` and what they hold)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca

__all__ = ["CSource"]


@dataclass(frozen=True)
class CSource:
    """A C99 header and source written by :mod:`prefriction.export` (no dependency beyond libm).

    Attributes
    ----------
    name : str
        The C prefix of every exported symbol (``<name>_state``, ``<name>_reset``, ...).
    header, source : pathlib.Path
        The files ``<name>.h`` and ``<name>.c``.
    kind : str
        ``"model"`` (:func:`prefriction.export.c_source`), ``"controller"``
        (:func:`prefriction.export.controller_source`) or ``"plant"``
        (:func:`prefriction.export.plant_source`).
    what : str
        One line: what the code computes (model, sample time, structure).
    function : casadi.Function
        The CasADi Function the C code was generated from; evaluated in Python it gives the same
        numbers as the C code (to rounding).
    state_size : int
        Number of doubles in ``<name>_state``'s array ``w``.
    model : FrictionModel or Oscillator or None
        The exported friction model (kind ``"model"``) or stage (kind ``"plant"``).
    options : dict
        The export's keyword values (``Ts``, ``n_sub``, ``F0``, ``rtol``, ``force_scale``, ...).
    """

    name: str
    header: Path
    source: Path
    kind: str
    what: str
    function: ca.Function = field(repr=False)
    state_size: int
    model: Any = field(default=None, repr=False)
    options: dict = field(default_factory=dict, repr=False)

    def __repr__(self) -> str:
        return f"CSource({self.name!r}, {self.kind}: {self.what}; {self.header.name} + {self.source.name} in {self.source.parent})"

    def summary(self) -> str:
        """Three lines: what the code computes, the files and their sizes, how to compile."""
        size = self.source.stat().st_size + self.header.stat().st_size
        return (f"{self.kind} {self.name!r}: {self.what}\n"
                f"files: {self.header} and {self.source} ({size / 1024:.1f} KiB, state of {self.state_size} doubles)\n"
                f"compile: gcc -std=c99 -O2 -c {self.source.name} (link with -lm)")
