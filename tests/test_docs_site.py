"""The documentation site's sources: every public name has an API entry, every page is in the
navigation, no page tells development history. Read from the files (no mkdocs needed); the site
itself is built in strict mode by .ci/run."""

from __future__ import annotations

import functools
import importlib
import inspect
import re

import pytest
from _doc_blocks import ROOT

import prefriction as pf

API = ROOT / "docs" / "api"
SUBMODULES = [name for name in pf.__all__ if inspect.ismodule(getattr(pf, name))]


@functools.lru_cache(maxsize=None)
def _public_names() -> list[tuple[str, object]]:
    """``(public path, object)`` of every public name: ``prefriction.__all__``, each public
    module's ``__all__``, and :mod:`prefriction.testing`'s."""
    import prefriction.testing

    out = [(f"prefriction.{n}", getattr(pf, n)) for n in pf.__all__ if n not in SUBMODULES]
    modules = [(f"prefriction.{n}", getattr(pf, n)) for n in SUBMODULES] + [("prefriction.testing", prefriction.testing)]
    for path, module in modules:
        assert hasattr(module, "__all__"), f"{path} has no __all__"
        out += [(f"{path}.{n}", getattr(module, n)) for n in module.__all__]
    return out


def _resolve(path: str) -> object:
    """The object an API entry ``::: a.b.C`` names, by attribute access from the package (as a
    user reaches it); a submodule is imported only where no attribute has the name. Importing
    first could shadow a lazily loaded function by its own module (``identify.fit``)."""
    parts = path.split(".")
    obj = importlib.import_module(parts[0])
    for k, attr in enumerate(parts[1:], 1):
        try:
            obj = getattr(obj, attr)
        except AttributeError:
            if not inspect.ismodule(obj):  # a function named like its module: ``a.fit.fit``
                obj = importlib.import_module(".".join(parts[:k]))
            obj = getattr(obj, attr) if hasattr(obj, attr) else importlib.import_module(".".join(parts[:k + 1]))
    return obj


@functools.lru_cache(maxsize=None)
def _entries() -> dict[str, object]:
    entries = {}
    for page in sorted(API.glob("*.md")):
        for path in re.findall(r"^::: (\S+)", page.read_text(), flags=re.M):
            entries[path] = _resolve(path)
    return entries


def test_every_public_name_has_an_api_entry():
    entries = _entries()
    missing = []
    for path, obj in _public_names():
        name = path.rsplit(".", 1)[1]
        if not any(e.rsplit(".", 1)[1] == name and got is obj for e, got in entries.items()):
            missing.append(path)
    assert not missing, f"no API entry (docs/api/*.md, '::: path') for {missing}"


def test_every_api_entry_names_an_existing_object():
    assert len(_entries()) >= len(_public_names())


def test_every_page_and_api_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    pages = [p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")]
    missing = [p for p in pages if f": {p}\n" not in nav]
    assert not missing, f"pages not in mkdocs.yml's nav: {missing}"


@pytest.mark.parametrize("phrase", ["this commit", "issue 1", "issue 2", "before this", "used to ", "redesign",
                                    "measured in issue"])
def test_no_page_tells_development_history(phrase):
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    hits = [p.name for p in pages if phrase in p.read_text().lower()
            and not (phrase == "used to " and _only_instrumental(p.read_text().lower()))]
    assert not hits, f"{phrase!r} in {hits}"


def _only_instrumental(text: str) -> bool:
    """``used to`` only as in 'the model used to design' (a purpose, not history)."""
    return all(re.match(r"used to (design|compute|build|fit|check|run|plan|model|make|find)", text[m.start():])
               for m in re.finditer("used to ", text))


def test_the_gallery_shows_every_example_and_its_images_exist():
    text = (ROOT / "docs" / "gallery.md").read_text()
    for script in sorted((ROOT / "examples").glob("*.py")):
        assert f"examples/{script.name}" in text, script.name
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(images) >= 30
    for image in images:
        assert (ROOT / "docs" / image).is_file(), image
