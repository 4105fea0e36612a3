"""Tables, CSV and figure of ``prefriction bench`` (headline and stiff cases)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

from prefriction.cli.bench import reference_rows
from prefriction.cli.bench.cases import HEADLINE, N_REV
from prefriction.cli.bench.stiff import StabilityRow
from prefriction.cli.bench.work_precision import Row


def format_rows(rows: list[Row]) -> str:
    """Readable work-precision table: solver, tol, error, err/tol, warm run and compile time [s]."""
    head = f"{'solver':<28} {'tol':>8} {'max rel error':>14} {'err/tol':>9} {'warm run [s]':>13} {'compile [s]':>12}  note"
    lines = [head, "-" * len(head)]
    for r in rows:
        if math.isnan(r.tol):
            lines.append(f"{r.solver:<28} {'':>8} {'':>14} {'':>9} {'':>13} {'':>12}  {r.note}")
            continue
        ratio = r.error / r.tol if math.isfinite(r.error) else math.inf
        comp = f"{r.compile_seconds:12.3f}" if r.compile_seconds else f"{'':>12}"
        lines.append(f"{r.solver:<28} {r.tol:8.0e} {r.error:14.3e} {ratio:9.2f} {r.seconds:13.5f} {comp}  {r.note}")
    return "\n".join(lines)


def format_stability(rows: list[StabilityRow]) -> str:
    """Readable stability table: one line per case with its errors, drift, run time and verdict."""
    head = (f"{'case':<32} {'max err/tol':>11} {'at tol':>7} {'n':>6} {'err 1st 50':>11} "
            f"{'err all n':>11} {'E_p drift':>10} {'run [s]':>8} {'us/rev':>7} result")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.case:<32} {r.worst_ratio:11.2f} {r.worst_tol:7.0e} {r.n_long:>6} {r.err_long_50:11.2e} "
            f"{r.err_long_all:11.2e} {r.energy_drift:10.2e} {r.seconds_long:8.3f} "
            f"{1e6 * r.seconds_long / max(r.n_long, 1):7.1f} {'pass' if r.passed else 'FAIL'}"
        )
    return "\n".join(lines)


def headline_section(rows: list[Row]) -> str:
    """The headline section: a title line and :func:`format_rows`."""
    return (f"Headline case: {HEADLINE.name} (error over the first {N_REV} reversals vs exact_reversals)\n\n"
            + format_rows(rows))


def stiff_section(rows: list[StabilityRow], ladder: list[float], n_long: int) -> str:
    """The section of the stiff and extreme cases: what passes, and :func:`format_stability`."""
    return (f"\nStiff and extreme cases: tolerance ladder {ladder[0]:g}..{ladder[-1]:g} over {N_REV} reversals, "
            f"then {n_long} reversals at rtol 1e-8 in one run.\npass: max err/tol <= 10 over the ladder, "
            f"first-50 error <= 10 rtol, all-{n_long} error <= 10 rtol n/{N_REV} (global error grows "
            f"linearly with the number of cycles)\n\n" + format_stability(rows))


def reference_section(rows: list[reference_rows.RowResult]) -> str:
    """The section of the rows against independent references: the references, and their table."""
    return (f"\nRows against independent references (scipy DOP853 rtol {reference_rows.REF_RTOL:g} with restarts "
            f"at every reversal and saturation; energy conservation for gamma = 0):\nerr/rtol per tolerance, "
            f"pass within {reference_rows.LIMIT:g}x rtol; a wrong reversal count is an infinite error\n\n"
            + reference_rows.format_rows(rows))


def write_csv(path: Path, rows: list[Row]) -> None:
    """Write ``rows`` to ``path``: case, solver, tol, max_rel_error, warm_run_s, compile_s, note."""
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "solver", "tol", "max_rel_error", "warm_run_s", "compile_s", "note"])
        for r in rows:
            w.writerow([r.case, r.solver, r.tol, r.error, r.seconds, r.compile_seconds, r.note])


def plot(path: Path, rows: list[Row]) -> None:
    """Work-precision figure of the headline rows (log-log error against warm run time), saved to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 5.5))
    for solver in dict.fromkeys(r.solver for r in rows):
        pts = [(r.seconds, r.error) for r in sorted(rows, key=lambda r: -r.tol)
               if r.solver == solver and math.isfinite(r.error) and math.isfinite(r.seconds)]
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if "simulate" in solver else ".--",
                      label=solver, lw=2 if "simulate" in solver else 1)
    ax.set_xlabel("warm run time for 50 reversals [s]")
    ax.set_ylabel("max relative error of reversal t, x, F [-]")
    ax.set_title("Work-precision, Dahl oscillator, sigma/Fc = 1e4 1/m, m = 1 kg, v0 = 1 m/s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # beside the axes: covers no point
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
