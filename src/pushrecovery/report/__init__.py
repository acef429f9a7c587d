"""The HTML report: surfaces, the paper's figures and push campaigns on one page.

:func:`write_report` writes ``OUT/index.html``. It needs the ``report`` extra (its campaigns
run in MuJoCo, it draws figures and fills templates): without it, importing the package raises
:class:`~pushrecovery.extras.MissingExtraError` naming it, before any work.
"""

from pushrecovery.extras import require_extra

require_extra("report")

from pushrecovery.report.config import (  # noqa: E402
    MUJOCO_SECTIONS,
    SECTIONS,
    SIZES,
    PushGrid,
    ReportGrids,
)
from pushrecovery.report.html import write_report  # noqa: E402

__all__ = [
    "MUJOCO_SECTIONS",
    "SECTIONS",
    "SIZES",
    "PushGrid",
    "ReportGrids",
    "write_report",
]
