"""The compiled-code cache recovers from damaged, foreign and unusable libraries.

Each case damages the cache the way the issue's reproducers did (a truncated library killed
every later process with SIGBUS, flipped bytes with SIGILL; a read-only cache, a directory in
place of the library and another structure's library under the same name raised), then a new
process asks for the same Function: it must give the right numbers, print one line saying
what was wrong, and (where the cache is writable) leave a good library for the next process.
The processes are separate because a library loaded into this process cannot be damaged safely.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

SCRIPT = textwrap.dedent(
    """
    import json, sys
    import casadi as ca
    from prefriction.simulation.compiled import compiled
    n, out = int(sys.argv[1]), {}
    for tag in sys.argv[2:]:
        x = ca.SX.sym("x", n)
        f = ca.Function(f"f_{tag}", [x], [ca.sin(x) * 3 + x[0]])
        g, info = compiled(f)
        out[tag] = [info.mode, float(g(ca.DM.ones(n))[0])]
    print(json.dumps(out))
    """
)
VALUE = 3 * math.sin(1.0) + 1.0
CASES = ["trunc", "flip", "foreign", "dir", "nosum"]


def _run(cache: Path, *tags: str, n: int = 3, env: dict | None = None, prefix: tuple = ()) -> tuple[dict, str]:
    full = {**os.environ, "PREFRICTION_CACHE": str(cache), **(env or {})}
    full.pop("PREFRICTION_NO_JIT", None)
    out = subprocess.run([*prefix, sys.executable, "-c", SCRIPT, str(n), *tags], env=full,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1]), out.stderr


def _lib(cache: Path, tag: str) -> Path:
    (lib,) = cache.glob(f"f_{tag}_*.so")
    return lib


@pytest.fixture(scope="module")
def damaged(tmp_path_factory) -> tuple[Path, dict, str]:
    """A cache with one library per case, each damaged in its own way, then loaded by a new process."""
    cache = tmp_path_factory.mktemp("cache")
    first, _ = _run(cache, *CASES)
    assert all(mode == "compiled" for mode, _ in first.values())
    lib = {tag: _lib(cache, tag) for tag in CASES}
    data = lib["trunc"].read_bytes()
    lib["trunc"].write_bytes(data[: len(data) // 2])
    data = bytearray(lib["flip"].read_bytes())
    for i in range(len(data) // 4, len(data) // 2, 97):
        data[i] ^= 0xFF
    lib["flip"].write_bytes(bytes(data))
    other = tmp_path_factory.mktemp("other")
    _run(other, "foreign", n=5)  # the same Function name with other sizes: another structure
    shutil.copyfile(_lib(other, "foreign"), lib["foreign"])
    shutil.copyfile(_lib(other, "foreign").with_name(_lib(other, "foreign").name + ".sha256"),
                    lib["foreign"].with_name(lib["foreign"].name + ".sha256"))
    lib["dir"].unlink()
    lib["dir"].mkdir()
    lib["nosum"].with_name(lib["nosum"].name + ".sha256").unlink()
    second, err = _run(cache, *CASES)
    return cache, second, err


@pytest.mark.parametrize("tag, said", [("trunc", "does not match its checksum"),
                                       ("flip", "does not match its checksum"),
                                       ("foreign", "belongs to another structure"),
                                       ("nosum", "no readable checksum")])
def test_bad_library_is_rebuilt_with_one_message(damaged, tag: str, said: str) -> None:
    cache, second, err = damaged
    mode, value = second[tag]
    assert mode == "compiled" and value == pytest.approx(VALUE, rel=1e-15)
    lines = [line for line in err.splitlines() if f"f_{tag}" in line]
    assert len(lines) == 1 and said in lines[0] and f"cached in {cache}" in lines[0]


def test_directory_in_place_compiles_for_the_process(damaged) -> None:
    cache, second, err = damaged
    mode, value = second["dir"]
    assert mode == "compiled" and value == pytest.approx(VALUE, rel=1e-15)
    (line,) = [line for line in err.splitlines() if "f_dir" in line]
    assert "is a directory" in line and "for this process only" in line and "cached in" not in line


def test_repaired_cache_loads_without_messages(damaged) -> None:
    cache, _, _ = damaged
    third, err = _run(cache, *[t for t in CASES if t != "dir"])
    assert all(mode == "cached" and value == pytest.approx(VALUE) for mode, value in third.values())
    assert err.strip() == ""


def _unprivileged() -> tuple:
    """A command prefix under which file permissions apply (root bypasses them)."""
    if os.geteuid() != 0:
        return ()
    if shutil.which("setpriv") is None:
        pytest.skip("running as root without setpriv: permissions cannot be enforced")
    return ("setpriv", "--bounding-set=-dac_override,-dac_read_search,-fowner")


def test_damaged_library_in_read_only_cache(tmp_path) -> None:
    prefix = _unprivileged()
    _run(tmp_path, "ro")
    lib = _lib(tmp_path, "ro")
    lib.write_bytes(lib.read_bytes()[:4096])
    os.chmod(tmp_path, 0o555)
    try:
        out, err = _run(tmp_path, "ro", prefix=prefix)
    finally:
        os.chmod(tmp_path, 0o755)
    assert out["ro"][0] == "compiled" and out["ro"][1] == pytest.approx(VALUE, rel=1e-15)
    (line,) = err.strip().splitlines()
    assert "does not match its checksum" in line and "not writable" in line and "cached in" not in line


def test_unwritable_cache_does_not_claim_cached(tmp_path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    out, err = _run(blocker / "cache", "nowrite")
    assert out["nowrite"][0] == "compiled" and out["nowrite"][1] == pytest.approx(VALUE, rel=1e-15)
    (line,) = err.strip().splitlines()
    assert "not writable" in line and "cached in" not in line


def test_hanging_compiler_stalls_one_process_only(tmp_path) -> None:
    cc = tmp_path / "slowcc"
    cc.write_text("#!/bin/sh\nsleep 60\n")
    cc.chmod(0o755)
    env = {"CC": str(cc), "PREFRICTION_COMPILE_TIMEOUT": "1"}
    out, err = _run(tmp_path / "cache", "hang", env=env)
    assert out["hang"] == ["interpreted", pytest.approx(VALUE, rel=1e-15)]
    assert "longer than 1 s" in err
    start = time.perf_counter()
    out, err = _run(tmp_path / "cache", "hang", env=env)
    assert time.perf_counter() - start < 20  # no second wait for the compiler (import ~1 s)
    assert out["hang"][0] == "interpreted" and "earlier process" in err and "delete" in err


def test_compile_time_of_the_process_is_counted(tmp_path, monkeypatch) -> None:
    """``prefriction bench`` reports compiled_seconds(): every compile of the process counts."""
    import casadi as ca

    from prefriction.simulation.compiled import compiled, compiled_seconds

    monkeypatch.setenv("PREFRICTION_CACHE", str(tmp_path))
    monkeypatch.delenv("PREFRICTION_NO_JIT", raising=False)
    before = compiled_seconds()
    x = ca.SX.sym("x", 2)
    _, info = compiled(ca.Function("f_counted", [x], [ca.cos(x) * 7]))
    assert info.mode == "compiled" and info.seconds > 0
    assert compiled_seconds() == pytest.approx(before + info.seconds)
