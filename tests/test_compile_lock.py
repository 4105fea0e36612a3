"""Processes that need the same compiled library at once compile it once (the lock beside it).

Two processes ask for the same Function with an empty cache; the first one's compiler is held
until the second one reports that it waits, so the two requests certainly overlap. Without the
lock the second would start its own compiler (and never print the waiting line).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

fcntl = pytest.importorskip("fcntl")

SCRIPT = textwrap.dedent(
    """
    import json
    import casadi as ca
    from prefriction.simulation.compiled import compiled
    x = ca.SX.sym("x", 3)
    g, info = compiled(ca.Function("f_locked", [x], [ca.sin(x) * 3 + x[0]]))
    print(json.dumps([info.mode, float(g(ca.DM.ones(3))[0])]))
    """
)
VALUE = 3 * math.sin(1.0) + 1.0


def _start(cache: Path, cc: Path) -> subprocess.Popen:
    # a compiler held for good (no lock: the second process runs its own) is stopped after 30 s
    env = {**os.environ, "PREFRICTION_CACHE": str(cache), "CC": str(cc), "PREFRICTION_COMPILE_TIMEOUT": "30"}
    env.pop("PREFRICTION_NO_JIT", None)
    return subprocess.Popen([sys.executable, "-c", SCRIPT], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def _wait_for(path: Path, proc: subprocess.Popen, what: str) -> None:
    deadline = time.monotonic() + 120
    while not path.exists():
        assert proc.poll() is None, f"the process ended before {what}: {proc.communicate()}"
        assert time.monotonic() < deadline, f"no {what} within 120 s"
        time.sleep(0.02)


def test_second_process_waits_and_loads_the_first_ones_library(tmp_path) -> None:
    started, release = tmp_path / "started", tmp_path / "release"
    cc = tmp_path / "heldcc"  # gcc, held until the test releases it
    cc.write_text(f"#!/bin/sh\ntouch {started}\nwhile [ ! -e {release} ]; do sleep 0.02; done\nexec gcc \"$@\"\n")
    cc.chmod(0o755)
    cache = tmp_path / "cache"
    first = _start(cache, cc)
    second = None
    try:
        _wait_for(started, first, "the first compile")
        second = _start(cache, cc)
        lines = []
        deadline = time.monotonic() + 120
        while not any("waiting for another process" in line for line in lines):
            line = second.stderr.readline()
            assert line or second.poll() is None, f"the second process did not wait: {lines}"
            assert time.monotonic() < deadline, f"the second process did not wait within 120 s: {lines}"
            lines.append(line)
        release.touch()
        out1, err1 = first.communicate(timeout=120)
        out2, err2 = second.communicate(timeout=120)
    finally:
        release.touch()
        for proc in (first, second):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.communicate()
    assert json.loads(out1) == ["compiled", pytest.approx(VALUE, rel=1e-15)]
    assert json.loads(out2) == ["cached", pytest.approx(VALUE, rel=1e-15)]
    assert err1.count("compiling f_locked") == 1 and "compiling f_locked" not in "".join(lines) + err2
    assert len(list(cache.glob("f_locked_*.so"))) == 1


def test_a_lock_held_too_long_is_given_up_after_the_patience(tmp_path) -> None:
    from prefriction.simulation import library_store as store

    lib = tmp_path / "f_x.so"
    holder = os.open(lib.with_name(lib.name + ".lock"), os.O_RDWR | os.O_CREAT)
    fcntl.flock(holder, fcntl.LOCK_EX)
    told = []
    try:
        start = time.monotonic()
        with store.build_lock(lib, 0.2, told.append) as locked:
            waited = time.monotonic() - start
    finally:
        os.close(holder)
    assert locked is False and told == [lib.with_name(lib.name + ".lock")] and 0.2 <= waited < 5
    with store.build_lock(lib, 0.2, told.append) as locked:
        assert locked is True and len(told) == 1
