"""The HTML report: surfaces, the paper's figures and push campaigns on one page.

:func:`write_report` writes ``OUT/index.html``.
"""

from pushrecovery.report.config import MUJOCO_SECTIONS, SECTIONS, SIZES, PushGrid, ReportGrids
from pushrecovery.report.html import write_report

__all__ = [
    "MUJOCO_SECTIONS",
    "SECTIONS",
    "SIZES",
    "PushGrid",
    "ReportGrids",
    "write_report",
]
