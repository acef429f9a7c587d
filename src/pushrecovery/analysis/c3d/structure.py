"""The C3D parameter section, walked in Python before ezc3d (a C++ library) sees the file.

ezc3d trusts the parameter records: a dimension that makes a record overrun its neighbours, or
a missing ``ANALOG:OFFSET``, ends the whole process with a segmentation fault
(``tests/data/segfault-*.c3d``, byte mutations of real Kistler files). This module reads the
records as the C3D specification lays them out (C3D.org, "The C3D File Format User Guide",
chapter 3: parameter section) and refuses, with one line naming the file and the record, any
file whose records do not fit where they claim to be or that lacks a parameter the data
section needs.

Record layout (little-endian on Intel and DEC files, big-endian on MIPS):

- group: int8 name length (< 0: locked), int8 id (< 0), name, int16 offset to the next
  record (from this field), uint8 description length, description;
- parameter: int8 name length, int8 group id (> 0), name, int16 offset, int8 type (−1 char,
  1 byte, 2 int16, 4 float), uint8 number of dimensions (0-7), uint8 dimensions, data
  (product of the dimensions × abs(type) bytes; abs(type) for a scalar), uint8 description
  length, description.

An offset of 0 (or a name length of 0) ends the section.
"""

from __future__ import annotations

import math
import stat
import struct
from dataclasses import dataclass
from pathlib import Path

from pushrecovery.arguments import require_type
from pushrecovery.errors import InputFileError

__all__ = [
    "ParameterRecord",
    "check_parameter_section",
    "parameter_records",
    "read_parameter_section",
]

#: Element sizes [bytes] of the parameter types: char, byte, int16, float.
_TYPE_SIZES = {-1: 1, 1: 1, 2: 2, 4: 4}
#: Most dimensions of one parameter (the specification's limit).
_MAX_DIMS = 7
#: Parameters the data section cannot be read without, by what the header announces.
_NEEDED_FOR_POINTS = ("USED", "SCALE", "RATE")
_NEEDED_FOR_ANALOGS = ("USED", "SCALE", "OFFSET", "GEN_SCALE", "RATE")


@dataclass(frozen=True)
class ParameterRecord:
    """One parameter as stored: its type, dimensions and where its data lies in the file."""

    group: str
    name: str
    type: int
    dims: tuple[int, ...]
    data_offset: int  # from the start of the file [bytes]

    @property
    def size(self) -> int:
        """Bytes of data (product of the dimensions × the element size)."""
        return math.prod(self.dims) * _TYPE_SIZES[self.type]


def parameter_records(file: Path, data: bytes) -> dict[tuple[str, str], ParameterRecord]:
    """Return every parameter of the C3D bytes ``data`` by (GROUP, NAME), upper case.

    Raises
    ------
    InputFileError
        On a record that overruns the parameter section or its neighbour, an unknown type,
        too many dimensions, a parameter of no group or a name that is not ASCII.
    """
    require_type("file", file, Path)
    require_type("data", data, bytes)
    if len(data) < 512 or data[0] < 1:
        raise InputFileError(f"{file}: not a C3D file (no C3D header)")
    start = (data[0] - 1) * 512
    if len(data) < start + 4:
        raise InputFileError(f"{file}: truncated C3D file (no parameter section)")
    blocks = data[start + 2]
    endian = ">" if data[start + 3] == 86 else "<"
    end = min(len(data), start + max(blocks, 1) * 512)
    groups: dict[int, str] = {}
    pending: list[tuple[int, str, int, tuple[int, ...], int, int]] = []
    at = start + 4

    def bad(what: str, where: int | None = None) -> InputFileError:
        byte = at if where is None else where
        return InputFileError(f"{file}: malformed C3D parameter section ({what} at byte {byte})")

    while at + 2 <= end:
        length, ident = struct.unpack_from("bb", data, at)
        if length == 0:
            break
        name_end = at + 2 + abs(length)
        if name_end + 2 > end:
            raise bad("a record past the end of the section")
        try:
            name = data[at + 2 : name_end].decode("ascii").strip().upper()
        except UnicodeDecodeError:
            raise bad("a name that is not ASCII") from None
        (offset,) = struct.unpack_from(endian + "h", data, name_end)
        following = name_end + offset if offset > 0 else end
        if offset < 0 or following > end:
            raise bad(f"record {name!r} pointing outside the section")
        if ident < 0:
            groups[-ident] = name
        elif ident > 0:
            if name_end + 4 > following:
                raise bad(f"parameter {name!r} shorter than its header")
            kind, ndims = struct.unpack_from("bB", data, name_end + 2)
            if kind not in _TYPE_SIZES:
                raise bad(f"parameter {name!r} of unknown type {kind}")
            if ndims > _MAX_DIMS:
                raise bad(f"parameter {name!r} with {ndims} dimensions (at most {_MAX_DIMS})")
            dims = tuple(data[name_end + 4 : name_end + 4 + ndims])
            first = name_end + 4 + ndims
            size = math.prod(dims) * _TYPE_SIZES[kind]
            if first + size + 1 > following:  # the data and the description's length byte
                raise bad(f"parameter {name!r} whose dimensions {list(dims)} overrun the record")
            pending.append((ident, name, kind, dims, first, at))
        else:
            raise bad(f"record {name!r} of group id 0")
        if offset == 0:
            break
        at = following
    records: dict[tuple[str, str], ParameterRecord] = {}
    for ident, name, kind, dims, first, record_at in pending:
        if ident not in groups:
            raise bad(f"parameter {name!r} of no group (id {ident})", record_at)
        records[(groups[ident], name)] = ParameterRecord(groups[ident], name, kind, dims, first)
    return records


def read_parameter_section(file: Path) -> bytes:
    """Return the bytes of ``file`` up to the end of its parameter section (header included)."""
    require_type("file", file, Path)
    if not stat.S_ISREG(file.stat().st_mode):  # a FIFO would block, a device never end
        raise InputFileError(f"{file}: not a regular file")
    with file.open("rb") as stream:
        head = stream.read(512)
        if len(head) < 512 or head[0] < 1:
            return head
        stream.seek(0)
        # At most 255 parameter blocks of 512 bytes after the first block's start.
        return stream.read((head[0] - 1) * 512 + 256 * 512)


def check_parameter_section(file: Path, data: bytes) -> None:
    """Refuse a C3D file ezc3d could not read safely: records that overrun, missing parameters.

    Besides :func:`parameter_records`' checks, the header's points and analog channels need
    their parameters: ``POINT:USED``, ``SCALE``, ``RATE`` when it announces points,
    ``ANALOG:USED``, ``SCALE``, ``OFFSET``, ``GEN_SCALE``, ``RATE`` when it announces analog
    samples, with ``SCALE`` and ``OFFSET`` holding one value per channel.

    Raises
    ------
    InputFileError
        One line naming the file and what is wrong.
    """
    require_type("file", file, Path)
    require_type("data", data, bytes)
    records = parameter_records(file, data)
    endian = ">" if data[(data[0] - 1) * 512 + 3] == 86 else "<"
    n_points, per_frame = struct.unpack_from(endian + "2H", data, 2)
    needed = [("POINT", name) for name in _NEEDED_FOR_POINTS] if n_points else []
    if per_frame:
        needed += [("ANALOG", name) for name in _NEEDED_FOR_ANALOGS]
    missing = [f"{group}:{name}" for group, name in needed if (group, name) not in records]
    if missing:
        raise InputFileError(
            f"{file}: malformed C3D parameters (missing {', '.join(missing)}, which the data "
            "section needs)"
        )
    if per_frame:
        used = records[("ANALOG", "USED")]
        if used.type != 2 or used.size < 2:
            raise InputFileError(
                f"{file}: malformed C3D parameters (ANALOG:USED must be an int16 count)"
            )
        (channels,) = struct.unpack_from(endian + "h", data, used.data_offset)
        # Past 255 channels the values continue in SCALE2, OFFSET2, ...: not checked here.
        for name in ("SCALE", "OFFSET") if 0 < channels <= 255 else ():
            record = records[("ANALOG", name)]
            count = record.size // _TYPE_SIZES[record.type]
            if count < channels:
                raise InputFileError(
                    f"{file}: malformed C3D parameters (ANALOG:{name} has {count} values for "
                    f"{channels} channels)"
                )
