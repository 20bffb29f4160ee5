"""Sphinx configuration of the API reference (built from the docstrings).

Build: ``python -m sphinx -W --keep-going -b html docs/api docs/_build/api`` (what ``.ci/run`` does).
"""

import os
import sys

sys.path.insert(0, os.path.abspath(os.path.join(__file__, "..", "..", "..")))
os.environ.setdefault("MPLBACKEND", "Agg")

project = "pymoo-rail"
author = "pymoo-rail contributors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.viewcode"]
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "description"
autodoc_member_order = "bysource"
# numpy and pymoo types in signatures are not documented here
nitpicky = False
suppress_warnings = []
exclude_patterns = ["_build"]
html_theme = "alabaster"
