"""Render a :class:`~pushrecovery.report.data.Report` to HTML through the jinja2 templates.

The templates (``report/templates``) hold the prose and the markup; the data classes hold
numbers, formatted cells and figure paths. Autoescaping is on for every template, so no text
of the data (a parameter name, an error message, a path) is ever read as markup. Undefined
names raise (``StrictUndefined``) rather than render as empty text.
"""

from __future__ import annotations

from functools import lru_cache

import jinja2

from pushrecovery.arguments import require_type
from pushrecovery.report.data import Report
from pushrecovery.report.markup import data_uri, num, percent

__all__ = ["render_report"]


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("pushrecovery.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
    )
    env.filters["num"] = num
    env.filters["percent"] = percent
    env.filters["data_uri"] = data_uri
    return env


def render_report(report: Report) -> str:
    """Return the whole page of ``report`` as one self-contained HTML document.

    Figures are embedded as base64 ``data:`` URIs (read from their paths now), the CSS is
    inline; there is no script and no external reference.
    """
    require_type("report", report, Report)
    return _environment().get_template("page.html.j2").render(report=report)
