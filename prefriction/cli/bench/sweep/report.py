"""Table, CSV, notes and targets T1/T2 of ``prefriction bench --sweep`` (``docs/bench.md#sweep``)."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Sequence

from prefriction.cli.bench.sweep.cases import T1_RATIO, TARGET_ERROR, SweepCase
from prefriction.cli.bench.sweep.measure import SweepRow


def format_table(rows: Sequence[SweepRow]) -> str:
    """The compact table: case, cold/warm, compiles, times, errors, scipy time and ratio.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows.

    Returns
    -------
    str
        Printable table.
    """
    head = (f"{'case':<28} {'run':<5} {'compiles':>8} {'end-to-end [s]':>14} {'per value [ms]':>14} "
            f"{'max error':>10} {'import [s]':>10} {'scipy [s]':>9} {'scipy rtol':>10} {'scipy err':>9} "
            f"{'ratio':>7}")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.case:<28} {r.run:<5} {r.compiles:>8d} {r.end_to_end_s:14.3f} {r.per_value_ms:14.2f} "
            f"{r.max_rel_error:10.1e} {r.import_s:10.2f} {r.scipy_s:9.2f} {r.scipy_rtol:10.0e} "
            f"{r.scipy_error:9.1e} {r.ratio:6.1f}x"
        )
    return "\n".join(lines)


def write_csv(path: Path, rows: Sequence[SweepRow]) -> None:
    """Write the rows to ``path`` as CSV, one column per :class:`SweepRow` field.

    Parameters
    ----------
    path : pathlib.Path
        Output file.
    rows : sequence of SweepRow
        Measured rows.
    """
    names = list(SweepRow.__dataclass_fields__)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for r in rows:
            w.writerow([getattr(r, k) for k in names])


def match_notes(rows: Sequence[SweepRow]) -> list[str]:
    """Notes for cases whose scipy sweep error exceeds the error matched on the first value.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows.

    Returns
    -------
    list of str
        One line per such case: its ratio is a lower bound (a tighter rtol would be slower).
    """
    notes = []
    for r in rows:
        target = max(TARGET_ERROR, r.max_rel_error)
        if r.run == "cold" and r.scipy_error > target:
            notes.append(f"note: {r.case}: rtol {r.scipy_rtol:g} matches on the first value, but scipy's error "
                         f"over the sweep is {r.scipy_error:.1e} > {target:.1e}: its ratios are lower bounds")
    return notes


def _find(rows: Sequence[SweepRow], case: SweepCase, run: str) -> SweepRow:
    """The row of ``case`` and ``run`` (``"cold"`` or ``"warm"``)."""
    return next(r for r in rows if r.case == case.label and r.run == run)


def targets(rows: Sequence[SweepRow], cases: Sequence[SweepCase], quick: bool) -> list[str]:
    """The PASS/FAIL lines of targets T1 and T2.

    Parameters
    ----------
    rows : sequence of SweepRow
        Measured rows (a cold and a warm row per case).
    cases : sequence of SweepCase
        The cases; the first is the gamma in [1, 3] sweep of T1.
    quick : bool
        With ``--quick`` the speed part of T1 is reported but not checked (4 values only).

    Returns
    -------
    list of str
        One line per target, starting with ``T1`` or ``T2`` and holding ``PASS`` or ``FAIL``.
    """
    first = cases[0]
    cold, warm = _find(rows, first, "cold"), _find(rows, first, "warm")
    fast = warm.ratio >= T1_RATIO
    ok1 = (warm.max_rel_error <= TARGET_ERROR and cold.compiles == 1 and warm.compiles == 0
           and (fast or quick))
    speed = "speed not checked in --quick, " if quick else ""
    lines = [
        f"T1 ({len(first.values)} gamma values in [1, 3], error <= {TARGET_ERROR:g}, new process with the "
        f"structure cached: >= {T1_RATIO:g}x faster than scipy DOP853 at the same error; empty cache: "
        f"1 compile): {'PASS' if ok1 else 'FAIL'}  ({speed}warm {warm.end_to_end_s * 1e3:.0f} ms end to end, "
        f"error {warm.max_rel_error:.1e}; scipy {warm.scipy_s * 1e3:.0f} ms at rtol {warm.scipy_rtol:g}, "
        f"error {warm.scipy_error:.1e}: ratio {warm.ratio:.1f}x; compiles cold {cold.compiles}, "
        f"warm {warm.compiles})"
    ]
    per = []
    ok2 = True
    for case in cases:
        c, w = _find(rows, case, "cold"), _find(rows, case, "warm")
        ok2 &= c.compiles <= 1 and w.compiles == 0 and c.compile_lines == c.compiles and w.compile_lines == 0
        per.append(f"{case.label}: {c.compiles} cold / {w.compiles} warm")
    lines.append(f"T2 (a sweep of one structure compiles at most once; compiles per sweep of "
                 f"{len(first.values)} values): {'PASS' if ok2 else 'FAIL'}  ({'; '.join(per)})")
    return lines
