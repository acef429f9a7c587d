"""Sphinx configuration of the pushrecovery documentation (``make docs`` builds it into out/docs).

Sphinx with numpydoc because the library's docstrings are numpy-style reStructuredText with
``.. math::`` blocks: numpydoc renders their sections and Sphinx their equations as they are.
The pages are Markdown (MyST); the CLI reference is rendered from click itself (sphinx-click).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import pushrecovery  # noqa: E402

project = "pushrecovery"
author = "The pushrecovery authors"
copyright = "the pushrecovery authors, MIT licence"  # noqa: A001
release = version = pushrecovery.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "offline_mathjax",  # MathJax served from the built site: equations render offline
    "numpydoc",
    "myst_parser",
    "sphinx_click",
    "pushrecovery_api",
    "cli_examples",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "_ext", "img/README.md"]
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
smartquotes_action = "qe"  # keep "--flag" as typed (no en dash) so examples copy and run

autodoc_typehints = "none"  # the types are in the numpydoc Parameters; signatures stay short
autodoc_member_order = "bysource"
autodoc_default_options = {"undoc-members": False}
python_maximum_signature_line_length = 88
numpydoc_show_class_members = False
numpydoc_xref_param_type = False

html_theme = "furo"
html_title = f"pushrecovery {release}"
html_static_path: list[str] = []
