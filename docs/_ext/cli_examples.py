"""Render the ``Example:`` blocks of the commands' help as console code on the CLI page.

The help keeps its examples in a click ``\\b`` block (printed verbatim by ``--help``), which
sphinx-click turns into a reStructuredText line block; this hook makes that block a
``console`` code block, so the page shows them as code a reader can copy.
"""

from __future__ import annotations

from typing import Any

import click
from sphinx.application import Sphinx


def examples_as_code(app: Sphinx, ctx: click.Context, lines: list[str]) -> None:
    """Rewrite, in place, a line block headed ``Example:``/``Examples:`` as a code block."""
    out: list[str] = []
    in_examples = False
    for line in lines:
        text = line[2:] if line.startswith("| ") else line
        if line.startswith("| ") and text.strip() in ("Example:", "Examples:"):
            in_examples = True
            out += [f"**{text.strip().rstrip(':')}**", "", ".. code-block:: console", ""]
            continue
        if in_examples and line.startswith("| "):
            command = text.strip()
            out.append(("   $ " if command.startswith("pushrecovery") else "     ") + command)
            continue
        if in_examples:
            in_examples = False
            out.append("")
        out.append(line)
    lines[:] = out


def setup(app: Sphinx) -> dict[str, Any]:
    """Connect the hook to sphinx-click's epilog and description events."""
    app.connect("sphinx-click-process-epilog", examples_as_code)
    app.connect("sphinx-click-process-description", examples_as_code)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
