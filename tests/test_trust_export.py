"""What an export writes never follows a link, holds no injected C, and is run only as exported
(issue 26, items 3, 4, 7, 8, 12 and the export names of 15).

References: the forces of the exported Dahl model against the closed form of the Dahl branch
from the virgin state, ``F = Fc (1 - exp(-sigma x / Fc))`` (gamma = 1, one monotone move).
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import prefriction as pf
from prefriction import export

needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")


def _dahl_closed_form(sigma: float, Fc: float, x: np.ndarray) -> np.ndarray:
    """Dahl gamma = 1 from the virgin state at x[0] = 0, moving forward: F = Fc (1 - exp(-sigma x / Fc))."""
    return Fc * (1.0 - np.exp(-sigma * x / Fc))


def test_export_does_not_write_through_a_planted_link(tmp_path) -> None:
    """Item 3: ``ln -s victim.txt DIR/dahl.h`` then ``c_source(..., "dahl", DIR)`` leaves victim.txt alone."""
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    d = tmp_path / "out"
    d.mkdir()
    for planted in ("dahl.h", "dahl.c"):
        link = d / planted
        link.symlink_to(victim)
        with pytest.raises(ValueError, match="symbolic link"):
            export.c_source(pf.Dahl(2e5, 1.5), "dahl", d)
        assert victim.read_text() == "precious\n" and link.is_symlink()
        link.unlink()


def test_export_replaces_files_atomically(tmp_path) -> None:
    """Item 3: a second export of the same name replaces the files (new inodes: renamed, not rewritten)."""
    a = export.c_source(pf.Dahl(1e5, 1.0), "m", tmp_path)
    inode = os.stat(a.source).st_ino
    b = export.c_source(pf.Dahl(4e5, 3.0), "m", tmp_path)
    assert os.stat(b.source).st_ino != inode and not list(tmp_path.glob(".m.*"))


class_name = "Dahl */ int injected = 42; /*"


@needs_gcc
def test_class_name_cannot_inject_c(tmp_path) -> None:
    """Item 4: a model class named with a comment end lands no code in the export."""
    Evil = type(class_name, (pf.Dahl,), {})
    src = export.c_source(Evil(2e5, 1.5), "evil", tmp_path)
    text = src.header.read_text() + src.source.read_text()
    assert "*/ int injected" not in text
    obj = tmp_path / "evil.o"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", "-c", str(src.source), "-o", str(obj)], check=True,
                   capture_output=True)
    symbols = subprocess.run(["nm", str(obj)], capture_output=True, text=True).stdout if shutil.which("nm") else ""
    assert "injected" not in symbols
    assert "* / int injected" in src.what  # the name is still shown, as inert text


@needs_gcc
def test_stale_handle_is_refused(tmp_path) -> None:
    """Item 7: a handle whose files were rewritten by another export refuses to run."""
    x = np.linspace(0.0, 2e-5, 50)
    a = export.c_source(pf.Dahl(1e5, 1.0), "m", tmp_path)
    np.testing.assert_allclose(export.run_c(a, x, optimize=False).F, _dahl_closed_form(1e5, 1.0, x), rtol=1e-12,
                               atol=1e-15)
    b = export.c_source(pf.Dahl(4e5, 3.0), "m", tmp_path)
    with pytest.raises(ValueError, match="no longer hold what this export of 'm' wrote"):
        export.run_c(a, x, optimize=False)
    np.testing.assert_allclose(export.run_c(b, x, optimize=False).F, _dahl_closed_form(4e5, 3.0, x), rtol=1e-12,
                               atol=1e-15)
    np.testing.assert_allclose(export.evaluate(a, x), _dahl_closed_form(1e5, 1.0, x), rtol=1e-12, atol=1e-15)


@needs_gcc
def test_run_c_refuses_a_source_replaced_by_a_link(tmp_path) -> None:
    """Item 3/7: a file of the export replaced by a link is not followed when running it."""
    a = export.c_source(pf.Dahl(1e5, 1.0), "m", tmp_path)
    copy = tmp_path / "copy.c"
    shutil.copyfile(a.source, copy)
    a.source.unlink()
    a.source.symlink_to(copy)
    with pytest.raises(ValueError, match="cannot be read"):
        export.run_c(a, [0.0, 1e-6], optimize=False)


@pytest.mark.parametrize("name", ["dahl\n", "_Exit", "_x", "math", "stdio", "time", "stdlib", "Math", "STDIO",
                                  "unistd", "casadiX", "CasADi_m"])
def test_export_names_that_reach_into_c_are_refused(tmp_path, name) -> None:
    """Item 15: names that pass a loose identifier check but break C or shadow system headers."""
    with pytest.raises(ValueError, match="name must"):
        export.c_source(pf.Dahl(2e5, 1.5), name, tmp_path)
    assert not list(tmp_path.iterdir())


def test_empty_directory_is_refused(tmp_path, monkeypatch) -> None:
    """Item 15: ``directory=""`` is an error, not the working directory."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="directory must name a directory, got ''"):
        export.c_source(pf.Dahl(2e5, 1.5), "d", "")
    assert not list(tmp_path.iterdir())


def test_directory_that_cannot_be_created_is_a_clear_error(tmp_path) -> None:
    """Item 15: a directory below a file: ValueError naming it, not a raw NotADirectoryError."""
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="directory .*cannot be created"):
        export.c_source(pf.Dahl(2e5, 1.5), "d", tmp_path / "file" / "sub")


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    stage = pf.Oscillator(pf.Dahl(2e5, 1.5), mass=0.5)
    return export.plant_source(stage, "stage", tmp_path_factory.mktemp("plant"), Ts=1e-3)


@pytest.mark.parametrize("x0", [math.inf, math.nan, 1e308])
def test_plant_start_must_be_finite(plant, x0) -> None:
    """Item 8: ``run_plant_c``/``evaluate_plant`` with x0 = inf, NaN, 1e308 are refused, naming x0."""
    with pytest.raises(ValueError, match="x0 must"):
        export.evaluate_plant(plant, [0.5] * 3, x0=x0)
    with pytest.raises(ValueError, match="x0 must"):
        export.run_plant_c(plant, [0.5] * 3, x0=x0)
    with pytest.raises(ValueError, match="v0 must"):
        export.evaluate_plant(plant, [0.5] * 3, v0=x0)


def test_controller_start_must_be_finite(tmp_path) -> None:
    """Item 8: ``controller_source(..., x0=nan)`` is refused before any C is written."""
    from prefriction.controllers import PID

    with pytest.raises(ValueError, match="x0 must be finite"):
        export.controller_source(PID(kp=1e3, ki=10.0, kd=1.0), "pid", tmp_path, Ts=1e-3, x0=math.nan)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("Ts", [5e-324, 1e-300, 1e-13])
def test_denormal_sample_time_is_refused(tmp_path, Ts) -> None:
    """Item 8: LuGre ``c_source(..., Ts=5e-324)`` gave NaN forces; now a ValueError naming Ts."""
    with pytest.raises(ValueError, match="Ts must be a sample time >= 1e-12 s"):
        export.c_source(pf.LuGre(1e5, 300.0, 0.4, 1.0, 1.5, 1e-3), "lugre", tmp_path, Ts=Ts)


@needs_gcc
def test_run_c_from_threads_on_first_use(tmp_path) -> None:
    """Item 12: many threads calling ``run_c`` on first use in a process all succeed."""
    script = textwrap.dedent(f"""
        import numpy as np, prefriction as pf
        from concurrent.futures import ThreadPoolExecutor
        from prefriction import export
        src = export.c_source(pf.Dahl(1e5, 1.0), "m", {str(tmp_path)!r})
        x = np.linspace(0.0, 2e-5, 20)
        ref = 1.0 * (1 - np.exp(-1e5 * x))
        def one(_):
            try:
                return float(np.max(np.abs(export.run_c(src, x, optimize=False).F - ref)))
            except Exception as exc:
                return repr(exc)
        with ThreadPoolExecutor(32) as pool:
            out = list(pool.map(one, range(32)))
        bad = [o for o in out if isinstance(o, str) or o > 1e-12]
        print(len(bad), bad[:2])
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[0] == "0", done.stdout


def test_unwritable_directory_is_a_clear_error(tmp_path) -> None:
    """Item 15: an export into a directory it cannot write names the directory (no raw PermissionError)."""
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        if shutil.which("setpriv") is None:
            pytest.skip("root bypasses permissions and setpriv is missing")
        code = ("import prefriction as pf; from prefriction import export\n"
                "try:\n    export.c_source(pf.Dahl(2e5, 1.5), 'd', {d!r})\n"
                "except ValueError as exc:\n    print('ValueError', exc)\n")
        d = tmp_path / "ro"
        d.mkdir()
        os.chmod(d, 0o555)
        done = subprocess.run(["setpriv", "--bounding-set=-dac_override,-dac_read_search,-fowner", sys.executable,
                               "-c", code.format(d=str(d))], capture_output=True, text=True, timeout=300,
                              env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        out = done.stdout
    else:
        d = tmp_path / "ro"
        d.mkdir()
        os.chmod(d, 0o555)
        with pytest.raises(ValueError) as info:
            export.c_source(pf.Dahl(2e5, 1.5), "d", d)
        out = f"ValueError {info.value}"
    assert out.startswith("ValueError directory") and "cannot be written" in out, out
