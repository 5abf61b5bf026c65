"""The API reference pages, generated from the `__all__` lists (docs/hooks.py fills each
page of docs/api/ with them when mkdocs builds the site; tests/test_docs.py checks them).

In `jaxship.__all__` and in each namespace's `__all__` a comment line
`# <page>: <section>` starts a section: the names after it, in their order, are entries
(`::: jaxship.NAME`, `::: jaxship.SPACE.NAME`) of that section of docs/api/<page>.md,
which holds the page's title and introduction and the `API_MARKER` where the entries go;
a comment line `# -- <text>` (a layer's heading) is a note.
Needs no mkdocs: only `jaxship` and the source of its `__init__` files.
"""

import importlib
import inspect
import re


API_MARKER = "<!-- API: the entries of __all__ -->"
# the modules whose `__all__` are documented: the package and its namespaces
MODULES = ("jaxship", "jaxship.effects", "jaxship.identification", "jaxship.indices",
           "jaxship.plotting", "jaxship.strategies", "jaxship.wind_loads")
NAMESPACES = tuple(m.split(".")[1] for m in MODULES[1:])

_SECTION = re.compile(r"^\s*#\s*([a-z_]+):\s*(.+?)\s*$")
_NAME = re.compile(r"""^\s*["'](\w+)["'],?\s*(#.*)?$""")


def sections() -> dict[str, dict[str, list[str]]]:
    """`{page: {section: [identifier, ...]}}` in the order of the `__all__` lists: every
    name of every `__all__` of `MODULES` except the namespaces themselves, once.
    **Raises** `ValueError` for a name before the first section comment, a line of an
    `__all__` that is neither, or a list that differs from the module's `__all__`."""
    pages: dict[str, dict[str, list[str]]] = {}
    for name in MODULES:
        module = importlib.import_module(name)
        found = []
        where = None
        for line in _all_lines(module):
            section, entry = _SECTION.match(line), _NAME.match(line)
            if section:
                where = section.groups()
            elif entry:
                if where is None:
                    raise ValueError(f"{name}.__all__: {entry[1]!r} before any "
                                     "`# page: section` comment.")
                found.append(entry[1])
                if not (name == "jaxship" and entry[1] in NAMESPACES):
                    pages.setdefault(where[0], {}).setdefault(where[1], []).append(
                        f"{name}.{entry[1]}")
            elif line.strip() and not line.strip().startswith("# --"):
                raise ValueError(f"{name}.__all__: cannot read the line {line.strip()!r}.")
        if found != list(module.__all__):
            raise ValueError(f"{name}.__all__ is not the literal list of its source.")
    return pages


def _all_lines(module) -> list[str]:
    """The lines inside the literal `__all__ = [...]` of `module`'s source."""
    source = inspect.getsource(module)
    found = re.search(r"^__all__ = \[\n(.*?)^\]", source, flags=re.M | re.S)
    if found is None:
        raise ValueError(f"{module.__name__}: no `__all__ = [` list, one name a line.")
    return found[1].splitlines()


def page_entries(page: str) -> str:
    """The Markdown of `page`'s entries: a `## section` heading, then one `::: name`
    block per name."""
    parts = []
    for section, names in sections()[page].items():
        parts.append(f"## {section}\n\n" + "\n\n".join(f"::: {n}" for n in names))
    return "\n\n".join(parts) + "\n"
