"""The compile cache trusts only its owner (issue 26, items 1, 2, 4 and 13).

Each attack plants, as "another user", what the issue's reproducers planted: a library whose
constructor writes a marker file (with a matching checksum beside it) in a cache directory
owned by another uid or writable by everyone, a lock that is a symbolic link, a failure note
full of terminal escapes. A new process then runs the issue's reproducer with that cache: the
marker must never appear, nothing outside the cache may be created, the numbers must be right
(against the closed form of the first Dahl reversal) and stderr must say once why the cache was
refused. Ownership is compared with the effective uid, so the tests hold as root (CI) too: as
root, "another user" is uid 12345 (``os.chown``).
"""

from __future__ import annotations

import functools
import os
import shutil
import stat
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import pytest

VICTIM = textwrap.dedent(
    """
    import prefriction as pf
    r = pf.simulate(pf.Oscillator(pf.Dahl(1e4, 1)), 1, reversals=5)
    print(repr(float(r.reversals.F[1])), r.stats.jit)
    """
)
EVIL = r"""
#include <stdio.h>
__attribute__((constructor)) static void planted(void) {
  FILE *f = fopen("@MARKER@", "w");
  if (f) { fputs("planted code ran\n", f); fclose(f); }
}
"""
OTHER_UID = 12345


def _env(cache: Path, **extra: str) -> dict:
    env = {**os.environ, "PREFRICTION_CACHE": str(cache), **extra}
    env.pop("PREFRICTION_NO_JIT", None)
    return env


def _victim(cache: Path, **extra: str) -> subprocess.CompletedProcess:
    out = subprocess.run([sys.executable, "-c", VICTIM], env=_env(cache, **extra), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return out


@pytest.fixture(scope="module")
def native_name(tmp_path_factory) -> str:
    """The file name of the native Dahl library the victim loads (from a clean cache of ours)."""
    if shutil.which(os.environ.get("CC", "gcc")) is None:
        pytest.skip("no C compiler: nothing is compiled or loaded")
    cache = tmp_path_factory.mktemp("clean")
    _victim(cache)
    (lib,) = cache.glob("native_dahl_*.so")
    return lib.name


def _plant(directory: Path, name: str, marker: Path) -> Path:
    """A library with a constructor that writes ``marker``, stored as ``name`` with a matching checksum."""
    import hashlib

    directory.mkdir(parents=True, exist_ok=True)
    src = directory.parent / "evil.c"
    src.write_text(EVIL.replace("@MARKER@", str(marker)))
    lib = directory / name
    subprocess.run([shutil.which(os.environ.get("CC", "gcc")), "-shared", "-fPIC", str(src), "-o", str(lib)],
                   check=True, capture_output=True)
    key = name[len("native_dahl_"):-len(".so")]
    lib.with_name(name + ".sha256").write_text(f"{hashlib.sha256(lib.read_bytes()).hexdigest()} {key}\n")
    return lib


def _chown_tree(path: Path, uid: int) -> None:
    os.chown(path, uid, uid)
    for p in path.iterdir():
        os.chown(p, uid, uid)


@functools.cache  # one Radau integration (0.8 s) for the four tests that compare with it
def _second_reversal() -> float:
    """The force [N] at the second reversal of the victim's run, from an independent Radau
    integration of the equations (m x'' = -F, dF/dt = sigma v (1 - F/Fc sgn v), branch by branch)."""
    from scipy.integrate import solve_ivp

    sigma, Fc, y, sgn = 1e4, 1.0, [0.0, 1.0, 0.0], 1.0
    for _ in range(2):
        def rhs(t, y, s=sgn):
            return [y[1], -y[2], sigma * y[1] * (1 - s * y[2] / Fc)]

        def stop(t, y):
            return y[1]
        stop.terminal, stop.direction = True, -sgn
        sol = solve_ivp(rhs, (0, 10), y, method="Radau", rtol=1e-11, atol=1e-14, events=stop)
        y, sgn = list(sol.y_events[0][0]), -sgn
        y[1] = 0.0
    return float(y[2])


def _can_chown() -> bool:
    return hasattr(os, "geteuid") and os.geteuid() == 0


@pytest.mark.parametrize("how", ["other_owner", "world_writable", "library_of_other_owner"])
def test_planted_library_is_never_loaded(native_name, tmp_path, how) -> None:
    """Item 1: a library planted by another user (constructor writes a marker) never runs."""
    if how != "world_writable" and not _can_chown():
        pytest.skip("planting a file of another uid needs root")
    cache, marker = tmp_path / "cache", tmp_path / "MARKER"
    lib = _plant(cache, native_name, marker)
    if how == "other_owner":
        _chown_tree(cache, OTHER_UID)
    elif how == "world_writable":
        os.chmod(cache, 0o777)
    else:  # the directory is ours and private, the library and its checksum another user's
        os.chmod(cache, 0o700)
        os.chown(lib, OTHER_UID, OTHER_UID)
        os.chown(lib.with_name(lib.name + ".sha256"), OTHER_UID, OTHER_UID)
    before = sorted((p.name, p.stat().st_ino, p.stat().st_mtime_ns) for p in cache.iterdir())
    out = _victim(cache)
    assert not marker.exists(), "the planted library's constructor ran"
    F0, jit = out.stdout.split()
    assert float(F0) == pytest.approx(_second_reversal(), rel=1e-6) and jit == "compiled"
    if how == "library_of_other_owner":
        (line,) = [s for s in out.stderr.splitlines() if "native_dahl" in s]
        assert "not by this process's user" in line and "not loaded" in line
    else:
        refusals = [s for s in out.stderr.splitlines() if "is refused" in s]
        assert len(refusals) == 1 and str(cache) in refusals[0]
        assert ("owned by uid 12345" in refusals[0] or "(uid 12345)" in refusals[0]
                if how == "other_owner" else "writable by others" in refusals[0])
        after = sorted((p.name, p.stat().st_ino, p.stat().st_mtime_ns) for p in cache.iterdir())
        assert after == before  # the refused cache is left alone: nothing written there


def test_planted_lock_link_is_not_followed(native_name, tmp_path) -> None:
    """Item 2: a lock planted as a symbolic link does not make the victim create its target."""
    cache, target = tmp_path / "cache", tmp_path / "elsewhere" / "created-by-victim"
    cache.mkdir(mode=0o700)
    target.parent.mkdir()
    (cache / (native_name + ".lock")).symlink_to(target)
    out = _victim(cache)
    assert not target.exists() and not os.path.lexists(target)
    assert float(out.stdout.split()[0]) == pytest.approx(_second_reversal(), rel=1e-6)


def test_cache_and_parents_are_private_under_umask_000(tmp_path) -> None:
    """Item 1: directories the cache creates are 0700 whatever the umask."""
    cache = tmp_path / "a" / "b" / "cache"
    code = "import casadi as ca; from prefriction.simulation.compiled import compiled; " \
           "x = ca.SX.sym('x'); print(compiled(ca.Function('f_umask', [x], [ca.sin(x)]))[1].mode)"
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache), capture_output=True, text=True,
                         timeout=300, preexec_fn=lambda: os.umask(0))
    assert out.returncode == 0, out.stderr
    for d in (tmp_path / "a", tmp_path / "a" / "b", cache):
        assert stat.S_IMODE(os.stat(d).st_mode) == 0o700, d
    for f in cache.iterdir():
        assert not os.stat(f).st_mode & (stat.S_IWGRP | stat.S_IWOTH), f


def _note_case(tmp_path: Path) -> tuple[Path, str]:
    """A cache with the library of a small Function and its name."""
    code = ("import casadi as ca; from prefriction.simulation.compiled import compiled; "
            "x = ca.SX.sym('x'); print(compiled(ca.Function('f_note', [x], [ca.sin(x)]))[1].mode)")
    return tmp_path / "cache", code


def test_failure_note_is_data_not_echoed_raw(tmp_path) -> None:
    """Item 4: a note full of terminal escapes is printed as printable text; another user's note is ignored."""
    cache, code = _note_case(tmp_path)
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache), capture_output=True, text=True, timeout=300)
    assert out.stdout.split() == ["compiled"]
    (lib,) = cache.glob("f_note_*.so")
    lib.unlink()
    note = lib.with_name(lib.name[:-3] + ".failed")
    note.write_text("timeout=\n\x1b[2J\x1b]0;owned\x07evil\nsecond line")
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache), capture_output=True, text=True, timeout=300)
    assert out.stdout.split() == ["interpreted"]
    assert "\x1b" not in out.stderr and "\x07" not in out.stderr and "evil second line" in out.stderr
    if _can_chown():  # a note of another user is not read: the library is compiled
        os.chown(note, OTHER_UID, OTHER_UID)
        out = subprocess.run([sys.executable, "-c", code], env=_env(cache), capture_output=True, text=True,
                             timeout=300)
        assert out.stdout.split() == ["compiled"] and "evil" not in out.stderr


def test_short_timeout_note_does_not_bind_a_longer_timeout(tmp_path) -> None:
    """Item 13: a compile stopped by a tiny timeout does not keep later processes on the slow path."""
    cache, code = _note_case(tmp_path)
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache, PREFRICTION_COMPILE_TIMEOUT="1e-9"),
                         capture_output=True, text=True, timeout=300)
    assert out.stdout.split() == ["interpreted"] and "longer than" in out.stderr
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache, PREFRICTION_COMPILE_TIMEOUT="1e-9"),
                         capture_output=True, text=True, timeout=300)
    assert out.stdout.split() == ["interpreted"] and "earlier process" in out.stderr  # same limit: note holds
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache), capture_output=True, text=True, timeout=300)
    assert out.stdout.split() == ["compiled"], out.stderr


def test_compile_timeout_inf_means_no_limit(tmp_path, monkeypatch) -> None:
    """Item 13: PREFRICTION_COMPILE_TIMEOUT=inf or 1e308 compiles (no OverflowError); junk is a clear error."""
    import casadi as ca

    from prefriction.simulation.compiled import compile_timeout, compiled

    monkeypatch.setenv("PREFRICTION_CACHE", str(tmp_path))
    monkeypatch.delenv("PREFRICTION_NO_JIT", raising=False)
    if shutil.which(os.environ.get("CC", "gcc")) is None:
        pytest.skip("no C compiler")
    for value, name in (("inf", "f_inf"), ("1e308", "f_big")):
        monkeypatch.setenv("PREFRICTION_COMPILE_TIMEOUT", value)
        assert compile_timeout() == float("inf")
        x = ca.SX.sym("x")
        fun, info = compiled(ca.Function(name, [x], [ca.cos(x) * 2]))
        assert info.mode == "compiled" and float(fun(0.5)) == pytest.approx(2 * 0.8775825618903728, rel=1e-15)
    for junk in ("abc", "nan", "-1", "0"):
        monkeypatch.setenv("PREFRICTION_COMPILE_TIMEOUT", junk)
        with pytest.raises(ValueError, match="PREFRICTION_COMPILE_TIMEOUT.*" + junk):
            compile_timeout()


@pytest.mark.parametrize("value, off", [("false", False), ("0", False), ("no", False), ("", False),
                                        ("1", True), ("TRUE", True), ("on", True)])
def test_no_jit_parses_words(monkeypatch, value, off) -> None:
    """Item 13: PREFRICTION_NO_JIT=false leaves compiled code on."""
    from prefriction.simulation.compiled import no_jit

    monkeypatch.setenv("PREFRICTION_NO_JIT", value)
    assert no_jit() is off


def test_no_jit_junk_is_a_clear_error(monkeypatch) -> None:
    from prefriction.simulation.compiled import no_jit

    monkeypatch.setenv("PREFRICTION_NO_JIT", "maybe")
    with pytest.raises(ValueError, match="PREFRICTION_NO_JIT.*'maybe'"):
        no_jit()


def test_cache_tilde_is_expanded(monkeypatch, tmp_path) -> None:
    """Item 13: PREFRICTION_CACHE=~/x names x in the home directory, not a directory called '~'."""
    from prefriction.simulation.compiled import cache_dir

    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("PREFRICTION_CACHE", "~/x")
    assert cache_dir() == tmp_path / "x"


def test_one_warning_per_process_without_compiler(monkeypatch) -> None:
    """Item 13: with no C compiler, one RuntimeWarning says what it costs and how to install one."""
    from prefriction.simulation import compiled as mod

    monkeypatch.setenv("CC", "no-such-compiler-prefriction")
    monkeypatch.delenv("PREFRICTION_NO_JIT", raising=False)
    monkeypatch.setattr(mod, "_WARNED", [])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert mod.jit_available() is False
        assert mod.jit_available() is False
    (w,) = [c for c in caught if issubclass(c.category, RuntimeWarning)]
    assert "no C compiler" in str(w.message) and "100 times slower" in str(w.message) and "install" in str(w.message)


# --- the primitives every loader and writer calls (prefriction._safe_files) -------------------

def test_safe_files_refuse_links_and_foreign_or_shared_files(tmp_path) -> None:
    from prefriction import _safe_files as safe

    real = tmp_path / "real"
    real.write_bytes(b"data")
    os.chmod(real, 0o600)
    assert safe.read_owned(real, 100) == b"data"
    link = tmp_path / "link"
    link.symlink_to(real)
    with pytest.raises(safe.UnsafeFile, match="symbolic link"):
        safe.read_owned(link, 100)
    with pytest.raises(safe.UnsafeFile, match="symbolic link"):
        safe.open_lock(link)
    with pytest.raises(safe.UnsafeFile, match="more than the 3"):
        safe.read_owned(real, 3)
    os.chmod(real, 0o620)
    with pytest.raises(safe.UnsafeFile, match="writable by its group"):
        safe.read_owned(real, 100)
    if _can_chown():
        os.chmod(real, 0o600)
        os.chown(real, OTHER_UID, OTHER_UID)
        with pytest.raises(safe.UnsafeFile, match="uid 12345"):
            safe.read_owned(real, 100)
        with pytest.raises(safe.UnsafeFile, match="uid 12345"):
            safe.open_lock(real)


def test_reading_a_small_file_under_a_large_limit_allocates_the_file_not_the_limit(tmp_path) -> None:
    """The cache reads libraries under a 1 GiB limit: a 4-byte file read so must not allocate
    that limit (tracemalloc's peak, which numbers Python's buffers), and a file at the limit is
    still read whole."""
    import tracemalloc

    from prefriction import _safe_files as safe

    real = tmp_path / "real"
    real.write_bytes(b"data")
    os.chmod(real, 0o600)
    tracemalloc.start()
    try:
        assert safe.read_owned(real, 1 << 30) == b"data"
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20, peak
    assert safe.read_owned(real, 4) == b"data"


def test_write_atomic_replaces_a_link_without_following_it(tmp_path) -> None:
    from prefriction import _safe_files as safe

    victim = tmp_path / "victim"
    victim.write_text("precious")
    dest = tmp_path / "dest"
    dest.symlink_to(victim)
    safe.write_atomic(dest, b"new")
    assert victim.read_text() == "precious" and not dest.is_symlink() and dest.read_bytes() == b"new"
    assert stat.S_IMODE(os.stat(dest).st_mode) == 0o600


def test_dir_problem_judges_the_directory_and_its_parents(tmp_path) -> None:
    from prefriction import _safe_files as safe

    mine = tmp_path / "a" / "b"
    old = os.umask(0)
    try:
        safe.make_private_dir(mine)
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(tmp_path / "a").st_mode) == 0o700 and safe.dir_problem(mine) == ""
    os.chmod(tmp_path / "a", 0o777)  # a parent others can write: they could swap b
    assert "writable by others" in safe.dir_problem(mine)
    os.chmod(tmp_path / "a", 0o1777)  # sticky, as /tmp: they cannot
    assert safe.dir_problem(mine) == ""
    os.chmod(tmp_path / "a", 0o700)
    via = tmp_path / "via"
    via.symlink_to(mine)
    assert safe.dir_problem(via) == ""
    os.chmod(mine, 0o770)
    assert "writable by its group" in safe.dir_problem(via)


def test_printable_makes_notes_inert() -> None:
    from prefriction import _safe_files as safe

    assert safe.printable("a\x1b[2Jb\nc\td\x07") == "a?[2Jb c d?"
    assert len(safe.printable("x" * 1000, 50)) == 50
