"""Small HTML helpers for the report: escaping, numbers, tables, embedded images, the page.

Everything the page needs is inside it: plain CSS in a ``<style>`` element, images as base64
``data:`` URIs; no script and no external reference.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = [
    "CSS",
    "data_uri",
    "esc",
    "figure",
    "num",
    "page",
    "paragraph",
    "percent",
    "table",
]

CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #1a1a1a;
       max-width: 1180px; margin: 2em auto; padding: 0 1em; line-height: 1.45; }
h1 { font-size: 1.7em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; margin-top: 2.2em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; }
h3 { font-size: 1.05em; margin-top: 1.4em; }
p.lead { color: #444; }
p.note { background: #fff4e5; border-left: 4px solid #ef6c00; padding: 0.5em 0.8em; }
p.verdict { background: #e8f5e9; border-left: 4px solid #2e7d32; padding: 0.6em 0.9em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }
th { background: #f0f0f0; }
td.text, th.text { text-align: left; }
table.confusion td.diagonal { background: #e6f2e6; font-weight: bold; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; margin-top: 0.3em; }
footer { margin-top: 3em; border-top: 1px solid #ccc; font-size: 0.88em; color: #444; }
nav ul { columns: 2; }
code { background: #f4f4f4; padding: 0 0.2em; }
"""


def esc(text: object) -> str:
    """HTML-escape ``text`` (quotes included)."""
    return html.escape(str(text), quote=True)


def num(value: float | None, digits: int = 4) -> str:
    """Format a number with ``digits`` significant digits; an em dash for None or NaN."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if isinstance(value, float) and math.isinf(value):
        return "∞" if value > 0 else "−∞"
    return f"{value:.{digits}g}".replace("-", "−")


def percent(value: float | None, digits: int = 1) -> str:
    """Format a fraction as a signed percentage (``+1.2 %``); an em dash for None or NaN."""
    if value is None or math.isnan(value):
        return "—"
    return f"{100.0 * value:+.{digits}f} %".replace("-", "−")


def percent_within(value: float | None, resolution: float | None) -> str:
    """Format a fraction as a percentage no finer than ``resolution`` (a fraction), with it.

    ``+27 % ± 4 %`` for a value known to ±0.04; one more digit per factor of ten finer, up
    to two decimals; :func:`percent` when the resolution is unknown.
    """
    if value is None or math.isnan(value) or resolution is None or not resolution > 0.0:
        return percent(value)
    digits = min(2, max(0, math.ceil(-math.log10(100.0 * resolution))))
    return f"{100.0 * value:+.{digits}f} % ± {100.0 * resolution:.{digits}f} %".replace("-", "−")


def paragraph(text: str, cls: str | None = None) -> str:
    """Wrap already-escaped HTML ``text`` in a ``<p>``."""
    attribute = f' class="{esc(cls)}"' if cls else ""
    return f"<p{attribute}>{text}</p>\n"


def table(
    header: Sequence[str],
    rows: Iterable[Sequence[str]],
    *,
    text_columns: int = 0,
    cls: str | None = None,
    ident: str | None = None,
) -> str:
    """Build a table of formatted cells (escaped here); the first ``text_columns`` left."""

    def cell(tag: str, k: int, value: str) -> str:
        align = ' class="text"' if k < text_columns else ""
        return f"<{tag}{align}>{esc(value)}</{tag}>"

    attributes = (f' class="{esc(cls)}"' if cls else "") + (f' id="{esc(ident)}"' if ident else "")
    lines = [
        f"<table{attributes}>",
        "<tr>" + "".join(cell("th", k, h) for k, h in enumerate(header)) + "</tr>",
    ]
    for row in rows:
        lines.append("<tr>" + "".join(cell("td", k, v) for k, v in enumerate(row)) + "</tr>")
    lines.append("</table>")
    return "\n".join(lines) + "\n"


def data_uri(path: Path) -> str:
    """Encode the file at ``path`` (PNG, GIF or SVG) as a base64 ``data:`` URI."""
    kinds = {".png": "image/png", ".gif": "image/gif", ".svg": "image/svg+xml"}
    kind = kinds.get(Path(path).suffix.lower(), "application/octet-stream")
    encoded = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f"data:{kind};base64,{encoded}"


def figure(path: Path, caption: str, alt: str | None = None) -> str:
    """Embed an image with its caption (``caption`` is already-escaped HTML)."""
    return (
        f'<figure><img src="{data_uri(path)}" alt="{esc(alt or Path(path).name)}">'
        f"<figcaption>{caption}</figcaption></figure>\n"
    )


def page(title: str, body: str, footer: str) -> str:
    """Assemble the whole HTML document."""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{esc(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
        f"{body}\n<footer>\n{footer}\n</footer>\n</body>\n</html>\n"
    )
