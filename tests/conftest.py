"""Scheduling under pytest-xdist: tests that share a module's fixture run on one worker.

``--dist loadgroup`` (pyproject addopts) hands ungrouped tests out one at a time, as ``--dist load``
does. A module-scoped fixture (a compiled structure, a fit, a set of figure runs) is built once per
worker that runs one of its tests, so a module split over two workers built it twice. Every test of
a module that uses a fixture of module or session scope defined in the test files goes into one
group named after the module: built once. Groups are handed out before single tests (xdist orders
work units by size), so the long units start first and the single tests fill the end of the run.

BLAS threads: one per process. ``-n 2`` already runs one worker per core; OpenBLAS's own threads
on top of that (two per worker on two cores, more on a machine shared with other jobs) wait for
each other in spin loops: the dense SVD of a motion fit's trust-region step took 45 s instead of
1.6 s (a 1700 x 850 matrix, two threads against one, on a loaded 2-core machine). The variables
are set before numpy is first imported (nothing imports it before this file), so the workers and
the processes the tests start inherit them; values set by the caller are kept.
"""

from __future__ import annotations

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import pytest  # noqa: E402


def _shares_a_fixture(item: pytest.Item) -> bool:
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    for defs in info.name2fixturedefs.values():
        for fixturedef in defs:
            where = getattr(fixturedef, "baseid", "")
            if fixturedef.scope in ("module", "session") and where.startswith("tests/"):
                return True
    return False


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not config.pluginmanager.hasplugin("xdist"):
        return
    for item in items:
        if _shares_a_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::", 1)[0]))
