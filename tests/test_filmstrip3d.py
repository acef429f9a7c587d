"""The recorded push of a 3-D filmstrip (experiments.filmstrip3d): its arguments and its run."""

import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.filmstrip3d import STRIP_DURATION, filmstrip_run

P = load_params()


@pytest.mark.parametrize(
    ("model", "controller", "fraction", "last", "message"),
    [
        ("biped3d", "mpc", 0.5, 1.0, "controller must be one of"),
        ("biped3d", "ankle", 0.0, 1.0, r"fraction must be in \[1e-09, 10\]"),
        ("biped3d", "ankle", float("nan"), 1.0, "fraction"),
        ("biped3d", "ankle", 0.5, -1.0, "last_frame must be > 0"),
        ("torso", "ankle", 0.5, 1.0, "model must be one of"),
    ],
)
def test_filmstrip_run_refuses_bad_arguments(model, controller, fraction, last, message):
    with pytest.raises(InvalidParameterError, match=message):
        filmstrip_run(P, model, 0.0, fraction, controller, last)


def test_a_small_push_is_recorded_and_recovered_on_the_ankles():
    recording, impulse, outcome = filmstrip_run(P, "biped3d", 0.0, 0.3, "ankle", 0.5)
    assert impulse > 0.0
    assert outcome == "recovered"
    # The run lasts at least STRIP_DURATION unless it is decided earlier: frames up to its end.
    assert 0.5 <= recording.time[-1] <= STRIP_DURATION + 0.1
