"""The parameter section walked in Python (analysis/c3d/structure.py) against ezc3d's reading."""

from __future__ import annotations

import re
from pathlib import Path

import biomdp
import ezc3d
import numpy as np
import pytest

from pushrecovery import InputFileError
from pushrecovery.analysis.c3d.structure import (
    check_parameter_section,
    parameter_records,
    read_parameter_section,
)

DATASETS = Path(biomdp.__file__).parent / "tests" / "datasets"
FILES = sorted(DATASETS.glob("*.c3d"))


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_every_parameter_is_where_ezc3d_reads_it(path: Path) -> None:
    data = read_parameter_section(path)
    records = parameter_records(path, data)
    check_parameter_section(path, data)
    theirs = ezc3d.c3d(str(path))["parameters"]
    # ezc3d adds defaults the file lacks (ANALOG:FORMAT ...): every record of ours is theirs.
    for (group, name), record in records.items():
        value = theirs[group][name]["value"]
        assert int(theirs[group][name]["type"]) == record.type, (group, name)
        if record.type in (2, 4) and record.dims:
            width = "<i2" if record.type == 2 else "<f4"
            count = int(np.prod(record.dims))
            raw = np.frombuffer(data, width, count=count, offset=record.data_offset)
            assert np.array_equal(np.ravel(value, order="F"), raw, equal_nan=True), (group, name)
    assert len(records) >= 15  # kistler_COP.c3d stores 15 (no POINT group): ezc3d adds 10


def _mutated(path: Path, tmp_path: Path, offset: int, value: int) -> Path:
    data = bytearray(path.read_bytes())
    data[offset] = value
    out = tmp_path / path.name
    out.write_bytes(bytes(data))
    return out


def test_a_dimension_past_its_record_is_refused(tmp_path: Path) -> None:
    source = DATASETS / "kistler_COP.c3d"
    records = parameter_records(source, read_parameter_section(source))
    used = records[("ANALOG", "USED")]
    ndims_at = used.data_offset - len(used.dims) - 1
    bad = _mutated(source, tmp_path, ndims_at, 1)  # a scalar made a vector of ... bytes
    bad = _mutated(bad, tmp_path, ndims_at + 1, 250)  # ... 250 int16: past the record
    with pytest.raises(InputFileError, match="overrun the record"):
        check_parameter_section(bad, read_parameter_section(bad))


def test_a_file_without_its_analog_scale_is_refused(tmp_path: Path) -> None:
    source = DATASETS / "kistler_COP.c3d"
    data = read_parameter_section(source)
    at = re.search(rb"\x05.SCALE", data, re.S).start() + 2  # the record's name, not GEN_SCALE
    bad = _mutated(source, tmp_path, at, ord("X"))
    with pytest.raises(InputFileError, match="missing ANALOG:SCALE"):
        check_parameter_section(bad, read_parameter_section(bad))


@pytest.mark.parametrize(
    ("data", "words"),
    [
        (b"", "not a C3D file"),
        (bytes([2, 0x50]) + bytes(510), "truncated C3D file"),
    ],
)
def test_headers_without_a_parameter_section(data: bytes, words: str, tmp_path: Path) -> None:
    path = tmp_path / "bad.c3d"
    path.write_bytes(data)
    with pytest.raises(InputFileError, match=words):
        parameter_records(path, read_parameter_section(path))
