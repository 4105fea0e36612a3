"""The top-level namespace holds the documented API and its subpackages, nothing else."""

from __future__ import annotations

import types

import prefriction as pf


def test_no_stray_names_at_top_level():
    stray = [n for n in dir(pf) if not n.startswith("_") and n not in pf.__all__
             and not isinstance(getattr(pf, n), types.ModuleType)]
    assert stray == []
    assert not hasattr(pf, "annotations")


def test_every_exported_name_resolves():
    for name in pf.__all__:
        assert getattr(pf, name) is not None
