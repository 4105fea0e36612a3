"""What an export wrote: :class:`CSource` (the paths of ``<name>.h`` and ``<name>.c`` and what they hold)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca

from prefriction import _safe_files as safe

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
    digest : str
        SHA-256 of the header and source as written: what this handle exported. Running it
        (:func:`prefriction.export.run_c`, ...) refuses files that no longer hold it
        (:meth:`texts`), e.g. after another export of the same name into the same directory.
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
    digest: str = field(default="", repr=False)

    MAX_BYTES = 1 << 28
    """Largest header or source [bytes] :meth:`texts` reads."""

    def texts(self) -> tuple[bytes, bytes]:
        """The header and source bytes as this export wrote them, read without following a link.

        Raises
        ------
        ValueError
            If either file is a link, missing, or no longer holds what this export wrote
            (changed, or written again by another export: export again to run it).
        """
        from ._codegen import digest

        try:
            data = safe.read_nofollow(self.header, self.MAX_BYTES), safe.read_nofollow(self.source, self.MAX_BYTES)
        except OSError as exc:
            raise ValueError(f"source: the files of the export {self.name!r} cannot be read "
                             f"({getattr(exc, 'strerror', None) or exc}); export again") from exc
        if digest(*data) != self.digest:
            raise ValueError(f"source: {self.header} and {self.source} no longer hold what this export of "
                             f"{self.name!r} wrote ({self.what}): they were changed or written again by another "
                             f"export; export again to run it")
        return data

    def __repr__(self) -> str:
        return f"CSource({self.name!r}, {self.kind}: {self.what}; {self.header.name} + {self.source.name} in {self.source.parent})"

    def summary(self) -> str:
        """Three lines: what the code computes, the files and their sizes, how to compile."""
        size = self.source.stat().st_size + self.header.stat().st_size
        return (f"{self.kind} {self.name!r}: {self.what}\n"
                f"files: {self.header} and {self.source} ({size / 1024:.1f} KiB, state of {self.state_size} doubles)\n"
                f"compile: gcc -std=c99 -O2 -c {self.source.name} (link with -lm)")
