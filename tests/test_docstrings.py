"""Every public function and class documents itself in numpydoc form (as python-control checks)."""

from __future__ import annotations

import inspect

import pytest

from prefriction import controllers
import prefriction
from prefriction import dahl, energy

PUBLIC = [
    (f"{mod.__name__}.{name}", getattr(mod, name))
    for mod in (prefriction, controllers, dahl, energy)
    for name in getattr(mod, "__all__", [n for n in dir(mod) if not n.startswith("_")])
    if callable(getattr(mod, name)) and getattr(getattr(mod, name), "__module__", "").startswith(("prefriction", "controllers"))
]


@pytest.mark.parametrize(("name", "obj"), PUBLIC, ids=[n for n, _ in PUBLIC])
def test_public_callables_have_numpydoc_docstrings(name, obj):
    doc = inspect.getdoc(obj)
    assert doc and len(doc.splitlines()[0]) > 10, f"{name} has no summary line"
    target = obj.__init__ if inspect.isclass(obj) and "__init__" in vars(obj) else obj
    try:
        params = [p for p in inspect.signature(target).parameters if p not in ("self", "cls")]
    except (TypeError, ValueError):
        params = []
    if params and not inspect.isclass(obj):
        assert "Parameters\n----------" in doc, f"{name} takes {params} but has no Parameters section"
