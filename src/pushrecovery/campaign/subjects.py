"""The subjects table of a batch of measured trials: who each file is, and their body.

A CSV file with a header row; ``pattern`` and ``subject`` are required, every other column is
optional and may be empty (the trial then takes the value from the flags, the file or the
preset, in that order: docs/analysis.md, "Many trials"):

=================  ===================================================================
``pattern``        a shell pattern (``*``, ``?``, ``[...]``) matched against the trial's
                   path relative to the batch root, then against its file name
``subject``        the subject's identifier (text)
``mass``           body mass [kg]
``leg_length``     leg length, floor to hip joint [m] (Hof's normalisation, the reach)
``com_height``     CoM height above the ankle [m]
``foot_length``    foot length, heel to toe [m]
``foot_width``     foot width [m]
``height``         stature [m], in [0.5, 2.5]: with ``sex``, the body from de Leva's
                   table (:func:`pushrecovery.anthropometry.person_params`)
``sex``            ``female`` or ``male`` (de Leva's column), with ``height``
``condition``      the trials' condition (``slip``, ``trip``, ``baseline``: printable
                   text, at most :data:`MAX_CONDITION` characters), the trials table's
                   ``condition`` column and the study figure's groups
=================  ===================================================================

The first row whose pattern matches a trial applies to it: one subject's trials of several
conditions are several rows with the same subject (and body) and narrower patterns
(``s01/slip*``, ``s01/trip*``). A malformed table (a missing column, a number that is not one,
a value out of the body's range, a condition that is no short printable text) is refused with
the line number.
"""

from __future__ import annotations

import csv
import fnmatch
import math
import os
from dataclasses import dataclass
from pathlib import Path

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import LIMITS

__all__ = [
    "MAX_CONDITION",
    "MAX_TABLE_BYTES",
    "SUBJECT_COLUMNS",
    "Subject",
    "read_subjects",
    "subject_for",
]

#: Largest subjects table read [bytes]: a study's table is kilobytes.
MAX_TABLE_BYTES = 50_000_000
#: Longest condition name [characters]: a label on a figure's axis.
MAX_CONDITION = 64

#: The table's columns: the two required ones, then the body's (all SI).
SUBJECT_COLUMNS = (
    "pattern",
    "subject",
    "mass",
    "leg_length",
    "com_height",
    "foot_length",
    "foot_width",
    "height",
    "sex",
    "condition",
)
_NUMBERS = SUBJECT_COLUMNS[2:-2]
#: Ranges of the columns that are no field of BodyParams' LIMITS [m].
_FOOT_RANGE = (0.01, 1.0)
_RANGES = {"height": (0.5, 2.5)}


@dataclass(frozen=True, slots=True)
class Subject:
    """One row of the subjects table (module docstring); None where the cell is empty."""

    pattern: str
    subject: str
    mass: float | None = None
    leg_length: float | None = None
    com_height: float | None = None
    foot_length: float | None = None
    foot_width: float | None = None
    height: float | None = None
    sex: str | None = None
    condition: str | None = None

    def matches(self, relative: str) -> bool:
        """Whether the pattern matches the trial's relative path or its file name."""
        return fnmatch.fnmatchcase(relative, self.pattern) or fnmatch.fnmatchcase(
            Path(relative).name, self.pattern
        )

    def body(self) -> dict[str, float]:
        """Return the body values the row gives, by BodyParams field name."""
        values = {
            "mass": self.mass,
            "leg_length": self.leg_length,
            "com_height": self.com_height,
            "foot_width": self.foot_width,
        }
        return {name: value for name, value in values.items() if value is not None}


def read_subjects(path: str | Path) -> tuple[Subject, ...]:
    """Read a subjects table (module docstring).

    Raises
    ------
    InvalidParameterError
        An unreadable file (or one that is not a regular file, or over
        :data:`MAX_TABLE_BYTES`), a missing ``pattern`` or ``subject`` column, an unknown
        column, an empty pattern or subject, a number that is not one or is out of its
        range, or a condition that is not printable text of at most :data:`MAX_CONDITION`
        characters, naming the line.
    """
    require_type("path", path, (str, os.PathLike))
    path = Path(path)
    # A device or a pipe (/dev/zero) would be read forever: a table is a file of some size.
    if not path.is_file() or path.stat().st_size > MAX_TABLE_BYTES:
        raise InvalidParameterError(
            f"cannot read the subjects table {path}: not a CSV file of at most "
            f"{MAX_TABLE_BYTES // 1_000_000} MB"
        )
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidParameterError(f"cannot read the subjects table {path}: {exc}") from None
    reader = csv.DictReader(text.splitlines())
    header = [name.strip().lower() for name in reader.fieldnames or []]
    missing = [name for name in ("pattern", "subject") if name not in header]
    if missing:
        raise InvalidParameterError(
            f"the subjects table {path.name} needs the columns pattern and subject, "
            f"missing {', '.join(missing)} (columns: {', '.join(SUBJECT_COLUMNS)})"
        )
    unknown = [name for name in header if name not in SUBJECT_COLUMNS]
    if unknown:
        raise InvalidParameterError(
            f"the subjects table {path.name} has unknown columns {', '.join(unknown)} "
            f"(allowed: {', '.join(SUBJECT_COLUMNS)})"
        )
    rows = []
    for line, raw in enumerate(reader, start=2):
        if raw is None or None in raw:
            raise InvalidParameterError(f"{path.name} line {line}: more cells than columns")
        row = {key.strip().lower(): (value or "").strip() for key, value in raw.items()}
        if not any(row.values()):
            continue  # a blank line
        rows.append(_subject(row, f"{path.name} line {line}"))
    if not rows:
        raise InvalidParameterError(f"the subjects table {path.name} has no rows")
    return tuple(rows)


def _subject(row: dict[str, str], where: str) -> Subject:
    if not row.get("pattern") or not row.get("subject"):
        raise InvalidParameterError(f"{where}: pattern and subject must not be empty")
    numbers: dict[str, float | None] = {}
    for name in _NUMBERS:
        text = row.get(name, "")
        if not text:
            numbers[name] = None
            continue
        try:
            value = float(text)
        except ValueError:
            raise InvalidParameterError(f"{where}: {name} must be a number, got {text!r}") from None
        low, high = LIMITS.get(name, _RANGES.get(name, _FOOT_RANGE))[:2]
        if not (math.isfinite(value) and low <= value <= high):
            raise InvalidParameterError(
                f"{where}: {name} must be in [{low:g}, {high:g}], got {text}"
            )
        numbers[name] = value
    sex = row.get("sex", "").lower() or None
    if sex not in (None, "female", "male"):
        raise InvalidParameterError(f"{where}: sex must be female or male, got {row['sex']!r}")
    if (numbers["height"] is None) != (sex is None):
        raise InvalidParameterError(f"{where}: height and sex go together: give both or neither")
    condition = row.get("condition", "") or None
    if condition is not None and not (len(condition) <= MAX_CONDITION and condition.isprintable()):
        raise InvalidParameterError(
            f"{where}: condition must be printable text of at most {MAX_CONDITION} characters, "
            f"got {condition[:MAX_CONDITION]!r}"
        )
    return Subject(row["pattern"], row["subject"], **numbers, sex=sex, condition=condition)


def subject_for(relative: str, subjects: tuple[Subject, ...]) -> Subject | None:
    """Return the first subject whose pattern matches ``relative`` (a trial's path), or None."""
    require_type("relative", relative, str)
    if not isinstance(subjects, tuple) or not all(isinstance(s, Subject) for s in subjects):
        raise ParameterTypeError("subjects must be a tuple of Subject")
    for subject in subjects:
        if subject.matches(relative):
            return subject
    return None
