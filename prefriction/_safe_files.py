"""Files the toolbox loads or writes are its user's own: no link followed, nothing another user wrote.

Every loader and writer of the compile cache (:mod:`prefriction.simulation.library_store`) and
every file an export writes (:mod:`prefriction.export`) goes through these primitives:

- :func:`make_private_dir` creates a directory and every missing parent with mode 0700,
  whatever the umask;
- :func:`dir_problem` says why a directory cannot be trusted: it (and every parent, through
  links too) must be owned by this user (or, for a parent, by root) and not writable by group
  or others (a parent may be world-writable with the sticky bit, as ``/tmp``);
- :func:`read_owned` reads a file without following a link (``O_NOFOLLOW``) and refuses one
  that is not a regular file of this user, or that group or others can write;
- :func:`write_atomic` writes a new temporary file (``O_EXCL``, through :func:`tempfile.mkstemp`)
  beside the destination and renames it over it, so a reader never sees half a file and a
  link planted at the destination is replaced, never followed;
- :func:`open_lock` opens a lock file without following a link, and only if it is this user's;
- :func:`output_dir` checks and creates the directory a writer was given (an export's
  ``directory``, a figure's ``outdir``), with errors naming that argument;
- :func:`printable` turns text read from a file (a note of an earlier process) into data fit to
  print: one line of printable ASCII, escapes and control characters shown as ``?``.

Ownership is compared with :func:`os.geteuid`, so a process running as root trusts only root's
files. Without ``os.geteuid`` (Windows) there are no owners to compare and only the link rules apply.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["UnsafeFile", "dir_problem", "make_private_dir", "open_lock", "output_dir", "printable",
           "read_nofollow", "read_owned", "write_atomic"]

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)  # a FIFO planted in place of a file must not block the open


class UnsafeFile(OSError):
    """A file that is not this user's own, or a link where a file was expected (the message says which)."""


def _euid() -> int | None:
    return os.geteuid() if hasattr(os, "geteuid") else None


def _who(uid: int) -> str:
    try:
        import pwd

        return f"user {pwd.getpwuid(uid).pw_name!r} (uid {uid})"
    except (ImportError, KeyError):
        return f"uid {uid}"


def _owner_problem(path: Path, st: os.stat_result, parent: bool = False) -> str:
    """Why the file or directory ``path`` with status ``st`` is not trusted (``""`` if it is)."""
    me = _euid()
    if me is None:
        return ""
    if st.st_uid != me and not (parent and st.st_uid == 0):
        return f"{path} is owned by {_who(st.st_uid)}, not by this process's user (uid {me})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        if parent and stat.S_ISDIR(st.st_mode) and st.st_mode & stat.S_ISVTX:
            return ""  # a sticky directory such as /tmp: others cannot rename or remove our entries
        return f"{path} is writable by {'others' if st.st_mode & stat.S_IWOTH else 'its group'} (mode {stat.S_IMODE(st.st_mode):o})"
    return ""


def dir_problem(path: Path) -> str:
    """Why the existing directory ``path`` cannot hold files this process loads (``""`` if it can).

    ``path`` itself must be a directory owned by this user that neither group nor others can
    write; each parent (of the path as given and of the path its links lead to) must be owned by
    this user or root and not writable by group or others unless it is sticky (``/tmp``).
    """
    path = Path(os.path.abspath(path))
    try:
        st = os.stat(path)
    except OSError as exc:
        return f"{path} cannot be examined ({exc.strerror or exc})"
    if not stat.S_ISDIR(st.st_mode):
        return f"{path} is not a directory"
    problem = _owner_problem(path, st)
    if problem:
        return problem
    real = Path(os.path.realpath(path))
    for parent in dict.fromkeys([*path.parents, *([real] if real != path else []), *real.parents]):
        try:
            problem = _owner_problem(parent, os.stat(parent), parent=parent != real)
        except OSError as exc:
            return f"{parent} cannot be examined ({exc.strerror or exc})"
        if problem:
            return problem
    return ""


def make_private_dir(path: Path) -> None:
    """Create the directory ``path`` and every missing parent with mode 0700 (the umask notwithstanding).

    Raises ``OSError`` if a component cannot be created or is not a directory; existing
    directories are left as they are (:func:`dir_problem` judges them).
    """
    path = Path(os.path.abspath(path))
    missing = []
    for p in [path, *path.parents]:
        if os.path.isdir(p):
            break
        missing.append(p)
    for p in reversed(missing):
        try:
            os.mkdir(p, 0o700)
        except FileExistsError:
            if not os.path.isdir(p):
                raise
            continue
        os.chmod(p, 0o700)  # mkdir's mode is reduced by the umask


def read_nofollow(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, read without following a link (whoever owns it).

    Raises :class:`UnsafeFile` if ``path`` is a link, not a regular file or longer than ``limit``
    bytes; ``OSError`` (e.g. ``FileNotFoundError``) if it cannot be opened.
    """
    return _read(path, limit, owned=False)


def read_owned(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, read without following a link.

    Raises :class:`UnsafeFile` if ``path`` is a link, not a regular file, not owned by this user,
    writable by group or others, or longer than ``limit`` bytes; ``OSError`` (e.g.
    ``FileNotFoundError``) if it cannot be opened.
    """
    return _read(path, limit, owned=True)


def _open_nofollow(path: Path, flags: int) -> int:
    """``os.open(path, flags)`` (new files 0600) without following a link, non-blocking, not inherited.

    Raises :class:`UnsafeFile` if ``path`` is a symbolic link; the ``OSError`` of the open otherwise.
    """
    try:
        return os.open(path, flags | _NOFOLLOW | _CLOEXEC | _NONBLOCK, 0o600)
    except OSError as exc:
        if os.path.islink(path):
            raise UnsafeFile(f"{path} is a symbolic link (not followed)") from exc
        raise


def _read(path: Path, limit: int, owned: bool) -> bytes:
    fd = _open_nofollow(path, os.O_RDONLY)
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise UnsafeFile(f"{path} is not a regular file")
        problem = _owner_problem(Path(path), st) if owned else ""
        if problem:
            raise UnsafeFile(problem)
        if st.st_size > limit:
            raise UnsafeFile(f"{path} holds {st.st_size} bytes, more than the {limit} expected")
        data = fh.read(st.st_size + 1)   # not read(limit + 1): that allocates the limit (a GiB for a library)
        if len(data) > st.st_size:       # grown since fstat: the rest, up to one byte past the limit
            data += fh.read(limit + 1 - len(data))
    if len(data) > limit:
        raise UnsafeFile(f"{path} holds more than the {limit} bytes expected")
    return data


def write_atomic(dest: Path, data: bytes, mode: int = 0o600) -> None:
    """Write ``data`` to ``dest`` through a new temporary file in its directory and a rename.

    The temporary file is created with ``O_EXCL`` (never an existing file or a link), given
    ``mode`` exactly, flushed to disk and renamed over ``dest``: a link at ``dest`` is replaced,
    not followed. Raises ``OSError`` if it cannot.
    """
    fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", dir=dest.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            if hasattr(os, "fchmod"):
                os.fchmod(fh.fileno(), mode)
            os.fsync(fh.fileno())
        os.replace(tmp, dest)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def open_lock(path: Path) -> int:
    """A descriptor of the lock file ``path`` (created 0600 if missing), opened without following a link.

    Raises :class:`UnsafeFile` if it is a link, not a regular file or not this user's own;
    ``OSError`` if it cannot be opened.
    """
    fd = _open_nofollow(path, os.O_RDWR | os.O_CREAT)
    st = os.fstat(fd)
    problem = "" if stat.S_ISREG(st.st_mode) else f"{path} is not a regular file"
    problem = problem or _owner_problem(path, st)
    if problem:
        os.close(fd)
        raise UnsafeFile(problem)
    return fd


def output_dir(directory: object, argument: str = "directory") -> Path:
    """``directory`` as a :class:`~pathlib.Path`, created with its missing parents if needed.

    Parameters
    ----------
    directory : str or os.PathLike
        The directory a writer was given (``"."`` for the working directory).
    argument : str, default "directory"
        The name of the caller's argument, used in the error messages.

    Raises
    ------
    TypeError
        If ``directory`` is not a str or path.
    ValueError
        If it is empty, names an existing file, or cannot be created (the reason from the
        operating system); each message names ``argument`` and the value.
    """
    if not isinstance(directory, (str, os.PathLike)):
        raise TypeError(f"{argument} must be a str or pathlib.Path, got {type(directory).__name__} {directory!r}")
    if str(directory) == "":
        raise ValueError(f"{argument} must name a directory, got '' (use '.' for the working directory)")
    path = Path(directory)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{argument} must be a directory, got the file {str(path)!r}")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"{argument} {str(path)!r} cannot be created ({exc.strerror or exc})") from exc
    return path


def printable(text: str, limit: int = 300) -> str:
    """``text`` as one line of printable ASCII of at most ``limit`` characters (others shown as ``?``)."""
    line = "".join(c if " " <= c <= "~" else "?" for c in " ".join(text.split()))
    return line if len(line) <= limit else line[: limit - 3] + "..."
