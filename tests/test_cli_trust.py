"""The command line: row counts, a closed pipe, --version."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import prefriction
from prefriction.cli import main


@pytest.mark.parametrize("rows", [1, 3, 5, 20])
def test_table_prints_the_rows_asked_for(rows, capsys) -> None:
    assert main(["table", "--n", "40", "--rows", str(rows)]) == 0
    out = capsys.readouterr().out
    table = out.split("-----\n", 1)[1].split("\n\n", 1)[0]
    assert sum(1 for line in table.splitlines() if line.strip()[:1].isdigit()) == rows


def test_version(capsys) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"prefriction {prefriction.__version__}"


def test_table_into_a_closed_pipe_exits_quietly() -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    cmd = (f"{sys.executable} -m prefriction.cli table --n 20000 --rows 20000 | head -1")
    out = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "Traceback" not in out.stderr and "BrokenPipe" not in out.stderr


def test_messages_show_numpy_scalars_as_numbers() -> None:
    import numpy as np

    from prefriction._validation import check_real

    with pytest.raises(TypeError) as err:
        check_real("v0", np.complex128(0.0304j))
    assert "0.0304j" in str(err.value) and "np." not in str(err.value)
