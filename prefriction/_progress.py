"""Progress lines on stderr: rewritten in place on a terminal, one line per event in a log."""

from __future__ import annotations

import sys

__all__ = ["ProgressLine"]


class ProgressLine:
    """A progress line on ``sys.stderr``.

    On a terminal each :meth:`show` rewrites the line (``\\r``) and :meth:`close` ends it; when
    stderr is a file or a pipe each :meth:`show` writes one whole line, so progress does not run
    into other messages in a log.
    """

    def __init__(self) -> None:
        self.width = 0
        self.open = False

    def show(self, text: str) -> None:
        """Write ``text`` as the current progress."""
        err = sys.stderr
        if _is_terminal(err):
            err.write("\r" + text.ljust(self.width))
            self.width = max(self.width, len(text))
            self.open = True
        else:
            err.write(text + "\n")
        err.flush()

    def close(self) -> None:
        """End the line on a terminal (nothing to do in a log)."""
        if self.open:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.open = False


def _is_terminal(stream: object) -> bool:
    try:
        return bool(stream.isatty())  # type: ignore[attr-defined]
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False
