import math

import pytest

from pushrecovery import BodyParams, InputFileError, InvalidParameterError, load_params
from pushrecovery.presets import PRESETS


def test_paper_preset_values():
    p = load_params()
    assert (p.mass, p.com_height, p.gravity, p.heel, p.toe) == (72.0, 1.0, 9.81, -0.05, 0.15)
    assert (p.flywheel_inertia, p.torque_max, p.flywheel_angle_max) == (10.0, 100.0, 1.0)
    assert p.leg_length == p.com_height
    assert p.omega == pytest.approx(math.sqrt(9.81))


def test_params_are_frozen(params):
    with pytest.raises(AttributeError):
        params.mass = 1.0


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("mass", 0.0, r"mass must be in \[0.01, 10000\] \[kg\], got mass=0"),
        ("mass", -72.0, r"mass must be in \[0.01, 10000\]"),
        ("com_height", 0.0, r"com_height must be in \[0.01, 10\]"),
        ("com_height", -1.0, r"com_height must be in \[0.01, 10\]"),
        ("gravity", 0.0, r"gravity must be in \[0.1, 100\]"),
        # Physically meaningless magnitudes are refused before any arithmetic (issue 16).
        ("gravity", 1e15, r"gravity must be in \[0.1, 100\] \[m/s\^2\], got gravity=1e\+15"),
        ("mass", 1e-300, r"mass must be in \[0.01, 10000\]"),
        ("leg_length", 1e300, r"leg_length must be in \[0.01, 10\]"),
        ("torque_max", 1e300, r"torque_max must be in \[0, 100000\]"),
        ("flywheel_inertia", 1e30, r"flywheel_inertia must be in \[1e-06, 10000\]"),
        ("flywheel_angle_max", 4.0, r"flywheel_angle_max must be in \[0.001, 3.14159\]"),
        ("torque_max_roll", -1.0, r"torque_max_roll must be in \[0, 100000\]"),
        ("mass", math.nan, "mass must be a finite number"),
        ("toe", math.inf, "toe must be a finite number"),
        ("heel", 0.2, "heel must be < toe"),  # inverted foot
        ("heel", 0.15, "heel must be < toe"),  # empty foot
        ("heel", 0.01, "heel must be < 0"),
        ("toe", -0.01, "toe must be > 0"),
        ("toe", 2.0, "closer to the ankle than com_height"),
        ("flywheel_inertia", -1.0, "flywheel_inertia must be in"),
        ("torque_max", -1.0, r"torque_max must be in \[0,"),
        ("flywheel_angle_max", 0.0, "flywheel_angle_max must be in"),
        ("leg_length", -1.0, "leg_length must be in"),
        ("ankle_torque_max", -1.0, r"ankle_torque_max must be in \[0, 100000\] \[N m\]"),
        ("ankle_torque_max", 1e6, r"ankle_torque_max must be in \[0, 100000\]"),
        ("ankle_torque_max", math.nan, "ankle_torque_max must be a finite number"),
        ("friction", 0.0, r"friction must be in \(0, 10\] \(a dimensionless coefficient\)"),
        ("friction", -0.5, r"friction must be in \(0, 10\]"),
        ("friction", 11.0, r"friction must be in \(0, 10\]"),
        ("friction", math.inf, "friction must be a finite number"),
    ],
)
def test_bad_values_name_the_parameter(field, value, words):
    with pytest.raises(InvalidParameterError, match=words):
        load_params(overrides={field: value})


def test_ankle_torque_and_friction_limits_are_optional(tmp_path):
    assert (load_params().ankle_torque_max, load_params().friction) == (None, None)
    path = tmp_path / "robot.toml"
    path.write_text("ankle_torque_max = 60\nfriction = 0.7\n")
    p = load_params(file=path)
    assert (p.ankle_torque_max, p.friction) == (60.0, 0.7)
    assert p.to_dict()["ankle_torque_max"] == 60.0 and p.to_dict()["friction"] == 0.7


def test_error_is_a_value_error():
    with pytest.raises(ValueError):
        BodyParams(-1, 1, 9.81, -0.05, 0.15, 10, 100, 1)


def test_unknown_preset_and_field():
    with pytest.raises(InvalidParameterError, match="preset must be one of"):
        load_params("moon")
    with pytest.raises(InvalidParameterError, match="unknown parameter 'height'"):
        load_params(overrides={"height": 1.0})


def test_toml_file_then_overrides(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("mass = 40.0\n[body]\ntoe = 0.1\n")
    p = load_params(file=path, overrides={"mass": 50.0})
    assert (p.mass, p.toe, p.heel) == (50.0, 0.1, PRESETS["paper"]["heel"])


def test_leg_follows_com_height_unless_given(tmp_path):
    assert load_params(overrides={"com_height": 0.9}).leg_length == 0.9
    assert load_params(overrides={"com_height": 0.9, "leg_length": 1.0}).leg_length == 1.0


def test_malformed_and_missing_toml(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("mass = = 3\n")
    with pytest.raises(InputFileError, match="malformed TOML"):
        load_params(file=bad)
    with pytest.raises(InputFileError, match="not found"):
        load_params(file=tmp_path / "nope.toml")
    wrong_type = tmp_path / "type.toml"
    wrong_type.write_text('mass = "heavy"\n')
    with pytest.raises(InvalidParameterError, match="mass must be a number"):
        load_params(file=wrong_type)
