"""Sphinx configuration: the API reference from the numpydoc docstrings (napoleon), the
Markdown pages through MyST. Built in CI with warnings as errors:
``sphinx-build -W -b html docs docs/_build/html``."""

import importlib.metadata

project = "poinsot"
author = "The poinsot developers"
release = importlib.metadata.version("poinsot")
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields: no duplicate entries beside properties
autodoc_member_order = "bysource"
autodoc_typehints = "none"
myst_heading_anchors = 3
# several result classes share attribute names (t, quaternion): a bare name may match more
# than one of them, which is no error in the docstrings
suppress_warnings = ["myst.xref_missing", "ref.python"]
html_theme = "alabaster"
# long lines of code wrap instead of scrolling sideways (docs/_static/poinsot.css)
html_static_path = ["_static"]
html_css_files = ["poinsot.css"]
