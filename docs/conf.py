"""Sphinx configuration of the ballc documentation.

Build (from the repository root):  python -m sphinx -W -b html docs docs/_build/html

The gallery (sphinx-gallery) runs every script in ../examples/ and renders its
figures and GIFs; each example writes its files into
docs/_build/gallery-output/<example>/ (gallery_helpers.py).
The API pages (numpydoc) and the gallery use the ballc that Python imports: this
checkout's src/ when its extensions are built in place (setup.py build_ext --inplace),
else the installed one (pip install ".[docs]").
"""
import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
if any((ROOT / "src" / "ballc").glob("_core.*")) and any(
        p.suffix in (".so", ".pyd") for p in (ROOT / "src" / "ballc").glob("_core.*")):
    sys.path.insert(0, str(ROOT / "src"))   # built in place: document this checkout
sys.path.insert(0, str(DOCS))          # gallery_helpers
os.environ.setdefault("MPLBACKEND", "Agg")

import ballc  # noqa: E402

project = "ballc"
author = "the ballc authors"
copyright = "ballc authors"
version = release = ballc.__version__

extensions = [
    "sphinx.ext.autodoc",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip",
                    "gallery/*.md5", "gallery/*.json", "README.md"]

# myst: GitHub-style Markdown of docs/*.md; headings get anchors for cross-references.
myst_heading_anchors = 3

# numpydoc: render Parameters/Returns/Attributes as field lists; no autosummary tables
# of every method (the API page lists them itself).
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"          # types are in the numpydoc fields

def _names(names):
    return ", ".join(f"``{name}``" for name in names)


# The layout constants, from the build itself (the generated header is their source).
rst_epilog = f"""
.. |STATE_NAMES| replace:: {_names(ballc.STATE_NAMES)}
.. |PARAMETER_NAMES| replace:: {_names(ballc.PARAMETER_NAMES)}
.. |TANGENTIAL_MODELS| replace:: {_names(ballc.TANGENTIAL_MODELS)}
"""


sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r".*\.py$",        # run every example
    "reset_argv": "gallery_helpers.example_argv",     # --out docs/_build/gallery-output/...
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    # examples unchanged since the last build are not run again, unless this is set
    "run_stale_examples": os.environ.get("BALLC_DOCS_RUN_ALL") == "1",
    "min_reported_time": 1,
    "write_computation_times": False,
    "show_memory": False,
    "show_signature": False,
    "image_scrapers": ("matplotlib", "gallery_helpers.gif_scraper"),   # figures, GIFs
    "within_subsection_order": "gallery_helpers.ExampleOrder",
}

html_theme = "alabaster"
html_title = f"ballc {release}"
html_theme_options = {
    "description": "An elastic ball bouncing between two planes, with a compiled core",
    "page_width": "1240px",
    "sidebar_width": "220px",
    "body_max_width": "none",           # code and tables of up to ~100 columns unwrapped
    "fixed_sidebar": True,
    "show_relbars": True,
}
html_static_path = []
