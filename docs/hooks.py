"""mkdocs hooks (mkdocs.yml `hooks:`), run by `mkdocs build`; nothing is written into the
source tree.

- The executed notebooks of `notebooks/` (outside `docs/`) become pages at
  `notebooks/NAME/`: their files are added to the build as they are, and mkdocs-jupyter
  renders them with the outputs CI stored (`execute: false`).
- The API pages (`docs/api/*.md`) get their entries, generated from the `__all__` lists
  (`api_pages.py`), where their `API_MARKER` stands.
- The home page (`docs/index.md`) takes the README below its first heading, its links
  into `docs/` made relative to the site, the notebooks' link to the first notebook's page
  and the benchmarks' README named as a file of the project.
"""

import pathlib
import re
import sys

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File


sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # api_pages beside this
import api_pages  # noqa: E402


ROOT = pathlib.Path(__file__).resolve().parent.parent
README_MARKER = "<!-- README -->"


@event_priority(100)  # before mkdocs-jupyter's on_files (priority 0) wraps the notebooks
def on_files(files, config):
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        files.append(File(f"notebooks/{path.name}", str(ROOT), config["site_dir"],
                          config["use_directory_urls"]))
    return files


def on_page_markdown(markdown, page, config, files):
    if page.file.src_uri.startswith("api/"):
        page_name = page.file.src_uri[len("api/"):-len(".md")]
        return markdown.replace(api_pages.API_MARKER, api_pages.page_entries(page_name))
    if page.file.src_uri != "index.md":
        return markdown
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    body = readme.split("\n", 1)[1] if readme.startswith("# ") else readme
    body = re.sub(r"\]\(docs/", "](", body)
    # the notebooks are pages of the site; the benchmarks' README is a file of the project
    body = body.replace("](notebooks/)", "](notebooks/quick_start.ipynb)")
    body = re.sub(r"\[([^\]]+)\]\(benchmarks/README\.md\)", r"`benchmarks/README.md`", body)
    return markdown.replace(README_MARKER, body)
