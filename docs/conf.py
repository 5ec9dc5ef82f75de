"""Sphinx configuration of the hinfnav documentation site (issue 24).

Build it with ``python docs/build.py`` (see that file): it executes the notebooks once into
``build/executed/`` (skipping those whose executed copy is up to date), copies them into
``docs/chapters/`` and runs ``sphinx-build -W --keep-going``. The notebooks are rendered by
myst-nb with ``nb_execution_mode = "off"``: Sphinx never executes a notebook itself.

``HINFNAV_DOCS_NOTEBOOKS=0`` builds the site without the chapters (the fast build of
tests/test_docs.py).
"""

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from hinfnav.io.provenance import package_version  # noqa: E402

project = "hinfnav"
author = "the hinfnav authors"
copyright = "the hinfnav authors, MIT licence"
release = package_version()
version = release

extensions = [
    "myst_nb",  # Markdown pages, README includes and the executed notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
]

WITH_NOTEBOOKS = os.environ.get("HINFNAV_DOCS_NOTEBOOKS", "1") != "0"

exclude_patterns = ["_build", "**.ipynb_checkpoints"]
if not WITH_NOTEBOOKS:
    exclude_patterns.append("chapters/**")

# The notebooks come executed (build.py); Sphinx renders their stored outputs.
nb_execution_mode = "off"
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

templates_path = ["_templates"]
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"show-inheritance": True}  # members: listed by autosummary
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc Parameters sections give the types (and units)
# numpydoc lists class members itself; autosummary's stubs would list them twice.
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

html_theme = "furo"
html_title = f"hinfnav {release}"

suppress_warnings = [
    # The notebooks' and README's headings skip levels where a chapter's first cell is a title (#) and
    # its sections start at ### — a cosmetic point of the source, not of the rendering.
    "myst.header",
]

CHAPTERS = HERE / "chapters"


def _chapter_toctree(app, docname, source):
    """Fill ``notebooks.md``'s toctree with the executed chapters present (none in the fast build)."""
    if docname != "notebooks":
        return
    names = sorted(p.stem for p in CHAPTERS.glob("*.ipynb")) if WITH_NOTEBOOKS else []
    if names:
        source[0] += "\n```{toctree}\n:maxdepth: 1\n\n" + "\n".join(f"chapters/{n}" for n in names) + "\n```\n"
    else:
        source[0] += "\n*This build of the site was made without the notebooks (`HINFNAV_DOCS_NOTEBOOKS=0`).*\n"


def setup(app):
    app.connect("source-read", _chapter_toctree)
