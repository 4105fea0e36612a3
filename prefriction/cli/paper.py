"""``prefriction paper --out DIR``: reproduce the paper's figures, go past them, write a report.

Runs every script ``examples/fig*.py`` and ``examples/beyond_*.py`` (each has
``main(outdir, *, quick=False) -> dict``), prints one progress line per figure (name,
seconds), and writes ``DIR/report.md``: each figure with a caption, the key numbers, the
erratum in (3.13) and every place where the toolbox disagrees with the paper, with numbers.

The examples live in the source tree (``examples/``) and are installed with the package as
``prefriction/examples/`` (the symlink ``prefriction/examples -> ../examples`` in the tree), so
the command runs from an installed wheel as from the repository.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
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


def examples_dir() -> Path:
    """Directory holding the figure scripts: ``prefriction/examples`` (installed with the package),
    else ``./examples``.

    Raises
    ------
    FileNotFoundError
        If neither place holds ``fig3_potential_energy.py``; names both places.
    """
    candidates = [Path(__file__).resolve().parents[1] / "examples", Path.cwd() / "examples"]
    for cand in candidates:
        if (cand / "fig3_potential_energy.py").is_file():
            return cand
    raise FileNotFoundError(
        "the figure scripts (examples/fig*.py) were not found in "
        + " or ".join(str(c) for c in candidates)
        + "; reinstall prefriction (pip install .) or run 'prefriction paper' from the repository root"
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


def _fmt_pct(x: float) -> str:
    return f"{100.0 * x:+.2f} %"


def _captions(r: dict) -> dict[str, tuple[str, str]]:
    """Title and caption of every figure, with the numbers of its result dict where it ran."""

    def get(name: str) -> dict | None:
        val = r.get(name)
        return None if val is None or isinstance(val, Exception) else val

    out: dict[str, tuple[str, str]] = {}
    f2 = get("fig2_energy_balance")
    out["fig2_energy_balance"] = (
        "Figure 2: energy-balanced reversal points, from a simulation",
        "Branch of the simulated oscillator (2.1), Dahl gamma = 1, between its first reversal x_i "
        "(F_i < 0) and the second x_{i+1}; shaded: the areas Delta_1 (x_i to the force zero "
        "crossing x_0, returned as kinetic energy) and Delta_2 (x_0 to x_{i+1}, taken back). "
        + (f"Delta_1 = {f2['delta_1']:.6f} J, Delta_2 = {f2['delta_2']:.6f} J, E_p(F_i) (3.9) = "
           f"{f2['E_p']:.6f} J; by integrated power (2.8) the two integrals of (2.9) are "
           f"{f2['work_1']:.6f} J and {f2['work_2']:.6f} J (sum {f2['work_1'] + f2['work_2']:.1e} J). "
           if f2 else "")
        + "Parameters chosen (the paper's sketch has none): m = 1 kg, sigma = 1 N/m, Fc = 1 N, v(0) = -0.8 m/s.",
    )
    f3 = get("fig3_potential_energy")
    out["fig3_potential_energy"] = (
        "Figure 3: potential energy (3.9) at a reversal",
        "E_p = (Fc^2/sigma)(a - ln(1 + a)) against a = |F_i|/Fc on a log scale for sigma/Fc in "
        "{1, 10, 100, 1000} 1/m (Fc = 1 N, not stated in the paper). The curves are one curve "
        "shifted by log10(sigma/Fc). "
        + (f"Maximum at a = 1: {f3['E_p_max'][1.0]:.6f} J for sigma/Fc = 1, i.e. "
           f"{f3['E_p_max'][1.0] * 1.0 / f3['Fc'] ** 2:.6f} Fc^2/sigma (paper: 0.3069)." if f3 else ""),
    )
    f4 = get("fig4_omega")
    p4 = f4["panels"][1.0] if f4 else None
    out["fig4_omega"] = (
        "Figure 4: Omega (3.10) and its linear approximation Omega* (3.11)",
        "(a) Omega = exp(-sigma x/Fc) (black dashed) and Omega* = 1 - K x for F_i = -Fc x {0.2, ..., 1} "
        "at sigma/Fc = 1 1/m, Fc = 1 N (top axis: x at 8 1/m; the paper's panels for sigma/Fc = 1, 2, 8 "
        "1/m differ only by this scale); circles: exact next reversal, crosses: next reversal from the "
        "corrected (3.13). (b) The gap Omega* - Omega against sigma x/Fc: it vanishes at the secant "
        "crossing (diamonds), which the paper takes for the next reversal. (c) Error of the secant "
        "crossing and of the corrected (3.13) against the exact next reversal. "
        + (("Error of the crossing / of (3.13): "
            + ", ".join(f"|F_i|/Fc = {a:g}: {_fmt_pct(p4['x_cross'][a] / p4['x_exact'][a] - 1)} / "
                        f"{_fmt_pct(p4['x_approx'][a] / p4['x_exact'][a] - 1)}" for a in (1.0, 0.6, 0.2))
            + ".") if p4 else ""),
    )
    out["fig5_force_displacement"] = (
        "Figure 5: force-displacement curve between two reversals",
        "Branch (3.5) from the reversal x_i (3.8) at F_i = -Fc to the exact next reversal, for "
        "Fc in {1, 1.5, 2} N with sigma = 1 N/m (sigma and F_i not stated in the paper); crosses: "
        "the next reversal from the corrected (3.13).",
    )
    out["fig6_reversal_energy"] = (
        "Figure 6: potential energy at consecutive reversals",
        "(a) E_p(i+n) from the exact map and (3.14), first reversal at F_i = -Fc, sigma/Fc in "
        "{10, 100, 1000} 1/m (Fc = 1 N), with the asymptotic law 9 Fc^2/(8 sigma n^2) dashed. "
        "(b) Normalised: the exact sequence (one curve for every sigma/Fc) against the paper's "
        "recursion (3.13)+(3.14), corrected (grey) and as printed (red band from sigma/Fc = 10 1/m, "
        "upper edge, to 1000 1/m, lower edge; the printed recursion depends on sigma/Fc only slightly).",
    )
    f7 = get("fig7_energy_time_series")
    out["fig7_energy_time_series"] = (
        "Figure 7: energy time series of the simulated oscillator",
        "Kinetic energy and the magnitude of the restoring-force work (2.8), integrated from the "
        "last reversal, one panel for each sigma/Fc in {10, 100, 1000} 1/m; circles: E_p (3.9) of the preceding "
        "reversal, which each kinetic-energy peak must reach. m = 1 kg, Fc = 1 N, x(0) = F(0) = 0, "
        "v(0) = 0.1 m/s (not stated in the paper). "
        + (("Energy balance max |E_k + E_f - E_k(0)|/E_k(0): "
            + ", ".join(f"{k:g}: {v['balance']:.1e}" for k, v in f7["runs"].items())
            + "; kinetic-energy peaks against (3.9): max relative deviation "
            + ", ".join(f"{k:g}: {np.max(np.abs(v['E_k_peak'] / v['E_p_rev'][: len(v['E_k_peak'])] - 1)):.1e}"
                        for k, v in f7["runs"].items()) + ".") if f7 else ""),
    )
    out["beyond_map_vs_approximation"] = (
        "Beyond: exact reversal map against the approximation (3.13)",
        "Next reversal (distance from the zero crossing and force) from the exact map "
        "(Lambert W0) and from the corrected (3.13); right: relative error of the approximation, "
        "tending to 5/6 - 1 = -16.7 % as a -> 0.",
    )
    fc = get("beyond_convergence")
    out["beyond_convergence"] = (
        "Beyond: convergence of the reversal amplitudes, a_n ~ 3/(2n)",
        "Amplitudes a_n = |F_n|/Fc of the exact map from a_0 = 1 on log-log axes against 3/(2n) and "
        "the refined law 15k/(10k^2 - 1), k = n + n_0; right: 1/a_n - 2n/3, which stays bounded. "
        + (f"After {fc['n'][-1]:,.0f} reversals a_n = {fc['a'][-1]:.6e}, a_n/(3/(2n)) - 1 = "
           f"{fc['rel_dev'][-1]:.2e}, 1/a_n - 2n/3 = {fc['offset'][-1]:.4f}; n_0 = {fc['n0']:.4f}." if fc else ""),
    )
    fe = get("beyond_energy_envelope")
    out["beyond_energy_envelope"] = (
        "Beyond: the energy envelope of Figure 7 against the t^-2 law",
        "(a) Potential energy at the reversals against time (exact reference lines, simulated "
        "circles) with 9 pi^2 m Fc^2/(8 sigma^2 t^2); the law's two ingredients: (b) n^2 E_p sigma/Fc^2 "
        "-> 9/8 and (c) the half-cycle duration's excess over pi sqrt(m/sigma), -> 0. "
        + (("At the last exact reversal sigma^2 t^2 E_p / (9 pi^2 m Fc^2/8) = "
            + ", ".join(f"{k:g}: {(k ** 2 * v['t'][-1] ** 2 * v['E_p'][-1]) / fe['law_product']:.4f}"
                        for k, v in fe["exact"].items()) + " (sigma/Fc: value).") if fe else ""),
    )
    fg = get("beyond_gamma_loops")
    out["beyond_gamma_loops"] = (
        "Beyond: hysteresis loops for gamma in {0, 0.5, 1, 2}",
        "Force-displacement loops of the simulated oscillator, m = 1 kg, sigma = 1 N/m, Fc = 1 N, "
        "v(0) = 1.5 m/s. gamma = 0 (Prandtl stop) oscillates between -Fc and +Fc for ever after "
        "its first saturation; the larger gamma, the more each half-cycle dissipates. "
        + (("E_p after the last reversal: "
            + ", ".join(f"gamma = {g:g}: {v['E_p'][-1]:.3e} J" for g, v in fg["runs"].items()) + ".")
           if fg else ""),
    )
    return out


def _disagreements(r: dict) -> list[str]:
    """Places where the toolbox disagrees with the paper, each with numbers from the results."""

    def get(name: str) -> dict | None:
        val = r.get(name)
        return None if val is None or isinstance(val, Exception) else val

    items = []
    f5, bm = get("fig5_force_displacement"), get("beyond_map_vs_approximation")
    if f5 and bm:
        c15, c2 = f5["curves"][1.5], f5["curves"][2.0]
        items.append(
            "**(3.13) as printed is dimensionally inconsistent** (see the erratum). With sigma = 1 N/m, "
            f"F_i = -Fc it puts x_(i+1) at {c15['x_next_printed']:.3g} m for Fc = 1.5 N (exact "
            f"{c15['x_next']:.4f} m) and at {c2['x_next_printed']:.3g} m, on the wrong side, for Fc = 2 N "
            f"(exact {c2['x_next']:.4f} m); for sigma/Fc = 10 1/m its x_(i+1) is off by "
            f"{_fmt_pct(bm['table'][0][5])} at a = 1."
        )
    items.append(
        "**Lambert W is usable.** The paper (after (3.10)) sets it aside as multivalued; the real "
        "principal branch W0 gives the unique root x_(i+1) sigma/Fc = c + 1 + W0(-exp(-(1 + c))), "
        "c = E_p sigma/Fc^2, used by the toolbox as the exact map."
    )
    if bm:
        rows = {row[0]: row for row in bm["table"]}
        items.append(
            "**The approximation (3.11)-(3.13), even corrected, is not uniformly accurate.** Error of "
            f"x_(i+1): {_fmt_pct(rows[1.0][3])} at a = 1, {_fmt_pct(rows[0.6][3])} at 0.6, "
            f"{_fmt_pct(rows[0.2][3])} at 0.2, {_fmt_pct(rows[1e-4][3])} at 1e-4 (limit 5/6 - 1 = -16.67 %): "
            "it is good only for the first reversals from sliding, where the paper's Figure 4 looks."
        )
    f4 = get("fig4_omega")
    if f4:
        p = f4["panels"][1.0]
        items.append(
            "**Omega* does not meet Omega at the next reversal.** (3.11) is meant to satisfy "
            "Omega*(x_(i+1)) = Omega(x_(i+1)); the secant with K from (3.11) crosses Omega at "
            + ", ".join(f"x = {p['x_cross'][a]:.4f} (exact x_(i+1) = {p['x_exact'][a]:.4f}, (3.13): "
                        f"{p['x_approx'][a]:.4f})" for a in (1.0, 0.2))
            + " Fc/sigma for F_i = -Fc and -0.2 Fc."
        )
    f6 = get("fig6_reversal_energy")
    if f6:
        n = len(f6["n"]) - 1
        ex, co = f6["amplitudes"][-1], f6["amplitudes_corrected_313"][-1]
        rc = f6["ratio_consecutive"]
        pr = f6["amplitudes_printed_313"]
        items.append(
            "**The decay over reversals is algebraic, not exponential (Figure 6).** The ratio of "
            f"consecutive potential energies is {rc[0]:.3f} at the first reversal and {rc[-1]:.3f} after "
            f"{n}, tending to 1 (E_p ~ 9 Fc^2/(8 sigma n^2)). The paper's recursion (3.13)+(3.14) decays "
            f"geometrically (amplitude ratio -> 5/6): after {n} reversals it gives |F|/Fc = {co:.3e} "
            f"against the exact {ex:.3e} ({_fmt_pct(co / ex - 1)}); with (3.13) as printed it collapses "
            "hyperexponentially (|F|/Fc after 4 reversals: "
            + ", ".join(f"{k:g} 1/m: {v[min(4, n)]:.1e}" for k, v in pr.items()) + ")."
        )
    if f5:
        ratios = [c["x_next"] / abs(c["x_i"]) for c in f5["curves"].values()]
        items.append(
            "**|x_(i+1)| > |x_i| does not depend on sigma/Fc (Figure 5 remark).** Measured from the "
            "force zero crossing both distances scale with Fc/sigma; their ratio depends on "
            f"|F_i|/Fc only: {ratios[0]:.4f} at F_i = -Fc for every Fc, and > 1 for every amplitude "
            "(it tends to 1 as a -> 0)."
        )
    fe = get("beyond_energy_envelope")
    if fe:
        items.append(
            "**Figure 7's envelope is a power law in time, E ~ 9 pi^2 m Fc^2/(8 sigma^2 t^2),** not "
            "'supposedly hyperexponential'. A larger sigma/Fc dissipates faster in time because the "
            "half-cycle pi sqrt(m/sigma) is shorter (factor 1/sigma^2 at a given time), not because the "
            "shape changes: in normalised units all runs are one curve up to the initial energy "
            "sigma m v0^2/(2 Fc^2)."
        )
    return items


ERRATUM = """(3.13) as printed reads

    x_(i+1)(F_i) = E_p(F_i)/Fc * (1 - (Fc/sigma) (Fc/(Fc - F_i))^(3/5))^(-1).

Substituting Omega* = 1 - K x with K = (sigma/Fc) r^(3/5), r = Fc/(Fc - F_i), from (3.11) into
(3.12) gives (Fc^2/sigma)(1 - K x) + Fc x - Fc^2/sigma = E_p, i.e. x (Fc - (Fc^2/sigma) K) = E_p, so

    x_(i+1)(F_i) = E_p(F_i) / (Fc (1 - r^(3/5))).

The printed form carries an extra factor Fc/sigma [m] inside the bracket, where a pure number
belongs; the two agree only when sigma/Fc = 1 1/m. The toolbox implements the corrected form
(`prefriction.analysis.dahl.next_amplitude_paper`) and shows the printed one only to quantify the erratum."""


def write_report(outdir: Path, results: dict, *, seconds: float, quick: bool) -> Path:
    """Write ``outdir/report.md`` from the figure results; return its path."""
    from prefriction import dahl

    outdir = Path(outdir)
    lines = [
        "# Ruderman (2023) reproduced with prefriction",
        "",
        "M. Ruderman, *Energy dissipation and hysteresis cycles in pre-sliding transients of kinetic "
        "friction*, Applications of Mathematics 68 (2023) 845-860. Dahl model, gamma = 1 unless stated.",
        f"Generated by `prefriction paper --out {outdir}{' --quick' if quick else ''}` in {seconds:.1f} s.",
        "",
        "## Key numbers",
        "",
        f"- Largest potential energy at a reversal (a = |F_i|/Fc = 1): (1 - ln 2) Fc^2/sigma = "
        f"{float(dahl.potential_energy(-1.0, 1.0, 1.0)):.6f} Fc^2/sigma (paper: 0.3069; bound (2.12): 0.5).",
        "- Exact reversal map a -> a' (universal, independent of sigma, Fc, m): "
        + ", ".join(f"{a:g} -> {float(dahl.next_amplitude(a)):.7f}" for a in (1.0, 0.5, 0.1)) + ".",
        "- Convergence: a' = a - (2/3) a^2 + O(a^3), hence a_n ~ 3/(2n), E_p ~ 9 Fc^2/(8 sigma n^2) "
        "at the reversals, half-cycles -> pi sqrt(m/sigma), energy ~ 9 pi^2 m Fc^2/(8 sigma^2 t^2): "
        "slower than exponential, never finite-time.",
    ]
    fc = results.get("beyond_convergence")
    if isinstance(fc, dict):
        lines.append(
            f"- After {fc['n'][-1]:,.0f} reversals from a_0 = 1: a_n = {fc['a'][-1]:.6e}, "
            f"3/(2n) = {fc['law'][-1]:.6e} (relative deviation {fc['rel_dev'][-1]:.2e}); "
            f"1/a_n - 2n/3 = {fc['offset'][-1]:.4f} (bounded)."
        )
    bm = results.get("beyond_map_vs_approximation")
    if isinstance(bm, dict):
        lines += [
            "",
            "Error of the paper's approximation (3.13), corrected, against the exact map "
            "(next reversal at distance x_(i+1) from the zero crossing, force |F_(i+1)|):",
            "",
            r"| a = \|F_i\|/Fc | exact \|F_(i+1)\|/Fc | (3.13) \|F_(i+1)\|/Fc | error of x_(i+1) | "
            r"error of \|F_(i+1)\| | (3.13) as printed, sigma/Fc = 10 1/m: error of x_(i+1) |",
            "|---:|---:|---:|---:|---:|---:|",
        ]
        for a, e, p, ex, ef, epr in bm["table"]:
            lines.append(f"| {a:g} | {e:.7f} | {p:.7f} | {_fmt_pct(ex)} | {_fmt_pct(ef)} | {_fmt_pct(epr)} |")
    lines += ["", "## Erratum in (3.13)", "", ERRATUM, "", "## Where the toolbox disagrees with the paper", ""]
    lines += [f"{k}. {text}" for k, text in enumerate(_disagreements(results), 1)]
    lines += [
        "",
        "Agreements: the bound max E_p = 0.3069 Fc^2/sigma; the equal areas of (2.9) (Figure 2); "
        "the peak kinetic energy of each half-cycle equals (3.9) of the preceding reversal "
        "(Figure 7); the convergence is only asymptotic, slower than exponential in time.",
        "",
        "## Figures",
        "",
    ]
    captions = _captions(results)
    for name in FIGURES:
        title, caption = captions[name]
        res = results.get(name)
        lines.append(f"### {title}")
        lines.append("")
        if isinstance(res, Exception):
            lines.append(f"**Not produced**: `{type(res).__name__}: {res}`")
        else:
            lines.append(f"![{title}]({Path(res['png']).name})")
            lines.append("")
            lines.append(f"{caption} Script: `examples/{name}.py`.")
        lines.append("")
    path = outdir / "report.md"
    outdir.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def writable_dir(path: Path) -> str | None:
    """Create ``path`` if needed and check that a file can be written in it.

    Returns
    -------
    str or None
        ``None`` if it can, else the reason it cannot (from the operating system).
    """
    if path.exists() and not path.is_dir():
        return "it exists and is not a directory"
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        return exc.strerror or str(exc)
    return None


DESCRIPTION = """\
Reproduce the figures of Ruderman (2023), go past them, and write DIR/report.md.

Runs every figure script (examples/fig*.py and examples/beyond_*.py), prints one
line per figure (name, seconds, ok or the error), and writes DIR/<figure>.png and
DIR/report.md: captions, key numbers, the erratum in (3.13) and every place where
the toolbox disagrees with the paper. Exit code 0 if every figure ran, 1 if some
failed, 2 for bad options (e.g. a DIR that cannot be written)."""


def main(argv: list[str] | None = None) -> int:
    """Command line ``prefriction paper --out DIR [--quick]``; returns 0 if every figure ran.

    Exits with code 2 (argparse's usage error) if ``--out`` is missing or cannot be written.
    """
    parser = argparse.ArgumentParser(
        prog="prefriction paper", description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--out", required=True, type=Path, metavar="DIR",
                        help="output directory for the PNG files and report.md (created if missing)")
    parser.add_argument("--quick", action="store_true", help="coarser grids and fewer reversals (for tests)")
    args = parser.parse_args(argv)
    problem = writable_dir(args.out)
    if problem is not None:
        parser.error(f"argument --out: cannot write to {str(args.out)!r}: {problem}")
    try:
        where = examples_dir()
    except FileNotFoundError as exc:
        print(f"prefriction paper: {exc}", file=sys.stderr)
        return 2
    print(f"figure scripts: {where}")
    start = time.perf_counter()
    results = run_all(args.out, quick=args.quick)
    total = time.perf_counter() - start
    report = write_report(args.out, results, seconds=total, quick=args.quick)
    failed = [n for n, r in results.items() if isinstance(r, Exception)]
    print(f"wrote {report} and {len(results) - len(failed)} figures in {total:.1f} s")
    if failed:
        print(f"failed: {', '.join(failed)}")
    return 1 if failed else 0
