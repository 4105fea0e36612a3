"""``prefriction bench --emps DIR``: the identification routes on the EMPS benchmark (opt-in).

Runs :func:`prefriction.identify.emps.benchmark` on the user's copy of the EMPS files in ``DIR``
(``DATA_EMPS.mat``, ``DATA_EMPS_PULSES.mat``; no data ship with the toolbox) and prints the
route-by-route table of ``docs/identify.md#closed-loop-records``: each route's mass, viscous, Coulomb and offset
with 95 % intervals (a check mark where the interval holds the published value), and the
benchmark's open-loop RMSE on the pulses record against the published rigid-body inverse model
in the same replay. Verdict PASS if the published inverse model is reproduced to its printed
digits, and some dynamic friction model holds the four published values in its intervals from
every start and beats the rigid body's RMSE.
"""

from __future__ import annotations

import sys

__all__ = ["main"]


def main(directory: str) -> int:
    """Run the benchmark on ``directory``; 0 if the verdict passes (module docstring)."""
    from prefriction.identify.emps import PUBLISHED, benchmark, format_table

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    try:
        rows = benchmark(directory, progress=say)
    except ValueError as exc:
        print(f"prefriction bench --emps: {exc}", file=sys.stderr)
        return 2
    print(format_table(rows))
    rigid = next(r for r in rows if r.route == "inverse" and r.model.startswith("rigid body (C"))
    published = next(r for r in rows if r.route == "published")
    digits = all(round(rigid.estimates[n][0], 4) == round(v, 4) for n, v in PUBLISHED.items())
    dynamic = [r for r in rows if r.route in ("inverse", "closed-loop") and r.model == "Dahl + Viscous"]
    holds = all(all(r.holds().values()) for r in dynamic if r.route == "inverse")
    beats = any(r.rmse < published.rmse for r in dynamic)
    print(f"published inverse model reproduced to 4 decimals: {digits}; Dahl + Viscous (inverse route) holds the "
          f"published M, Fv, Fc, offset from every start: {holds}; beats the rigid body's "
          f"{1e3 * published.rmse:.3f} mm: {beats}  {'PASS' if digits and holds and beats else 'FAIL'}")
    return 0 if digits and holds and beats else 1
