"""The documentation site (mkdocs.yml) documents the whole public API and nothing
else: every name of `jaxship.__all__` (and of the namespaces `jaxship.effects`,
`jaxship.indices`, `jaxship.plotting` and `jaxship.wind_loads`) has its `::: jaxship.NAME`
entry on an API reference page in the site's navigation, and every entry names one of
them, so that a new export without docs, or docs of a name no longer exported, fails here;
`mkdocs build --strict` (.ci/run) then checks that each entry renders. Reads the pages'
text: mkdocs need not be installed."""

import pathlib
import re
import types

import jaxship
import jaxship.plotting


ROOT = pathlib.Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api"
# public modules with their own names
NAMESPACES = ("effects", "indices", "plotting", "strategies", "wind_loads")


def public() -> set[str]:
    """`jaxship.NAME` for every name of `jaxship.__all__` that is not a namespace, and
    `jaxship.SPACE.NAME` for every name of each namespace's `__all__` (plotting: its
    public functions)."""
    names = {f"jaxship.{n}" for n in jaxship.__all__ if n not in NAMESPACES}
    for space in NAMESPACES:
        module = getattr(jaxship, space)
        exported = getattr(module, "__all__", None) or [
            n for n, v in vars(module).items() if not n.startswith("_")
            and not isinstance(v, types.ModuleType)]
        names |= {f"jaxship.{space}.{n}" for n in exported}
    return names


def documented() -> dict[str, str]:
    """Identifier -> page of every `::: identifier` entry of the API reference."""
    entries = {}
    for page in sorted(API.glob("*.md")):
        for ident in re.findall(r"^::: *([\w.]+)\s*$", page.read_text(), flags=re.M):
            assert ident not in entries, f"{ident} on {entries[ident]} and {page.name}"
            entries[ident] = page.name
    return entries


def test_every_public_name_is_in_the_api_reference():
    names = public()
    assert len(names) > 100  # the parse found the exports
    missing = sorted(names - set(documented()))
    assert not missing, "not in docs/api/*.md: " + ", ".join(missing)


def test_every_api_entry_names_an_export():
    """An entry names a public name, or a namespace itself (its module text)."""
    modules = {f"jaxship.{space}" for space in NAMESPACES}
    stale = sorted(set(documented()) - public() - modules)
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
