"""A progress bar for long commands: tqdm on stderr, drawn on a terminal only.

A piped stderr keeps its one-line errors: the bar is disabled there.
"""

from __future__ import annotations

import sys


class Progress:
    """A tqdm bar (count, rate and, with a total, ETA) of ``unit`` items."""

    def __init__(self, total: int | None, label: str, unit: str) -> None:
        from tqdm import tqdm

        self.bar = tqdm(
            total=total, desc=label, unit=unit, file=sys.stderr, disable=not sys.stderr.isatty()
        )

    def update(self, count: int) -> None:
        """Advance by ``count`` items."""
        self.bar.update(count)

    def close(self) -> None:
        """Remove the bar from the terminal's last line."""
        self.bar.close()
