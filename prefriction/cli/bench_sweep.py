"""The former module of ``prefriction bench --sweep``, now the package :mod:`prefriction.cli.bench.sweep`.

Kept so that ``import prefriction.cli.bench_sweep`` and ``python -m prefriction.cli.bench_sweep``
go on working; every name is that of :mod:`prefriction.cli.bench.sweep`.
"""

import sys

from prefriction.cli.bench.sweep import (ChildRun, ScipyResult, SweepCase, SweepRow, exact_tables, format_table, main,
                                         match_notes, matched_rtol, measure_case, reversal_error, run_child, scipy_peer,
                                         scipy_reversals, sweep_cases, targets, worker, write_csv)

__all__ = ["ChildRun", "ScipyResult", "SweepCase", "SweepRow", "exact_tables", "format_table", "main", "match_notes",
           "matched_rtol", "measure_case", "reversal_error", "run_child", "scipy_peer", "scipy_reversals",
           "sweep_cases", "targets", "worker", "write_csv"]

if __name__ == "__main__":
    sys.exit(main())
