"""Sphinx configuration of softbend's documentation (``make docs`` builds it into docs/_build).

The pages are Markdown (MyST), so that they read the same on a repository page and in the built
site; the API reference is generated from the numpydoc docstrings by autodoc + napoleon and
autosummary. No extension fetches anything from the network.
"""

from __future__ import annotations

import softbend

project = "softbend"
author = "softbend developers"
copyright = "softbend developers, BSD-3-Clause"
release = softbend.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]

# MyST: heading anchors for in-page links, $math$, ::: fences.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]

# The docstrings are numpydoc.
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# Attributes as fields of their class, not separate objects (a documented property would clash).
napoleon_use_ivar = True
autosummary_generate = True
autosummary_imported_members = False
# Methods scikit-learn generates on every estimator (metadata routing); documented by scikit-learn.
_SKLEARN_GENERATED = ",".join(
    f"set_{kind}_request"
    for kind in ("fit", "predict", "score", "partial_fit", "transform", "inverse_transform")
)
autodoc_default_options = {
    "members": True,
    "show-inheritance": True,
    "ignore-module-all": True,
    "exclude-members": _SKLEARN_GENERATED,
}
autodoc_typehints = "description"
autodoc_member_order = "bysource"
# autodoc imports every module, so the build needs every extra (make setup installs them all);
# nothing is mocked, so a page never shows a signature that the code does not have.
autodoc_mock_imports: list[str] = []

html_theme = "furo"
html_title = f"softbend {release}"
html_static_path: list[str] = []

# A numpydoc type such as "ndarray of shape (n_samples,)" is read by Sphinx as cross-references
# word by word, and a word like ``n_samples`` names attributes of several classes: Sphinx then
# warns that the reference is ambiguous. Those words are not references, so that one kind of
# warning is silenced; every other warning fails the build (``make docs`` runs with -W).
suppress_warnings = ["ref.python"]
