"""A trial's events in a C3D file's EVENT group, where gait software reads them.

:func:`write_events` copies a C3D file with events added to its ``EVENT`` group (``USED``,
``TIMES``, ``CONTEXTS``, ``LABELS``, ``DESCRIPTIONS``, ``SUBJECTS``, ``ICON_IDS``,
``GENERIC_FLAGS``: the C3D format's event parameters, as Vicon Nexus and Visual3D write and
read them); :func:`read_events` reads them back. The input file is never modified. Times are
seconds in the file's own time base, the one :func:`~pushrecovery.analysis.c3d.read_c3d`
gives its frames (frame k of the header's numbering at (k − 1) / rate), stored as the
format's (minutes, seconds) pair. The events the file already holds are kept.

Both run ezc3d in the helper process of :mod:`.isolated` (a malformed file cannot crash the
caller).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pushrecovery.analysis.c3d.header import _check_header
from pushrecovery.analysis.c3d.isolated import run_isolated
from pushrecovery.analysis.c3d.structure import check_parameter_section, read_parameter_section
from pushrecovery.arguments import finite_float, require_type
from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError
from pushrecovery.extras import require

__all__ = ["C3DEvent", "read_events", "write_events"]

#: The labels gait software expects for foot events (Vicon's, also Visual3D's defaults).
FOOT_STRIKE, FOOT_OFF, GENERAL = "Foot Strike", "Foot Off", "General"


@dataclass(frozen=True, slots=True)
class C3DEvent:
    """One event of a C3D file's EVENT group.

    Attributes
    ----------
    time : float
        Time [s] in the file's time base (module docstring), >= 0.
    context : str
        ``Left``, ``Right`` or ``General`` (the side the event belongs to).
    label : str
        ``Foot Strike``, ``Foot Off``, ``General`` or another name.
    description : str
        Free text (this project writes what detected the event).
    """

    time: float
    context: str
    label: str
    description: str = ""


def write_events(source: str | Path, target: str | Path, events: Sequence[C3DEvent]) -> Path:
    """Write a copy of the C3D file ``source`` with ``events`` added to its EVENT group.

    Parameters
    ----------
    source : str or Path
        The C3D file (read, never modified).
    target : str or Path
        The copy to write (overwritten; not ``source``).
    events : sequence of C3DEvent
        The events to add, after the ones the file holds.

    Returns
    -------
    Path
        ``target``.

    Raises
    ------
    InvalidParameterError
        ``target`` is ``source``, or an event's time is negative or not finite, or a text
        field is not a string.
    InputFileError
        ``source`` cannot be read as a C3D file.
    """
    if isinstance(events, str) or not isinstance(events, list | tuple):
        raise ParameterTypeError(f"events must be a list of C3DEvent, got {type(events).__name__}")
    require_type("source", source, (str, os.PathLike))
    require_type("target", target, (str, os.PathLike))
    source, target = Path(source), Path(target)
    if "\x00" in f"{source}{target}":
        raise InvalidParameterError("source and target must be file names (a NUL character)")
    try:
        same = target.resolve() == source.resolve()
    except (OSError, RuntimeError) as exc:  # RuntimeError: a symlink loop
        raise InputFileError(f"{str(source)[:200]}: {exc}") from None
    if same:
        raise InvalidParameterError(f"target must differ from source ({source}): never modified")
    rows = []
    for k, event in enumerate(events):
        if not isinstance(event, C3DEvent):
            raise InvalidParameterError(f"events[{k}] must be a C3DEvent, got {type(event)}")
        time = finite_float(f"events[{k}].time", event.time, "s")
        if time < 0.0:
            raise InvalidParameterError(f"events[{k}].time must be >= 0 s, got {time!r}")
        texts = (event.context, event.label, event.description)
        if not all(isinstance(text, str) for text in texts):
            raise InvalidParameterError(f"events[{k}]: context, label, description must be str")
        rows.append((time, *texts))
    _check(source)
    require("analysis", "ezc3d", "write_events")
    run_isolated(_write, (str(source), str(target), rows), source)
    return target


def read_events(path: str | Path) -> list[C3DEvent]:
    """Return the events of a C3D file's EVENT group, in time order (none: empty)."""
    require_type("path", path, (str, os.PathLike))
    path = Path(path)
    _check(path)
    require("analysis", "ezc3d", "read_events")
    rows = run_isolated(_read, (str(path),), path)
    return sorted((C3DEvent(*row) for row in rows), key=lambda event: event.time)


def _check(file: Path) -> None:
    """Refuse what is no C3D file before ezc3d (C++, trusting the file) opens it, as the reader."""
    try:
        if not file.is_file():
            raise InputFileError(
                f"{file}: no such file" if not file.exists() else f"{file}: not a file"
            )
        _check_header(file)
        check_parameter_section(file, read_parameter_section(file))
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise InputFileError(f"{str(file)[:200]}: cannot read ({reason.splitlines()[0]})") from None


def _open(path: str) -> Any:
    import ezc3d

    try:
        return ezc3d.c3d(path)
    except Exception as exc:  # ezc3d raises OSError, RuntimeError, IndexError, ... on bad input
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputFileError(f"{path}: not a readable C3D file ({first})") from None


def _write(source: str, target: str, rows: list[tuple[float, str, str, str]]) -> None:
    """Run in the helper process: ezc3d's ``add_event`` per row, then ``write``."""
    c3d = _open(source)
    for time, context, label, description in rows:
        minutes = math.floor(time / 60.0)
        c3d.add_event(
            [float(minutes), time - 60.0 * minutes],
            context=context,
            label=label,
            description=description,
        )
    c3d.write(target)


def _read(path: str) -> list[tuple[float, str, str, str]]:
    """Run in the helper process: the EVENT group's (time, context, label, description)."""
    c3d = _open(path)
    group: dict[str, Any] = c3d["parameters"].get("EVENT", {})
    if "TIMES" not in group:
        return []
    times = group["TIMES"]["value"]
    used = int(group["USED"]["value"][0]) if "USED" in group else len(times[0])

    def texts(name: str) -> list[str]:
        values = list(group[name]["value"]) if name in group else []
        return [str(v).strip() for v in values] + [""] * (used - len(values))

    contexts, labels, descriptions = (texts(n) for n in ("CONTEXTS", "LABELS", "DESCRIPTIONS"))
    return [
        (60.0 * float(times[0][k]) + float(times[1][k]), contexts[k], labels[k], descriptions[k])
        for k in range(used)
    ]
