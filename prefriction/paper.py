"""``prefriction paper --out DIR``: reproduce the paper's figures, go past them, write a report.

Runs every script ``examples/fig*.py`` and ``examples/beyond_*.py`` (each has
``main(outdir, *, quick=False) -> dict``), prints one progress line per figure (name,
seconds), and writes ``DIR/report.md``: each figure with a caption, the key numbers, the
erratum in (3.13) and every place where the toolbox disagrees with the paper, with numbers.

The examples live in the source tree (``examples/`` beside the package); they are found next
to the package or, for a non-editable install, in ``./examples`` of the working directory.

Also holds :func:`printed_313_displacement`, (3.13) exactly as printed, used by the figures
that show what the erratum does.
"""

from __future__ import annotations

import argparse
import importlib.util
import time
import traceback
from pathlib import Path
from types import ModuleType
from typing import Callable

import numpy as np

#: Figure scripts in the order they run and appear in the report.
FIGURES = (
    "fig2_energy_balance",
    "fig3_potential_energy",
    "fig4_omega",
    "fig5_force_displacement",
    "fig6_reversal_energy",
    "fig7_energy_time_series",
    "beyond_map_vs_approximation",
    "beyond_convergence",
    "beyond_energy_envelope",
    "beyond_gamma_loops",
)


def printed_313_displacement(a: np.ndarray, sigma_over_fc: float) -> np.ndarray:
    """Next reversal from (3.13) exactly as printed, in units of ``Fc/sigma``.

    (3.13) reads ``x_{i+1} = (E_p/Fc) (1 - (Fc/sigma) (Fc/(Fc - F_i))^{3/5})^{-1}``. Solving
    (3.12) with ``K`` from (3.11) gives ``(1 - (Fc/(Fc - F_i))^{3/5})^{-1}`` instead: the printed
    form has an extra factor ``Fc/sigma`` [m] inside the bracket, where a pure number belongs,
    so it agrees with the corrected form only when ``sigma/Fc = 1 m^-1``. Evaluated here with
    ``Fc = 1 N`` and the given number ``sigma/Fc`` [1/m], at the reversal ``F_i = -a Fc``.

    Parameters
    ----------
    a : array_like
        Reversal amplitudes ``|F_i|/Fc`` in [0, 1].
    sigma_over_fc : float
        The ratio ``sigma/Fc`` [1/m] (with ``Fc = 1 N``).

    Returns
    -------
    numpy.ndarray
        ``x_{i+1} sigma/Fc`` [-]; negative or huge where the printed form breaks down
        (``sigma/Fc < 1``).
    """
    a = np.asarray(a, dtype=float)
    c = a - np.log1p(a)  # E_p sigma/Fc^2, (3.9)
    return c / (1.0 - (1.0 / sigma_over_fc) * (1.0 + a) ** -0.6)


def examples_dir() -> Path:
    """Directory holding the figure scripts: beside the package, else ``./examples``.

    Raises
    ------
    FileNotFoundError
        If neither place holds ``fig3_potential_energy.py``; names both places.
    """
    candidates = [Path(__file__).resolve().parent.parent / "examples", Path.cwd() / "examples"]
    for cand in candidates:
        if (cand / "fig3_potential_energy.py").is_file():
            return cand
    raise FileNotFoundError(
        "the figure scripts (examples/fig*.py) were not found in "
        + " or ".join(str(c) for c in candidates)
        + "; run 'prefriction paper' from the repository root or install with 'pip install -e .'"
    )


def load_example(name: str) -> ModuleType:
    """Import ``examples/<name>.py`` as a module (without putting ``examples`` on ``sys.path``)."""
    path = examples_dir() / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"prefriction_examples.{name}", path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load figure script {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_all(outdir: Path, *, quick: bool = False, log: Callable[[str], None] = print) -> dict:
    """Run every figure script into ``outdir``; return ``{name: result dict or Exception}``."""
    results: dict = {}
    width = max(len(n) for n in FIGURES)
    for k, name in enumerate(FIGURES, 1):
        start = time.perf_counter()
        try:
            results[name] = load_example(name).main(outdir, quick=quick)
            status = "ok"
        except Exception as exc:  # reported in the progress line and in report.md
            results[name] = exc
            status = "FAILED: " + "".join(traceback.format_exception_only(type(exc), exc)).strip()
        log(f"[{k:>2}/{len(FIGURES)}] {name:<{width}} {time.perf_counter() - start:6.2f} s  {status}")
    return results


def main(argv: list[str] | None = None) -> int:
    """Command line ``prefriction paper --out DIR [--quick]``; returns 0 if every figure ran."""
    parser = argparse.ArgumentParser(
        prog="prefriction paper",
        description="Reproduce the figures of Ruderman (2023), go past them, and write DIR/report.md.",
    )
    parser.add_argument("--out", required=True, type=Path, help="output directory (created if missing)")
    parser.add_argument("--quick", action="store_true", help="coarser grids and fewer reversals (for tests)")
    args = parser.parse_args(argv)
    from ._report import write_report

    start = time.perf_counter()
    results = run_all(args.out, quick=args.quick)
    total = time.perf_counter() - start
    report = write_report(args.out, results, seconds=total, quick=args.quick)
    failed = [n for n, r in results.items() if isinstance(r, Exception)]
    print(f"wrote {report} and {len(results) - len(failed)} figures in {total:.1f} s")
    if failed:
        print(f"failed: {', '.join(failed)}")
    return 1 if failed else 0
