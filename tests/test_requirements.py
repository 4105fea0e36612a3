"""The CasADi version: pyproject declares the one that works, import checks it with a clear message."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from prefriction._requirements import CASADI_MIN, check_casadi

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("version", ["3.6.7", "3.7.2", "3.8.0", "3.8.1", "3.8.1rc1"])
def test_old_casadi_is_refused_with_the_version_to_install(version: str) -> None:
    with pytest.raises(ImportError, match=rf"casadi>=3\.8\.2.*casadi {re.escape(version)} is installed"):
        check_casadi(version)


@pytest.mark.parametrize("version", ["3.8.2", "3.8.10", "3.9.0", "4.0.0+local"])
def test_working_casadi_is_accepted(version: str) -> None:
    check_casadi(version)


def test_pyproject_declares_the_checked_minimum() -> None:
    text = (ROOT / "pyproject.toml").read_text()
    (declared,) = re.findall(r'"casadi>=([\d.]+)"', text)
    assert tuple(int(n) for n in declared.split(".")) == CASADI_MIN
