"""The documentation site (mkdocs.yml) documents the whole public API and nothing
else. The API pages' entries are generated from the `__all__` lists (docs/api_pages.py:
`# page: section` comments place the names), so every name of `jaxship.__all__` and of
the namespaces' (`jaxship.effects`, `.identification`, `.indices`, `.plotting`, `.strategies`,
`.wind_loads`) has its `::: jaxship.NAME` entry on a page of the site's navigation, and
every entry names an export; `mkdocs build --strict` (.ci/run) then checks that each
renders. Reads the pages' text: mkdocs need not be installed."""

import importlib
import pathlib
import re
import sys
import types

import pytest

import jaxship
import jaxship.plotting


ROOT = pathlib.Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api"
sys.path.insert(0, str(ROOT / "docs"))
import api_pages  # noqa: E402


def public() -> set[str]:
    """`jaxship.NAME` for every name of `jaxship.__all__` that is not a namespace, and
    `jaxship.SPACE.NAME` for every name of each namespace's `__all__`; checks that each
    namespace's `__all__` is what it holds."""
    names = {f"jaxship.{n}" for n in jaxship.__all__ if n not in api_pages.NAMESPACES}
    for space in api_pages.NAMESPACES:
        module = getattr(jaxship, space)
        held = {n for n, v in vars(module).items() if not n.startswith("_")
                and not isinstance(v, types.ModuleType)}
        assert held == set(module.__all__), (space, held ^ set(module.__all__))
        names |= {f"jaxship.{space}.{n}" for n in module.__all__}
    return names


def documented() -> dict[str, str]:
    """Identifier -> page of every entry of the generated API reference."""
    entries = {}
    for page, sections in api_pages.sections().items():
        for ident in (n for names in sections.values() for n in names):
            assert ident not in entries, f"{ident} on {entries[ident]} and {page}"
            entries[ident] = page
    return entries


def test_every_public_name_is_in_the_api_reference():
    names = public()
    assert len(names) > 100  # the parse found the exports
    missing = sorted(names - set(documented()))
    assert not missing, "not on an API page: " + ", ".join(missing)


def test_every_api_entry_names_an_export():
    """An entry names a public name that exists; a page's own text names no other
    entry than a namespace itself (its module text): the entries are generated."""
    stale = sorted(set(documented()) - public())
    assert not stale, "documented but not exported: " + ", ".join(stale)
    for ident in documented():
        module, name = ident.rsplit(".", 1)
        assert hasattr(importlib.import_module(module), name), ident
    modules = {f"jaxship.{space}" for space in api_pages.NAMESPACES}
    for page in sorted(API.glob("*.md")):
        written = set(re.findall(r"^::: *([\w.]+)\s*$", page.read_text(), flags=re.M))
        assert written <= modules, (page.name, sorted(written - modules))


def test_every_section_of_all_has_its_page_and_every_page_its_entries():
    """Each `# page: section` names a page of docs/api/ holding the marker where the
    entries go, and each page there gets entries."""
    pages = api_pages.sections()
    stubs = {p.stem: p.read_text() for p in API.glob("*.md")}
    assert sorted(pages) == sorted(stubs)
    for page, text in stubs.items():
        assert text.count(api_pages.API_MARKER) == 1, page
        markdown = api_pages.page_entries(page)
        assert markdown.count("::: jaxship.") == sum(map(len, pages[page].values()))
        assert markdown.startswith("## "), page


@pytest.mark.parametrize("body, reason", [
    ('    "fit",\n', "before any"),
    ('    # estimation: Fitting\n    "fit",\n    fit\n', "cannot read the line"),
    ('    # estimation: Fitting\n    "fit",\n', "not the literal list"),
])
def test_an_all_list_the_pages_cannot_place_is_refused(tmp_path, monkeypatch, body, reason):
    """A name with no section, a line that is neither, or a list the module does not
    export as written: the generator refuses it with the reason (the build fails)."""
    name = f"fake_api_{len(body)}"  # a module of its own for each case
    (tmp_path / f"{name}.py").write_text(f"fit = 1\npredict = 2\n__all__ = [\n{body}]\n"
                                         + ("__all__ += ['predict']\n" if "literal" in reason
                                            else ""))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(api_pages, "MODULES", (name,))
    with pytest.raises(ValueError, match=reason):
        api_pages.sections()


def test_every_api_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [p.name for p in sorted(API.glob("*.md")) if f"api/{p.name}" not in nav]
    assert not missing, "API pages missing from mkdocs.yml's nav: " + ", ".join(missing)


def test_every_notebook_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [p.name for p in sorted((ROOT / "notebooks").glob("*.ipynb"))
               if f"notebooks/{p.name}" not in nav]
    assert not missing, "notebooks missing from mkdocs.yml's nav: " + ", ".join(missing)
