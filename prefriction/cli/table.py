"""``prefriction table``: the exact reversal table of an unforced Dahl oscillator.

Prints the reversals of :func:`prefriction.exact_reversals` for one case (default: sigma =
1e4 N/m, Fc = 1 N, m = 1 kg, gamma = 1, v0 = 0.01 m/s, i.e. a first excursion storing
``sigma m v0^2 / (2 Fc^2) = 0.5`` in units ``Fc^2 / sigma``), the check of the bound (2.12)
and the normalised reversal map ``|F_i| / Fc -> |F_{i+1}| / Fc`` (3.14).
"""

from __future__ import annotations

import argparse
import math
import re

import numpy as np

from prefriction import dahl
from prefriction._validation import check_count
from prefriction.analysis.exact import MAX_REVERSALS, exact_reversals
from prefriction.models import Dahl, Oscillator
from prefriction.reversals import ReversalTable


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="prefriction table",
        description="Exact reversal table of the unforced Dahl oscillator m x'' + F = 0 (paper (2.1), (3.2)).",
    )
    p.add_argument("--sigma", type=float, default=1e4, help="rest stiffness sigma [N/m] > 0 (default 1e4)")
    p.add_argument("--Fc", type=float, default=1.0, help="Coulomb force Fc [N] > 0 (default 1)")
    p.add_argument("--mass", type=float, default=1.0, help="mass m [kg] > 0 (default 1)")
    p.add_argument("--gamma", type=float, default=1.0, help="Dahl shape factor gamma >= 0 (default 1)")
    p.add_argument("--v0", type=float, default=0.01, help="initial velocity [m/s] (default 0.01)")
    p.add_argument("--F0", type=float, default=0.0, help="initial friction force [N], |F0| <= Fc (default 0)")
    p.add_argument("--x0", type=float, default=0.0, help="initial position [m] (default 0)")
    p.add_argument("--n", type=int, default=20, help=f"number of reversals, 1 to {MAX_REVERSALS:_} (default 20)")
    p.add_argument("--rows", type=int, default=20, help="rows printed, >= 1: first and last halves (default 20)")
    return p


# the options behind the arguments of Dahl, Oscillator and exact_reversals, for their messages
_OPTIONS = {"sigma": "--sigma", "Fc": "--Fc", "mass": "--mass", "gamma": "--gamma", "v0": "--v0", "F0": "--F0",
            "x0": "--x0", "n": "--n", "rows": "--rows"}


def report(system: Oscillator, table: ReversalTable, v0: float, F0: float, rows: int = 20) -> str:
    """Readable text: case, reversal table, bound (2.12) and the normalised map.

    Parameters
    ----------
    system : Oscillator
        The unforced oscillator with :class:`Dahl` friction.
    table : ReversalTable
        Its reversals, e.g. from :func:`prefriction.exact_reversals`.
    v0 : float
        Initial velocity [m/s] (for the header).
    F0 : float
        Initial friction force [N] (for the header).
    rows : int, default 20
        Number of table rows printed.

    Returns
    -------
    str
        The report, lines separated by newlines.
    """
    fr = system.friction
    sigma, Fc, gamma, m = fr.sigma, fr.Fc, fr.gamma, system.mass
    c = sigma * m * v0 * v0 / (2.0 * Fc * Fc)
    lines = [
        f"Unforced Dahl oscillator: sigma = {sigma:g} N/m, Fc = {Fc:g} N, gamma = {gamma:g}, m = {m:g} kg",
        f"Initial state: v0 = {v0:g} m/s, F0 = {F0:g} N; kinetic energy sigma m v0^2/(2 Fc^2) = {c:.6g} Fc^2/sigma",
        f"Units: Fc/sigma = {Fc / sigma:.6g} m, sqrt(m/sigma) = {math.sqrt(m / sigma):.6g} s, "
        f"Fc^2/sigma = {Fc * Fc / sigma:.6g} J",
        "",
        "Exact reversals: t time, x position, F friction force at the reversal, E_p potential energy",
        "((3.9) for gamma = 1), E_d energy dissipated in the half-cycle ending there (2.10);",
        f"initial energy E_0 = {table.E_0:.6e} J",
        "",
        table.format(max_rows=rows),
        "",
    ]
    bound = Fc * Fc / (2.0 * sigma)
    worst = float(np.max(table.E_p))
    lines.append(
        f"Bound (2.12): max E_p = {worst:.6e} J <= Fc^2/(2 sigma) = {bound:.6e} J: "
        f"{'holds' if worst <= bound else 'VIOLATED'} (margin {1.0 - worst / bound:.2%})"
    )
    if gamma == 1.0:
        lines.append(
            f"  sharp form for gamma = 1: (1 - ln 2) Fc^2/sigma = {dahl.max_potential_energy(sigma, Fc):.6e} J"
        )
    a = np.abs(table.F) / Fc
    if len(a) >= 2:
        k = min(len(a) - 1, 4)
        pairs = ", ".join(f"{a[i]:.7f} -> {a[i + 1]:.7f}" for i in range(k))
        lines.append("Normalised map |F_i|/Fc -> |F_(i+1)|/Fc (3.14), independent of sigma, Fc and m:")
        lines.append(f"  {pairs}, ...")
        if gamma == 1.0:
            n = len(a)
            lines.append(
                f"  after {n} reversals |F_n|/Fc = {a[-1]:.6g}; asymptotic law 3/(2n) gives {1.5 / n:.6g}, "
                f"with corrections {float(dahl.asymptotic_amplitude(n - 1, a0=float(a[0]))):.6g}"
            )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``prefriction table``; returns the exit code (0 on success, 2 on bad input).

    A value that is not a number exits through argparse (``SystemExit`` with code 2); a number
    out of range prints a message naming the option, its value and the allowed range.
    """
    args = _parser().parse_args(argv)
    try:
        check_count("rows", args.rows, minimum=1)
        system = Oscillator(Dahl(args.sigma, args.Fc, args.gamma), mass=args.mass)
        table = exact_reversals(system, args.v0, args.n, x0=args.x0, F0=args.F0)
    except (TypeError, ValueError) as exc:
        message = str(exc)
        named = [opt for name, opt in _OPTIONS.items() if re.match(rf"{name}\b", message)]
        print(f"prefriction table: error: {named[0] + ': ' if named else ''}{message}")
        return 2
    print(report(system, table, args.v0, args.F0, rows=args.rows))
    return 0
