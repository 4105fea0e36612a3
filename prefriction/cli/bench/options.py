"""Command-line options of ``prefriction bench`` and their checks (``docs/bench.md``).

Every option is checked while it is parsed: a bad value is an argparse error (exit status 2)
naming the option, the value and the allowed range, before anything runs.
"""

from __future__ import annotations

import argparse
from pathlib import Path

MAX_REPEATS = 1000
DEFAULT_OUT = "bench_out"

_DESCRIPTION = """\
Measure the accuracy of prefriction.simulate against its run time, next to scipy solve_ivp
and python-control on the same equations, on the headline case (sigma/Fc = 1e4, m = 1 kg,
v0 = 1 m/s) and on stiff and extreme cases; print the tables and the three targets.

The error of a run is the largest relative error of the reversal times, positions and forces
over the first 50 reversals against the exact reversal table. Run times are warm (compiled
code loaded; the minimum of repeated runs). Exit status 0 only if every target passes.
Definitions, cases and targets: docs/bench.md."""

_EPILOG = """\
output (in --out): bench.csv (every measured point), work_precision.png, stability.txt;
  with --models models.csv, with --sweep sweep.csv; --loops prints its table only

examples:
  prefriction bench --quick          two tolerances, one repeat, 500 long reversals
  prefriction bench --along          friction_along per 100,000 samples against scipy
  prefriction bench --stability      simulate only: stiff and extreme cases, no peers
  prefriction bench --repeats 9      more warm repeats per point
  prefriction bench --models         Maxwell-slip, LuGre and GMS against scipy
  prefriction bench --sweep          parameter sweeps in cold and warm processes
  prefriction bench --elements       Maxwell-slip and GMS compile and cost against the element count
  prefriction bench --loops          compiled PID loop against python-control
  prefriction bench --compensation   PID alone against PID with each friction compensator
                                     (writes compensation_*.png to --out)
  prefriction bench --export         exported C code: ns per step against friction_along
  prefriction bench --identify       fit success rate, interval coverage, time and memory
  prefriction bench --emps DIR       identification routes on the EMPS benchmark files in DIR"""


def repeats(text: str) -> int:
    """``--repeats``: an integer in [1, :data:`MAX_REPEATS`].

    Raises
    ------
    argparse.ArgumentTypeError
        If ``text`` is not such an integer.
    """
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 1 <= value <= MAX_REPEATS or str(value) != text.strip().lstrip("+"):
        raise argparse.ArgumentTypeError(f"must be an integer in [1, {MAX_REPEATS}], got {text!r}")
    return value


def out_dir(text: str) -> Path:
    """``--out`` of the bench commands: a directory path (created later if missing).

    Raises
    ------
    argparse.ArgumentTypeError
        If ``text`` is empty or names an existing file that is not a directory.
    """
    path = Path(text)
    if not text.strip():
        raise argparse.ArgumentTypeError("must be a directory path, got an empty string")
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"must be a directory, got {text!r}, an existing file")
    return path


def make_out_dir(ap: argparse.ArgumentParser, path: Path) -> Path:
    """Create the ``--out`` directory (and its parents) now, so that a path that cannot be a
    directory is an option error before anything runs, not a failure after the measurements.

    Returns
    -------
    pathlib.Path
        ``path``, an existing directory.

    Raises
    ------
    SystemExit
        Status 2 (``ap.error``) naming ``--out``, the path and the reason.
    """
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        ap.error(f"argument --out: cannot create the directory {str(path)!r}: {exc.strerror or exc}")
    return path


def parse(argv: list[str] | None) -> argparse.Namespace:
    """Parse and check the options of ``prefriction bench``.

    Parameters
    ----------
    argv : list of str or None
        The options (None: ``sys.argv[1:]``).

    Returns
    -------
    argparse.Namespace
        ``out`` (pathlib.Path, an existing directory; None with ``--loops``), ``quick``, ``repeats`` (int or None), and at most one of
        ``stability``, ``models``, ``sweep``, ``elements``, ``loops``, ``compensation``, ``identify`` set.

    Raises
    ------
    SystemExit
        With status 2 and the argparse message on a bad option; with status 0 after ``--help``.
    """
    ap = argparse.ArgumentParser(prog="prefriction bench", description=_DESCRIPTION, epilog=_EPILOG,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, type=out_dir, metavar="DIR",
                    help=f"output directory, created if missing (default: {DEFAULT_OUT})")
    ap.add_argument("--quick", action="store_true",
                    help="small run: two tolerances, one repeat, 500 long reversals")
    ap.add_argument("--repeats", type=repeats, default=None, metavar="N",
                    help=f"warm repeats per point, 1..{MAX_REPEATS}; the minimum time is kept "
                         "(default: 5, 1 with --quick)")
    what = ap.add_mutually_exclusive_group()
    what.add_argument("--along", action="store_true",
                      help="instead: friction_along, warm time per 100,000 samples per model and error against "
                           "scipy references restarted at every interval and event (docs/along.md#speed)")
    what.add_argument("--stability", action="store_true",
                      help="simulate only: the stiff and extreme cases, no peers (target 2 not measured)")
    what.add_argument("--models", action="store_true",
                      help="instead: Maxwell-slip, LuGre and GMS, error against run time next to scipy "
                           "Radau, BDF, LSODA and DOP853 with restarts at every event")
    what.add_argument("--sweep", action="store_true",
                      help="instead: parameter sweeps, compiles and end-to-end time of cold and warm "
                           "processes against scipy DOP853")
    what.add_argument("--elements", action="store_true",
                      help="instead: Maxwell-slip and GMS with 3 to 100 elements, compile time and cost "
                           "per reversal (target: linear in the element count)")
    what.add_argument("--loops", action="store_true",
                      help="instead: the positioning-loop benchmark (python -m prefriction.controllers.benchmark): "
                           "compiled PID loop against python-control, tuning sweep, loop lengths; "
                           "--repeats sets its warm repeats (default 3)")
    what.add_argument("--compensation", action="store_true",
                      help="instead: PID alone against PID with each friction compensator (feedforward, LuGre, "
                           "friction and disturbance observers) on Dahl, LuGre and GMS stages, nominal, mismatched "
                           "and quantised (docs/compensation.md#bench)")
    what.add_argument("--export", action="store_true",
                      help="instead: ns per step of the exported C code (prefriction.export) against friction_along "
                           "and FrictionStream, and the exported plant and loop; --repeats sets its passes (default 5)")
    what.add_argument("--native", action="store_true",
                      help="instead: every run kind of the native driver (unforced, forced, Samples, dense) against "
                           "the plain-C and numba references written from the equations, at matched error, in the "
                           "same run (docs/bench.md#native)")
    what.add_argument("--identify", action="store_true",
                      help="instead: success rate of Motion fits against the start distance (x1.25-x2, seeded, "
                           "per synthetic stage, time and peak memory), coverage of the 95 %% intervals, cost of "
                           "force-displacement fits against the samples, and time and peak memory of a closed-loop "
                           "Motion fit against the samples (1e3, 5e3, 2.5e4; --quick: fewer fits, 500-2000 samples)")
    what.add_argument("--emps", default=None, metavar="DIR",
                      help="instead: the identification routes on the EMPS benchmark files in DIR (DATA_EMPS.mat, "
                           "DATA_EMPS_PULSES.mat; not shipped), docs/identify_closed_loop.md#emps")
    args = ap.parse_args(argv)
    if args.compensation and (args.quick or args.repeats is not None):
        ap.error("--quick and --repeats do not apply to --compensation")
    if args.export and (args.quick or args.out is not None):
        ap.error("--quick and --out do not apply to --export (it writes no files; its table goes to stdout)")
    if args.repeats is not None and (args.sweep or args.models or args.elements):
        ap.error("--repeats applies to the headline and stability sections, not to --sweep, --models or --elements")
    if args.loops and args.quick:
        ap.error("--quick does not apply to --loops (the loop benchmark has no quick mode; "
                 "python -m prefriction.controllers.benchmark --help lists its sizes)")
    if args.loops and args.out is not None:
        ap.error("--out does not apply to --loops (it writes no files; its table goes to stdout)")
    if not (args.loops or args.export):
        args.out = make_out_dir(ap, Path(DEFAULT_OUT) if args.out is None else args.out)
    return args
