"""A person's body from de Leva (1996) Table 4, checked against the table's printed numbers.

The expected values are written from the paper's table (lengths [mm] of the samples of stature
1735 mm (women) and 1741 mm (men), mass and CoM fractions [%], radii of gyration [% of length])
and Winter's Fig. 4.1 (ankle height 0.039 H, foot width 0.055 H), not from the module's table.
"""

from __future__ import annotations

import math

import pytest

from pushrecovery.anthropometry import person_params
from pushrecovery.errors import InvalidParameterError

# (length mm, mass %, CoM % from the first endpoint, r_sag %, r_trans %), de Leva 1996 Table 4.
FEMALE = {
    "stature": 1735.0,
    "head": (243.7, 6.68, 48.41, 27.1, 29.5),  # VERT -> CERV
    "trunk": (614.8, 42.57, 49.64, 30.7, 29.2),  # CERV -> MIDH
    "mids_midh": 497.9,
    "upper_arm": (275.1, 2.55, 57.54, 27.8, 26.0),
    "forearm": (264.3, 1.38, 45.59, 26.1, 25.7),
    "hand": (78.0, 0.56, 74.74, 53.1, 45.4),
    "thigh": (368.5, 14.78, 36.12),
    "shank": (438.6, 4.81, 43.52),  # KJC -> AJC
    "foot": (228.3, 1.29),
}
MALE = {
    "stature": 1741.0,
    "head": (242.9, 6.94, 50.02, 30.3, 31.5),
    "trunk": (603.3, 43.46, 51.38, 32.8, 30.6),
    "mids_midh": 515.5,
    "upper_arm": (281.7, 2.71, 57.72, 28.5, 26.9),
    "forearm": (268.9, 1.62, 45.74, 27.6, 26.5),
    "hand": (86.2, 0.61, 79.00, 62.8, 51.3),
    "thigh": (422.2, 14.16, 40.95),
    "shank": (440.3, 4.33, 43.95),
    "foot": (258.1, 1.37),
}


def _by_hand(t: dict, mass: float, height: float) -> dict[str, float]:
    """The body computed step by step from the table's numbers (the docstring's chain)."""
    k = height / t["stature"]  # [m per table mm]
    length = {name: t[name][0] * k for name in t if isinstance(t[name], tuple)}
    m = {name: t[name][1] / 100 * mass for name in t if isinstance(t[name], tuple)}
    hip = length["shank"] + length["thigh"]
    shoulder = hip + t["mids_midh"] * k
    elbow = shoulder - length["upper_arm"]
    wrist = elbow - length["forearm"]
    z = {
        "shank": length["shank"] * (1 - t["shank"][2] / 100),
        "thigh": hip - length["thigh"] * t["thigh"][2] / 100,
        "trunk": hip + length["trunk"] * (1 - t["trunk"][2] / 100),
        "head": hip + length["trunk"] + length["head"] * (1 - t["head"][2] / 100),
        "upper_arm": shoulder - length["upper_arm"] * t["upper_arm"][2] / 100,
        "forearm": elbow - length["forearm"] * t["forearm"][2] / 100,
        "hand": wrist - length["hand"] * t["hand"][2] / 100,
        "foot": -0.039 * height,
    }
    n = {name: 1 if name in ("head", "trunk") else 2 for name in z}
    total = sum(m[s] * n[s] for s in z)
    upper = ("head", "trunk", "upper_arm", "forearm", "hand")

    def inertia(column: int) -> float:
        return sum(
            n[s] * m[s] * ((t[s][column] / 100 * length[s]) ** 2 + (z[s] - hip) ** 2) for s in upper
        )

    return {
        "com_height": sum(m[s] * n[s] * z[s] for s in z) / total,
        "leg_length": 0.039 * height + hip,
        "foot_length": length["foot"],
        "foot_width": 0.055 * height,
        "pitch": inertia(4),
        "roll": inertia(3),
        "head": m["head"],
        "trunk": m["trunk"],
        "thigh": m["thigh"],
        "shank": m["shank"],
        "foot": m["foot"],
    }


@pytest.mark.parametrize(
    ("mass", "height", "sex", "table", "masses"),
    [
        # segment masses [kg] by hand: 60 x 6.68 %, 42.57 %, 14.78 %, 4.81 %, 1.29 %
        (60.0, 1.65, "female", FEMALE, (4.008, 25.542, 8.868, 2.886, 0.774)),
        # 80 x 6.94 %, 43.46 %, 14.16 %, 4.33 %, 1.37 %
        (80.0, 1.80, "male", MALE, (5.552, 34.768, 11.328, 3.464, 1.096)),
    ],
)
def test_person_matches_de_leva_table(mass, height, sex, table, masses):
    body = person_params(mass, height, sex)
    p = body.params
    hand = _by_hand(table, mass, height)
    for name, expected in zip(("head", "trunk", "thigh", "shank", "foot"), masses, strict=True):
        assert body.segment_masses[name] == pytest.approx(expected, rel=1e-12)
        assert hand[name] == pytest.approx(expected, rel=1e-12)
    assert p.mass == mass
    assert p.com_height == pytest.approx(hand["com_height"], rel=1e-12)
    assert p.leg_length == pytest.approx(hand["leg_length"], rel=1e-12)
    assert p.toe - p.heel == pytest.approx(hand["foot_length"], rel=1e-12)
    assert p.heel == pytest.approx(-0.25 * hand["foot_length"], rel=1e-12)
    assert p.foot_width == pytest.approx(hand["foot_width"], rel=1e-12)
    assert p.flywheel_inertia == pytest.approx(hand["pitch"], rel=1e-12)
    assert p.flywheel_inertia_roll == pytest.approx(hand["roll"], rel=1e-12)
    assert p.max_step_length == p.leg_length
    # Plausible for an adult: CoM 0.5-0.6 H above the floor, the upper body 6-10 kg m^2 at 80 kg.
    assert 0.5 < (p.com_height + 0.039 * height) / height < 0.6


def test_known_numbers_female_60kg_165cm():
    """A few numbers written out, so that a change of the table or the chain shows."""
    p = person_params(60.0, 1.65, "female").params
    # foot: 228.3 / 1735 * 1.65 = 0.217115 m; width 0.055 * 1.65 = 0.09075 m
    assert p.toe - p.heel == pytest.approx(0.217115, abs=1e-6)
    assert p.foot_width == pytest.approx(0.09075, abs=1e-12)
    # leg: 0.039 * 1.65 + (438.6 + 368.5) / 1735 * 1.65 = 0.06435 + 0.767559 = 0.831909 m
    assert p.leg_length == pytest.approx(0.831909, abs=1e-6)


def test_sources_say_where_each_value_came_from():
    body = person_params(80.0, 1.80, "male")
    assert set(body.sources) >= set(body.params.__dataclass_fields__)
    assert body.sources["mass"] == "given"
    assert "de Leva 1996" in body.sources["com_height"]
    assert "de Leva 1996" in body.sources["flywheel_inertia"]
    assert "Winter" in body.sources["foot_width"]
    assert "assumption" in body.sources["heel"]
    for name in ("torque_max", "flywheel_angle_max", "stance_width"):
        assert "NOT a person's value" in body.sources[name]
    assert "EXTRAPOLATED" not in body.sources["model"]


def test_child_gets_child_scaled_geometry():
    body = person_params(14.5, 1.0, "female")
    p = body.params
    assert p.mass == 14.5
    assert 0.45 < p.com_height < 0.55  # not the preset's 1 m
    assert p.leg_length == pytest.approx(0.039 + (438.6 + 368.5) / 1735, rel=1e-12)
    assert p.toe - p.heel == pytest.approx(228.3 / 1735, rel=1e-12)  # a 13 cm foot
    assert p.foot_width == pytest.approx(0.055, rel=1e-12)
    assert p.flywheel_inertia < 1.0  # not the preset's 10 kg m^2
    assert "EXTRAPOLATED" in body.sources["model"]


def test_base_body_keeps_its_other_fields():
    from dataclasses import replace

    from pushrecovery.presets import load_params

    base = replace(load_params(), torque_max=42.0, gravity=9.8)
    body = person_params(70.0, 1.7, "male", base=base)
    assert body.params.torque_max == 42.0 and body.params.gravity == 9.8
    assert body.sources["torque_max"].startswith("base body given")


@pytest.mark.parametrize(
    ("args", "kwargs", "name"),
    [
        ((0.0, 1.7, "male"), {}, "mass"),
        ((-1.0, 1.7, "male"), {}, "mass"),
        ((501.0, 1.7, "male"), {}, "mass"),
        ((math.nan, 1.7, "male"), {}, "mass"),
        ((70.0, 0.49, "male"), {}, "height"),
        ((70.0, 2.51, "male"), {}, "height"),
        ((70.0, "tall", "male"), {}, "height"),
        ((70.0, 1.7, "Male"), {}, "sex"),
        ((70.0, 1.7, "x"), {}, "sex"),
        ((70.0, 1.7, "male"), {"ankle_from_heel": 1.0}, "ankle_from_heel"),
    ],
)
def test_bad_input_names_the_parameter(args, kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        person_params(*args, **kwargs)


# de Leva 1996 Table 4 as an independent transcription gives it (R. Gurchiek's deleva.m, 2018:
# fractions, here in % and mm): (length, mass, CoM, r_sag, r_trans, r_long) per sex
# (female, male). Its 'x' is the table's sagittal column, 'z' the transverse, 'y' the
# longitudinal (for the foot, 'z' sagittal, 'y' transverse, 'x' longitudinal).
TRANSCRIBED = {
    "head": ((243.7, 6.68, 48.41, 27.1, 29.5, 26.1), (242.9, 6.94, 50.02, 30.3, 31.5, 26.1)),
    "trunk": ((614.8, 42.57, 49.64, 30.7, 29.2, 14.7), (603.3, 43.46, 51.38, 32.8, 30.6, 16.9)),
    "trunk_shoulders": (
        (497.9, 42.57, 37.82, 37.9, 36.1, 18.2),
        (515.5, 43.46, 43.10, 38.4, 35.8, 19.7),
    ),
    "upper_arm": ((275.1, 2.55, 57.54, 27.8, 26.0, 14.8), (281.7, 2.71, 57.72, 28.5, 26.9, 15.8)),
    "forearm": ((264.3, 1.38, 45.59, 26.1, 25.7, 9.4), (268.9, 1.62, 45.74, 27.6, 26.5, 12.1)),
    "hand": ((78.0, 0.56, 74.74, 53.1, 45.4, 33.5), (86.2, 0.61, 79.00, 62.8, 51.3, 40.1)),
    "thigh": ((368.5, 14.78, 36.12, 36.9, 36.4, 16.2), (422.2, 14.16, 40.95, 32.9, 32.9, 14.9)),
    "shank": ((438.6, 4.81, 43.52, 26.7, 26.3, 9.2), (440.3, 4.33, 43.95, 25.1, 24.6, 10.2)),
    "foot": ((228.3, 1.29, 40.14, 29.9, 27.9, 13.9), (258.1, 1.37, 44.15, 25.7, 24.5, 12.4)),
}


def test_every_number_of_the_table_agrees_with_an_independent_transcription():
    from pushrecovery.anthropometry import DE_LEVA, STATURE

    assert dict(STATURE) == {"female": 1735.0, "male": 1741.0}
    for sex, column in (("female", 0), ("male", 1)):
        assert set(DE_LEVA[sex]) == set(TRANSCRIBED)
        for name, rows in TRANSCRIBED.items():
            assert tuple(DE_LEVA[sex][name]) == pytest.approx(rows[column], abs=1e-9), (sex, name)
