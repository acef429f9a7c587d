"""The base-of-support polygon per frame: foot models, CSV vertices, stated feet (issue 18)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.analysis.base_polygon import (
    FootModel,
    base_from_feet,
    base_from_params,
    base_from_vertices,
    foot_soles,
)
from pushrecovery.analysis.recording import Foot, fixed_feet
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.ground import Support, convex_hull

P = load_params()


def _foot(name: str, heel: tuple[float, float], toe: tuple[float, float], n: int = 3) -> Foot:
    """A flat foot on the floor, ankle 5 cm ahead of the heel on its axis, 2 cm to its side."""
    h, t = np.array(heel), np.array(toe)
    u = (t - h) / np.linalg.norm(t - h)
    side = 1.0 if name == "left" else -1.0
    a = h + 0.05 * u + side * 0.02 * np.array([-u[1], u[0]])

    def at(p: np.ndarray, z: float) -> np.ndarray:
        return np.tile([p[0], p[1], z], (n, 1))

    return Foot(name, at(h, 0.0), at(t, 0.0), at(a, 0.07))


def _rotated(foot: Foot, angle: float) -> Foot:
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return Foot(foot.name, foot.heel @ turn.T, foot.toe @ turn.T, foot.ankle @ turn.T)


def test_one_foot_is_the_rectangle_of_the_model() -> None:
    foot = _foot("left", (0.0, 0.1), (0.2, 0.1))
    soles = foot_soles(foot, FootModel(width=0.08, heel_offset=0.01, toe_offset=0.05))
    expected = [[-0.01, 0.06], [0.25, 0.06], [0.25, 0.14], [-0.01, 0.14]]
    np.testing.assert_allclose(soles[0], expected, atol=1e-12)
    base = base_from_feet((foot,), FootModel(width=0.08), contact_height=0.02)
    np.testing.assert_allclose(base.area, 0.2 * 0.08)
    assert base.counts.tolist() == [4, 4, 4]


def test_lateral_edge_through_the_ankle_marker() -> None:
    left = _foot("left", (0.0, 0.1), (0.2, 0.1))  # ankle marker 2 cm to the left of the axis
    sole = foot_soles(left, FootModel(width=0.1, lateral="ankle", lateral_offset=0.01))[0]
    np.testing.assert_allclose(sole[:, 1].max(), 0.1 + 0.03)
    np.testing.assert_allclose(sole[:, 1].min(), 0.1 + 0.03 - 0.1)
    right = _foot("right", (0.0, -0.1), (0.2, -0.1))
    sole = foot_soles(right, FootModel(width=0.1, lateral="ankle"))[0]
    np.testing.assert_allclose([sole[:, 1].min(), sole[:, 1].max()], [-0.12, -0.02])


def test_double_support_hull_areas() -> None:
    feet = fixed_feet(4, 0.0, 0.0, -0.05, 0.15, 0.2)  # soles 0.2 x 0.1, ankles 0.2 apart
    base = base_from_feet(feet, FootModel(width=0.1), contact_height=0.02)
    np.testing.assert_allclose(base.area, 0.2 * 0.3)  # a rectangle 0.2 x 0.3
    assert (base.counts == 4).all()  # collinear heel and toe corners dropped
    # Staggered: the left foot 0.1 ahead. Hull by hand: the 0.3 x 0.3 box minus two corner
    # triangles of legs 0.1 x 0.2 (a hexagon).
    left = _foot("left", (0.05, 0.1), (0.25, 0.1))
    right = _foot("right", (-0.05, -0.1), (0.15, -0.1))
    base = base_from_feet((left, right), FootModel(width=0.1), contact_height=0.02)
    np.testing.assert_allclose(base.area, 0.3 * 0.3 - 2 * 0.5 * 0.1 * 0.2, atol=1e-12)
    assert base.counts[0] == 6
    assert base.sole is not None
    np.testing.assert_allclose(base.sole, (-0.05, 0.15, 0.05, 0.05), atol=1e-12)


def test_a_lifted_foot_and_missing_markers() -> None:
    left = _foot("left", (0.0, 0.1), (0.2, 0.1), n=4)
    right = _foot("right", (0.0, -0.1), (0.2, -0.1), n=4)
    right.heel[1:3, 2] = right.toe[1:3, 2] = 0.10  # lifted in frames 1 and 2
    left.toe[3] = np.nan  # a missing marker: the base is unknown
    base = base_from_feet((left, right), FootModel(width=0.1), contact_height=0.02)
    np.testing.assert_allclose(base.area[:3], [0.06, 0.02, 0.02])
    assert base.counts[3] == 0 and np.isnan(base.area[3])
    assert base.polygon(3) is None
    assert base.supporting is not None and base.supporting[1].tolist() == [True, False]


def test_rotating_the_lab_rotates_the_base() -> None:
    left = _foot("left", (0.05, 0.1), (0.25, 0.12))
    right = _foot("right", (-0.05, -0.1), (0.15, -0.14))
    model = FootModel(width=0.09, toe_offset=0.03)
    base = base_from_feet((left, right), model, contact_height=0.02)
    angle = 0.7
    turned = base_from_feet(
        (_rotated(left, angle), _rotated(right, angle)), model, contact_height=0.02
    )
    np.testing.assert_allclose(turned.area, base.area, rtol=1e-12)
    c, s = math.cos(angle), math.sin(angle)
    polygon = base.polygon(0)
    assert polygon is not None
    expected = convex_hull(polygon.vertices @ np.array([[c, -s], [s, c]]).T)
    got = turned.polygon(0)
    assert got is not None
    np.testing.assert_allclose(
        np.sort(got.vertices, axis=0), np.sort(expected.vertices, axis=0), atol=1e-12
    )


def test_vertex_columns_are_hulled_per_frame() -> None:
    rng = np.random.default_rng(3)
    points = rng.normal(scale=0.1, size=(50, 9, 2))
    points[5, 2:] = np.nan  # two vertices left: unknown
    points[6, :, 1] = 0.0  # collinear: unknown
    points[7, 4] = np.nan  # an absent vertex
    base = base_from_vertices(points)
    for i in range(50):
        if i in (5, 6):
            assert base.counts[i] == 0
            continue
        finite = points[i][np.isfinite(points[i]).all(axis=1)]
        hull = convex_hull(finite)
        assert base.counts[i] == len(hull.vertices)
        np.testing.assert_allclose(base.area[i], hull.area, rtol=1e-12)


def test_stated_feet_are_the_library_support() -> None:
    base = base_from_params(P, 5, stance="left")
    support = Support.from_params(P, "left")
    np.testing.assert_allclose(base.vertices[3], support.polygon.vertices)
    assert base.support is support and base.source == "stated feet"
    xmin, xmax, ymin, ymax = base.extents()
    np.testing.assert_allclose([xmin[0], xmax[0]], [P.heel, P.toe])
    np.testing.assert_allclose([ymin[0], ymax[0]], [0.1 - 0.05, 0.1 + 0.05])


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"width": 0.0}, "width"),
        ({"width": math.nan}, "width"),
        ({"heel_offset": 0.5}, "heel_offset"),
        ({"toe_offset": -1.0}, "toe_offset"),
        ({"lateral_offset": math.inf}, "lateral_offset"),
        ({"lateral": "medial"}, "lateral"),
    ],
)
def test_bad_foot_models_name_the_argument(kwargs: dict[str, object], name: str) -> None:
    with pytest.raises(InvalidParameterError, match=name):
        FootModel(**kwargs)  # type: ignore[arg-type]


def test_bad_inputs_name_the_argument() -> None:
    feet = fixed_feet(4, 0.0, 0.0, -0.05, 0.15, 0.2)
    with pytest.raises(InvalidParameterError, match="contact_height"):
        base_from_feet(feet, FootModel(), contact_height=-0.01)
    with pytest.raises(PushRecoveryError, match="model"):
        base_from_feet(feet, "rectangle", contact_height=0.02)  # type: ignore[arg-type]
    with pytest.raises(PushRecoveryError, match="feet"):
        base_from_feet((), FootModel(), contact_height=0.02)
    with pytest.raises(PushRecoveryError, match="foot"):
        foot_soles("left", FootModel())  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="vertices"):
        base_from_vertices(np.zeros((4, 2, 2)))
    with pytest.raises(InvalidParameterError, match="vertices"):
        base_from_vertices(np.full((4, 3, 2), np.inf))
    with pytest.raises(InvalidParameterError, match="vertices"):
        base_from_vertices(np.zeros((4, 3)))
    with pytest.raises(InvalidParameterError, match="n"):
        base_from_params(P, 0)
    with pytest.raises(InvalidParameterError, match="stance"):
        base_from_params(P, 3, stance="both")
    with pytest.raises(InvalidParameterError, match="frame"):
        base_from_params(P, 3).polygon(7)
