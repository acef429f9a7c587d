"""MathJax served from the built site, so the equations render without a network.

The MathJax files come from the ``sphinx-mathjax-offline`` package (a registry package that
bundles MathJax 3); this extension copies them into ``_static/mathjax`` and points Sphinx at
them. It replaces that package's own ``setup`` only to declare the build parallel-safe.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx
from sphinx.util.fileutil import copy_asset


def mathjax_files() -> Path:
    """The bundled MathJax directory of the installed ``sphinx-mathjax-offline``."""
    spec = importlib.util.find_spec("sphinx-mathjax-offline")
    if spec is None or spec.origin is None:
        raise RuntimeError("the docs need the sphinx-mathjax-offline package (pip install '.[docs]')")
    return Path(spec.origin).parent / "static" / "mathjax"


def copy_mathjax(app: Sphinx, exception: Exception | None) -> None:
    """Copy MathJax next to the pages once the build has succeeded."""
    if exception is None and app.builder.format == "html":
        copy_asset(mathjax_files(), Path(app.outdir) / "_static" / "mathjax")


def setup(app: Sphinx) -> dict[str, Any]:
    """Point ``mathjax_path`` at the local copy and copy it at the end of the build."""
    app.config.mathjax_path = "mathjax/tex-chtml.js"
    app.connect("build-finished", copy_mathjax)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
