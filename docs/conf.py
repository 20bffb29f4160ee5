"""Sphinx configuration of the documentation site: the guides (``docs/*.md``, MyST Markdown), the
glossary, the changelog and the API reference from the docstrings (``docs/api``).

Build (what ``.ci/run`` does; any warning fails it)::

    python -m sphinx -E -W --keep-going -q -b html docs docs/_build/html
"""

import os
import sys

sys.path.insert(0, os.path.abspath(os.path.join(__file__, "..", "..")))
os.environ.setdefault("MPLBACKEND", "Agg")

project = "pymoo-rail"
author = "pymoo-rail contributors"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.viewcode"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# the guides stay plain Markdown that reads on GitHub too: anchors for their headings, tables, no
# Sphinx-only syntax needed
myst_heading_anchors = 3
myst_enable_extensions = ["deflist"]
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "description"
autodoc_member_order = "bysource"
# numpy and pymoo types in signatures are not documented here
nitpicky = False
# numpydoc array shapes such as ``(n_sections + 1,)`` become cross-references to every attribute of
# that name (SpeedCodes.n_sections, Journey.n_sections): "more than one target" is not an error there
suppress_warnings = ["ref.python"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
html_theme = "alabaster"
html_title = "pymoo-rail"
html_static_path = ["_static"]
html_css_files = ["wrap.css"]
html_theme_options = {
    "sidebar_width": "300px",
    "page_width": "1140px",
    "description": "Energy-efficient train driving for pymoo",
}
html_sidebars = {"**": ["about.html", "navigation.html", "relations.html", "searchbox.html"]}
