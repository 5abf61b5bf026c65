"""The documentation site as a reader sees it (issue 59): `mkdocs build --strict`, then
the built HTML of every page is read as a browser would show it:

- no warning printed by a notebook (a stderr stream with "Warning") reaches a page;
- no code cell imports a private module (`jaxship._...`, `jaxship.cli._...`, `_studies`);
- every TeX formula ($...$ with a backslash command) lies in an element that MathJax
  typesets (class `arithmatex`: the docstrings and pages; class `jp-MarkdownOutput`: the
  notebooks' Markdown), and docs/javascripts/mathjax.js typesets those classes with those
  delimiters;
- reports display as Markdown: no Markdown table source (`|---|`) in a plain-text output,
  and the discovery notebook shows its report as a heading and a table.

Slow tier (the build takes about 25 s); set JAXSHIP_SITE to a built site to check that
one instead."""

import html
import html.parser
import os
import pathlib
import re
import subprocess
import sys

import pytest


ROOT = pathlib.Path(__file__).resolve().parent.parent
TEX = re.compile(r"\$[^$\n]*\\[A-Za-z]+[^$\n]*\$")
PRIVATE_IMPORT = re.compile(r"(?:from|import)\s+(?:jaxship(?:\.\w+)*\._\w*|\S*_studies)")
MATH_CLASSES = ("arithmatex", "jp-MarkdownOutput")


class Page(html.parser.HTMLParser):
    """The text of a page, each piece with the classes and MIME types around it."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.pieces = [], []

    def handle_starttag(self, tag, attrs):
        if tag in ("br", "img", "meta", "link", "input", "hr", "source", "path", "rect",
                   "circle", "line", "polyline", "use"):
            return
        a = dict(attrs)
        self.stack.append((tag, set((a.get("class") or "").split()), a.get("data-mime-type")))

    def handle_endtag(self, tag):
        for i in range(len(self.stack) - 1, -1, -1):
            if self.stack[i][0] == tag:
                del self.stack[i:]
                return

    def handle_data(self, data):
        classes = set().union(*(s[1] for s in self.stack)) if self.stack else set()
        mimes = {s[2] for s in self.stack if s[2]}
        tags = {s[0] for s in self.stack}
        self.pieces.append((data, classes, mimes, tags))


def read(path: pathlib.Path) -> Page:
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> pathlib.Path:
    if os.environ.get("JAXSHIP_SITE"):
        return pathlib.Path(os.environ["JAXSHIP_SITE"])
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocs_jupyter")
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(out)], cwd=ROOT, capture_output=True, text=True, timeout=600,
                          env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert done.returncode == 0, done.stderr[-3000:]
    return out


def notebook_pages(site):
    pages = sorted((site / "notebooks").glob("*/index.html"))
    assert len(pages) == len(list((ROOT / "notebooks").glob("*.ipynb")))
    return pages


@pytest.mark.slow
def test_no_warning_reaches_a_notebook_page(site):
    found = []
    for path in notebook_pages(site):
        for text, _, mimes, _ in read(path).pieces:
            if "application/vnd.jupyter.stderr" in mimes and "Warning" in text:
                found.append(f"{path.parent.name}: {text.strip()[:120]}")
    assert not found, "\n".join(found)


@pytest.mark.slow
def test_no_code_cell_imports_a_private_module(site):
    found = []
    for path in notebook_pages(site):
        page = read(path)
        code = "".join(t for t, classes, _, _ in page.pieces
                       if classes & {"jp-InputArea", "highlight-ipynb", "jp-CodeMirrorEditor"})
        assert "import" in code or path.parent.name == "mariner", path  # the cells were read
        found += [f"{path.parent.name}: {m}" for m in PRIVATE_IMPORT.findall(code)]
    assert not found, "\n".join(found)


@pytest.mark.slow
def test_every_formula_is_typeset_by_mathjax(site):
    config = (site / "javascripts" / "mathjax.js").read_text()  # as the site serves it
    for name in MATH_CLASSES:
        assert name in re.search(r'processHtmlClass: "([^"]*)"', config).group(1)
    assert '["$", "$"]' in config and '["\\\\(", "\\\\)"]' in config
    raw, typeset = [], {name: 0 for name in MATH_CLASSES}
    for path in sorted(site.rglob("*.html")):
        for text, classes, _, tags in read(path).pieces:
            inside = [name for name in MATH_CLASSES if name in classes]
            if inside:
                typeset[inside[0]] += bool(TEX.search(text) or "\\(" in text)
            elif TEX.search(text) and not tags & {"code", "pre", "script", "style"}:
                raw.append(f"{path.relative_to(site)}: {TEX.search(text).group(0)[:80]}")
    assert not raw, "raw TeX outside MathJax's classes:\n" + "\n".join(raw[:20])
    assert all(typeset.values()), typeset  # docstring maths and notebook maths were found


@pytest.mark.slow
def test_reports_display_as_markdown(site):
    found = []
    for path in notebook_pages(site):
        for text, classes, mimes, tags in read(path).pieces:
            plain = mimes & {"text/plain", "application/vnd.jupyter.stdout"} and "pre" in tags
            if plain and "|---" in text:
                found.append(f"{path.parent.name}: {text.strip()[:80]}")
    assert not found, "Markdown source printed as text:\n" + "\n".join(found)
    page = (site / "notebooks" / "discovery" / "index.html").read_text(encoding="utf-8")
    rendered = re.findall(r'data-mime-type="text/markdown"[^>]*>(.*?)</div>', page, flags=re.S)
    reports = [r for r in rendered if "Discovery report" in html.unescape(r)]
    assert reports and all("<table>" in r and "<h1" in r for r in reports), len(reports)
