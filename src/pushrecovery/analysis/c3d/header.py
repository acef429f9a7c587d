"""The 512-byte C3D header, checked against what ezc3d reads (files it truncates silently).

ezc3d itself is still adjusting its header semantics for very long files
(pyomeca/ezc3d#372, >65,535-frame Vicon files); this check catches truncated files first.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InputFileError

FloatArray = NDArray[np.float64]


def _check_header(file: Path) -> None:
    """Check the 512-byte header: a C3D file, with frames, not shorter than its data.

    ezc3d stops quietly at the end of a truncated file (and shrinks its header to match), so
    the file size is compared with what the header announces.
    """
    size = file.stat().st_size
    if size == 0:
        raise InputFileError(f"{file}: empty file, not a C3D file")
    with file.open("rb") as stream:
        header = stream.read(512)
        if len(header) < 2 or header[1] != 0x50 or header[0] < 2:  # byte 2 is always 0x50
            raise InputFileError(f"{file}: not a C3D file (no C3D header)")
        if len(header) < 512:
            raise InputFileError(f"{file}: truncated C3D header ({size} bytes of 512)")
        stream.seek((header[0] - 1) * 512 + 3)
        processor = stream.read(1)
    if not processor:
        raise InputFileError(f"{file}: truncated C3D file (no parameter section)")
    kind = processor[0]  # 84 Intel, 85 DEC, 86 MIPS (big-endian)
    endian = ">" if kind == 86 else "<"
    n_points, per_frame, first, last = struct.unpack_from(endian + "4H", header, 2)
    (data_start,) = struct.unpack_from(endian + "H", header, 16)
    if last < first:
        raise InputFileError(f"{file}: the file has no frames")
    # The sign of the header's scale factor (words 7-8) says float (< 0) or integer storage;
    # the sign bit is the top bit of byte 15 (Intel), 13 (DEC's word-swapped float) or 12 (MIPS).
    sign_byte = {85: header[13], 86: header[12]}.get(kind, header[15])
    frames = last - first + 1
    needed = (data_start - 1) * 512 + frames * (4 * n_points + per_frame) * (
        4 if sign_byte & 0x80 else 2
    )
    if size < needed:
        raise InputFileError(
            f"{file}: truncated C3D file ({size} bytes, its header needs {needed})"
        )
