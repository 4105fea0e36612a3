"""The CasADi version the simulator needs, checked when prefriction is imported.

The simulator integrates with CasADi's ``erk`` integrator plugin and its event support, which
CasADi ships from 3.8.2 on: with 3.7.x, 3.8.0 or 3.8.1 the first ``simulate`` failed with
CasADi's raw "Cannot load shared library 'libcasadi_integrator_erk.so'".
"""

from __future__ import annotations

import re

__all__ = ["CASADI_MIN", "check_casadi"]

CASADI_MIN = (3, 8, 2)
"""Oldest CasADi release with the ``erk`` plugin the simulator uses (``pyproject.toml`` declares it)."""


def check_casadi(version: str) -> None:
    """Raise ``ImportError`` naming the installed and the required CasADi version if ``version`` is older.

    Parameters
    ----------
    version : str
        ``casadi.__version__``, e.g. ``"3.8.2"`` (a suffix such as ``"rc1"`` or ``"+local"`` is ignored).
    """
    numbers = tuple(int(n) for n in re.findall(r"\d+", version.split("+")[0])[:3])
    if numbers < CASADI_MIN:
        need = ".".join(map(str, CASADI_MIN))
        raise ImportError(
            f"prefriction needs casadi>={need} (its 'erk' integrator plugin); casadi {version} is "
            f"installed. Upgrade it: pip install 'casadi>={need}'")
