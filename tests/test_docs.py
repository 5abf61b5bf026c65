"""The documentation site (mkdocs.yml) documents the whole public API: every class and
function that `jaxship` (and `jaxship.plotting`) exports has its `::: jaxship.NAME` entry
on an API reference page in the site's navigation, so that a new export without docs
fails here; `mkdocs build --strict` (.ci/run) then checks that each entry renders. Reads
the pages' text: mkdocs need not be installed."""

import inspect
import pathlib
import re

import jaxship
import jaxship.plotting


ROOT = pathlib.Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api"


def public(module) -> set[str]:
    """The public classes and functions of jaxship re-exported by `module`."""
    return {f"{module.__name__}.{name}" for name, obj in vars(module).items()
            if not name.startswith("_") and (inspect.isclass(obj) or inspect.isfunction(obj))
            and getattr(obj, "__module__", "").startswith("jaxship")}


def documented() -> dict[str, str]:
    """Identifier -> page of every `::: identifier` entry of the API reference."""
    entries = {}
    for page in sorted(API.glob("*.md")):
        for ident in re.findall(r"^::: *([\w.]+)\s*$", page.read_text(), flags=re.M):
            assert ident not in entries, f"{ident} on {entries[ident]} and {page.name}"
            entries[ident] = page.name
    return entries


def test_every_public_name_is_in_the_api_reference():
    names = public(jaxship) | public(jaxship.plotting)
    assert len(names) > 100  # the parse found the exports
    missing = sorted(names - set(documented()))
    assert not missing, "not in docs/api/*.md: " + ", ".join(missing)


def test_every_api_entry_names_an_export():
    stale = []
    for ident in documented():
        obj = None
        module, _, name = ident.rpartition(".")
        if module in ("jaxship", "jaxship.plotting"):
            obj = getattr(jaxship if module == "jaxship" else jaxship.plotting, name, None)
        if ident != "jaxship.plotting" and (obj is None or name.startswith("_")):
            stale.append(ident)
    assert not stale, "documented but not exported: " + ", ".join(stale)


def test_every_api_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [p.name for p in sorted(API.glob("*.md")) if f"api/{p.name}" not in nav]
    assert not missing, "API pages missing from mkdocs.yml's nav: " + ", ".join(missing)


def test_every_notebook_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [p.name for p in sorted((ROOT / "notebooks").glob("*.ipynb"))
               if f"notebooks/{p.name}" not in nav]
    assert not missing, "notebooks missing from mkdocs.yml's nav: " + ", ".join(missing)
