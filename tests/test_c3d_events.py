"""A trial's events written into a copy of its C3D file's EVENT group, and read back."""

import math

import numpy as np
import pytest

from pushrecovery.analysis.c3d import C3DEvent, read_events, write_c3d, write_events
from pushrecovery.errors import InputFileError, InvalidParameterError


@pytest.fixture
def source(tmp_path):
    path = tmp_path / "trial.c3d"
    n = 50
    markers = {"LHEE": np.column_stack([np.linspace(0, 0.1, n), np.full(n, 0.1), np.zeros(n)])}
    write_c3d(path, point_rate=100.0, markers=markers, analog_rate=100.0, plates=[])
    return path


def test_events_round_trip_and_the_source_is_kept(tmp_path, source):
    before = source.read_bytes()
    events = [
        C3DEvent(0.58, "Right", "Foot Off", "markers"),
        C3DEvent(0.25, "General", "General", "onset"),
        C3DEvent(75.5, "Left", "Foot Strike", ""),  # past a minute: (1 min, 15.5 s)
    ]
    target = write_events(source, tmp_path / "out.c3d", events)
    assert source.read_bytes() == before
    back = read_events(target)
    assert [(e.context, e.label, e.description) for e in back] == [
        ("General", "General", "onset"),
        ("Right", "Foot Off", "markers"),
        ("Left", "Foot Strike", ""),
    ]
    # C3D stores times as 32-bit floats.
    expected = [0.25, 0.58, 75.5]
    assert [e.time for e in back] == pytest.approx(expected, rel=1e-7, abs=0)
    assert read_events(source) == []


def test_the_files_own_events_are_kept(tmp_path, source):
    first = write_events(source, tmp_path / "a.c3d", [C3DEvent(0.1, "Left", "Foot Off")])
    second = write_events(first, tmp_path / "b.c3d", [C3DEvent(0.3, "Left", "Foot Strike")])
    assert [e.label for e in read_events(second)] == ["Foot Off", "Foot Strike"]


@pytest.mark.parametrize(
    ("event", "match"),
    [
        (C3DEvent(-0.1, "Left", "Foot Off"), r"events\[0\].time must be >= 0"),
        (C3DEvent(math.nan, "Left", "Foot Off"), r"events\[0\].time"),
        (C3DEvent(math.inf, "Left", "Foot Off"), r"events\[0\].time"),
        (C3DEvent(0.1, 3, "Foot Off"), "must be str"),  # type: ignore[arg-type]
        ("Foot Off", "must be a C3DEvent"),
    ],
)
def test_bad_events_are_refused(tmp_path, source, event, match):
    with pytest.raises(InvalidParameterError, match=match):
        write_events(source, tmp_path / "out.c3d", [event])
    assert not (tmp_path / "out.c3d").exists()


def test_the_source_is_never_the_target(source):
    with pytest.raises(InvalidParameterError, match="target must differ from source"):
        write_events(source, source, [])


def test_a_file_that_is_no_c3d_is_one_clear_error(tmp_path):
    bad = tmp_path / "bad.c3d"
    bad.write_bytes(b"not a c3d file at all" * 20)
    with pytest.raises(InputFileError, match=r"bad\.c3d"):
        write_events(bad, tmp_path / "out.c3d", [C3DEvent(0.1, "Left", "Foot Off")])
    with pytest.raises(InputFileError, match=r"bad\.c3d"):
        read_events(bad)
