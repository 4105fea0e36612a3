"""Command line: ``prefriction {table,bench,paper} ...``.

Each subcommand lives in its own module, imported only when it runs, with a
``main(argv) -> int`` entry point that parses its own options.
"""

from __future__ import annotations

import importlib
import os
import sys

COMMANDS = {
    "table": ("prefriction.cli.table", "exact reversal table of an unforced Dahl oscillator"),
    "bench": ("prefriction.cli.bench", "error against run time of simulate and its peers"),
    "paper": ("prefriction.cli.paper", "reproduce the paper's figures and write a report"),
}


def main(argv: list[str] | None = None) -> int:
    """Dispatch ``argv`` (default ``sys.argv[1:]``) to a subcommand; return its exit code.

    ``-h``/``--help`` prints the usage and returns 0; no command or an unknown one prints an
    error to stderr and returns 2 (the argparse convention).
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if not args:  # argparse convention: a missing command is a usage error
        print(_usage() + "\nprefriction: error: a command is required", file=sys.stderr)
        return 2
    if args[0] in ("-h", "--help"):
        print(_usage())
        return 0
    if args[0] == "--version":
        from prefriction import __version__

        print(f"prefriction {__version__}")
        return 0
    name, rest = args[0], args[1:]
    if name not in COMMANDS:
        print(f"prefriction: unknown command {name!r}; choose one of {', '.join(COMMANDS)}", file=sys.stderr)
        return 2
    module = importlib.import_module(COMMANDS[name][0])
    try:
        code = int(module.main(rest) or 0)
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (prefriction table | head): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
        return 0
    return code


def _usage() -> str:
    """The usage text: every command with its one-line description."""
    lines = ["usage: prefriction COMMAND [options]", "", "commands:"]
    lines += [f"  {name:<8} {text}" for name, (_, text) in COMMANDS.items()]
    lines += ["", "'prefriction COMMAND --help' shows the options of a command; 'prefriction --version' the version."]
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
