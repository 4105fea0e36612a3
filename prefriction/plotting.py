"""Shared plot helpers: Agg-only figures with a note strip, saved as PNG.

Figures are built with :class:`matplotlib.figure.Figure` directly (no pyplot), so that
they render with the Agg canvas whatever backend the user has configured and leave no
global state behind.
"""

from __future__ import annotations

import io
import os
import sys
from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

PathLike = Union[str, Path]

#: Colours for parameter families (colour-blind safe, matplotlib's tab10 order).
COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def length_unit(values: np.ndarray) -> tuple[float, str]:
    """Factor and label that bring lengths [m] of the size of ``values`` to mm, µm or nm.

    >>> length_unit(np.array([0.0, 7e-3]))
    (1000.0, 'mm')
    """
    peak = float(np.max(np.abs(values))) if np.size(values) else 0.0
    return (1e3, "mm") if peak >= 1e-3 else (1e6, "µm") if peak >= 1e-6 else (1e9, "nm")


def new_figure(
    nrows: int = 1,
    ncols: int = 1,
    *,
    size: tuple[float, float] = (7.0, 4.5),
    sharex: bool = False,
    sharey: bool = False,
) -> tuple[Figure, np.ndarray]:
    """Create a constrained-layout figure and its axes.

    Parameters
    ----------
    nrows, ncols : int
        Grid of axes.
    size : (float, float)
        Width and height [inch].
    sharex, sharey : bool
        Share the axes' x or y limits.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : numpy.ndarray of Axes, shape ``(nrows, ncols)``
    """
    fig = Figure(figsize=size, layout="constrained")
    axes = fig.subplots(nrows, ncols, sharex=sharex, sharey=sharey, squeeze=False)
    return fig, axes


def new_mosaic(layout: str, *, size: tuple[float, float] = (7.0, 4.5)) -> tuple[Figure, dict[str, Axes]]:
    """Create a constrained-layout figure with axes laid out by a mosaic string.

    Parameters
    ----------
    layout : str
        Rows separated by ``;``, one letter per cell, e.g. ``"AB;AC"`` (``A`` spans two rows).
    size : (float, float)
        Width and height [inch].

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : dict
        Letter -> Axes.
    """
    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplot_mosaic(layout)


def add_note(fig: Figure, text: str, *, lines: int = 1) -> None:
    """Write ``text`` in a strip along the bottom of ``fig`` (e.g. parameters the paper leaves open).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure created by :func:`new_figure`.
    text : str
        Note, possibly several lines separated by ``\\n``.
    lines : int
        Number of text lines, used to reserve the strip's height.
    """
    height_in = fig.get_figheight()
    strip = min(0.4, (0.2 + 0.17 * lines) / height_in)
    fig.get_layout_engine().set(rect=(0.0, strip, 1.0, 1.0 - strip))
    fig.text(0.01, strip / 2.0, text, ha="left", va="center", fontsize=8, color="0.25")


def save(fig: Figure, outdir: PathLike, name: str, *, dpi: int = 130) -> Path:
    """Save ``fig`` as ``outdir/name`` (PNG), creating ``outdir`` if needed; return the path."""
    from prefriction._safe_files import output_dir

    return write_figure(fig, output_dir(outdir, "outdir") / name, dpi=dpi, argument="outdir")


def write_figure(fig: Figure, path: object, *, dpi: int = 120, argument: str = "path") -> Path:
    """Write ``fig`` to the file ``path`` (format from its suffix, PNG if none); return the path.

    The image is rendered in memory and written atomically (a new temporary file renamed over
    the destination, :func:`prefriction._safe_files.write_atomic`), so a link at ``path`` is
    replaced, never followed. ``TypeError``/``ValueError`` naming ``argument`` for a path that
    is not one, is empty, or whose directory is missing or not writable.
    """
    from prefriction import _safe_files as safe

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{argument} must be a str or pathlib.Path, got {type(path).__name__} {path!r}")
    out = Path(path)
    if str(path) == "" or out.name == "":
        raise ValueError(f"{argument} must name a file, got {str(path)!r}")
    if os.path.isdir(out) and not os.path.islink(out):
        raise ValueError(f"{argument} must name a file, got the directory {str(out)!r}")
    fmt = out.suffix[1:].lower() or "png"
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format=fmt, dpi=dpi)
    except ValueError as exc:
        raise ValueError(f"{argument} {str(out)!r}: matplotlib cannot write the format {fmt!r} ({exc})") from exc
    if not os.path.isdir(out.parent if str(out.parent) else "."):
        raise ValueError(f"{argument} {str(out)!r}: the directory {str(out.parent)!r} does not exist")
    try:
        safe.write_atomic(out, buf.getvalue(), 0o644)
    except OSError as exc:
        raise ValueError(f"{argument} {str(out)!r} cannot be written ({exc.strerror or exc})") from exc
    return out


def script_args(
    argv: Sequence[str], default_out: PathLike = ".", *, allow_quick: bool = True, prog: Optional[str] = None
) -> tuple[str, bool]:
    """Parse an example script's command line ``[outdir] [--quick]``.

    Parameters
    ----------
    argv : sequence of str
        The arguments after the script name, e.g. ``sys.argv[1:]``.
    default_out : str or Path
        Output directory when none is given.
    allow_quick : bool
        Whether the script accepts ``--quick`` (a faster, coarser run); when False, ``--quick``
        is refused like any other option.
    prog : str, optional
        Script name shown in the usage line (default ``sys.argv[0]``).

    Returns
    -------
    outdir : str
        The output directory (``default_out`` if none given).
    quick : bool
        True if ``--quick`` was given.

    Notes
    -----
    ``-h``/``--help`` prints the usage and exits with status 0. Any other argument starting
    with ``-``, or more than one output directory, prints the usage and a message naming the
    argument to stderr and exits with status 2 (the argparse convention).
    """
    prog = prog if prog is not None else Path(sys.argv[0]).name
    usage = f"usage: {prog} [outdir]" + (" [--quick]" if allow_quick else "")
    outdirs: list[str] = []
    quick = False
    for arg in argv:
        if arg in ("-h", "--help"):
            print(usage)
            raise SystemExit(0)
        if arg == "--quick" and allow_quick:
            quick = True
        elif arg.startswith("-"):
            allowed = "--quick, -h/--help" if allow_quick else "-h/--help"
            _refuse(usage, f"unknown option {arg!r} (allowed: {allowed})")
        else:
            outdirs.append(arg)
    if len(outdirs) > 1:
        _refuse(usage, f"one output directory expected, got {len(outdirs)}: {outdirs!r}")
    return (outdirs[0] if outdirs else str(default_out)), quick


def _refuse(usage: str, message: str) -> None:
    """Print ``usage`` and ``message`` to stderr and exit with status 2."""
    print(f"{usage}\nerror: {message}", file=sys.stderr)
    raise SystemExit(2)
