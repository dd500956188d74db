"""Sphinx configuration of the rockfrag documentation (``make docs``: docs/_build/html).

The site is built from this folder with warnings as errors. Its tutorials (``examples/``, run by
sphinx-gallery into ``tutorials/``) execute at every build; its reference pages are generated from the code
(``_ext/rockfrag_docs.py`` writes ``_generated/``): the command line from the argument parser, the study keys
from the schema, the output variables from the written files' CF attributes, the API from the docstrings
(autodoc and numpydoc), and the verification tables from the verification tests' own references.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # the tutorials' figures are written, never shown

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))  # tests.physics: the verification tables use the tests' references

import rockfrag  # noqa: E402

project = "rockfrag"
author = "the rockfrag authors"
copyright = "the rockfrag authors, MIT licence"
release = version = rockfrag.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "rockfrag_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated", "examples", "tutorials/*.ipynb", "tutorials/*.py"]
templates_path = ["_templates"]

# MyST: $...$ and $$...$$ maths, labelled equations, definition lists and anchors for the headings.
myst_enable_extensions = ["dollarmath", "amsmath", "deflist", "colon_fence"]
myst_heading_anchors = 3
myst_dmath_double_inline = True

# The API pages: autosummary writes one page per module (reference/api/); numpydoc renders the sections.
autosummary_generate = True
autosummary_ignore_module_all = False  # a module's __all__, where it has one, is its public API
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "none"   # the numpydoc Parameters sections state the types, with units
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "tutorials",
    "filename_pattern": r".*\.py$",          # every tutorial executes
    "ignore_pattern": r"__init__\.py",
    "run_stale_examples": True,              # no cache: every build runs every tutorial on the code as it is
    "abort_on_example_error": False,         # a failing tutorial fails the build after the others ran
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "capture_repr": ("_repr_html_", "__repr__"),
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "min_reported_time": 0,
    "write_computation_times": True,
    "show_signature": False,
}

html_theme = "furo"
html_title = f"rockfrag {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
html_last_updated_fmt = None

# Nothing is fetched: no intersphinx inventories, no remote images (the build runs offline).
nitpicky = False
suppress_warnings: list[str] = []
smartquotes = False  # TOML values, units and code in prose keep their straight quotes
