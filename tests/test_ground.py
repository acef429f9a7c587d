"""Feet, support polygons and the signed distance on the ground plane."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.ground import FootPose, Support, convex_hull, convex_polygon, rectangle
from pushrecovery.ground.polygon import MIN_EDGE
from pushrecovery.params import BodyParams

P = load_params()
FOOT = [[-0.05, -0.04], [0.2, -0.05], [0.24, 0.0], [0.2, 0.05], [-0.05, 0.04]]


def brute_signed_distance(vertices, px, py, samples=4000):
    """Distance to a densely sampled boundary, sign from the half-planes (independent code)."""
    v = np.asarray(vertices, float)
    t = np.linspace(0.0, 1.0, samples, endpoint=False)
    boundary = np.vstack(
        [a + t[:, None] * (b - a) for a, b in zip(v, np.roll(v, -1, 0), strict=True)]
    )
    distance = np.hypot(boundary[:, 0] - px, boundary[:, 1] - py).min()
    edges = np.roll(v, -1, 0) - v
    inside = all(
        (e[0] * (py - a[1]) - e[1] * (px - a[0])) > 0 for a, e in zip(v, edges, strict=True)
    )
    return distance if inside else -distance


@pytest.mark.parametrize(
    "point", [(0.0, 0.0), (0.1, 0.02), (0.3, 0.0), (0.3, 0.2), (-0.2, -0.3), (0.22, 0.049)]
)
def test_signed_distance_matches_dense_boundary(point):
    polygon = convex_polygon("foot_polygon", FOOT)
    # The boundary is sampled every <= 0.25 mm / 4000: the brute force is within 1e-4 m.
    assert float(polygon.signed_distance(*point)) == pytest.approx(
        brute_signed_distance(polygon.vertices, *point), abs=1e-4
    )


def test_signed_distance_vectorised_equals_scalar_calls():
    polygon = convex_polygon("foot_polygon", FOOT)
    rng = np.random.default_rng(0)
    px, py = rng.uniform(-0.5, 0.5, 200), rng.uniform(-0.5, 0.5, 200)
    many = polygon.signed_distance(px, py)
    one = [float(polygon.signed_distance(a, b)) for a, b in zip(px, py, strict=True)]
    np.testing.assert_array_equal(many, one)


def test_clockwise_input_is_reversed_and_collinear_vertices_dropped():
    square = [[-1, -1], [-1, 0], [-1, 1], [1, 1], [1, -1]]  # clockwise, (-1, 0) collinear
    polygon = convex_polygon("p", square)
    assert polygon.area == pytest.approx(4.0)
    assert len(polygon.vertices) == 4


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0], [1, 0]], "at least 3"),
        ([[0, 0], [1, 0], [float("nan"), 1]], "vertex 2 is not finite"),
        ([[0, 0], [1, 0], [1, 0], [0, 1]], "vertex 2 repeats vertex 1"),
        ([[0, 0], [1, 1], [1, 0], [0, 1]], "self-intersecting: edge 0-1 crosses edge 2-3"),
        ([[0, 0], [2, 0], [1, 0.2], [1, 2]], "not convex at vertex 2"),
        ([[0, 0], [1, 0], [2, 0]], "degenerate: area 0"),
        ([[0, 0], [1e-4, 0], [0, 1e-4]], "degenerate: area 5e-09 m², at least 1e-06"),
        ([[0, 0], [1, 0], [1, 1e-7], [0, 1]], "vertex 2 repeats vertex 1"),
        ([[0, 0], [1e4, 0], [0, 1]], r"vertex 1 \(10000, 0\) lies beyond ±1000 m"),
        ("abc", "must be"),
    ],
)
def test_bad_polygons_name_the_fault(vertices, message):
    with pytest.raises(InvalidParameterError, match=message):
        convex_polygon("foot_polygon", vertices)


def test_pentagram_is_self_intersecting():
    star = [[math.cos(a), math.sin(a)] for a in np.arange(5) * 4 * math.pi / 5]
    with pytest.raises(InvalidParameterError, match="self-intersecting"):
        convex_polygon("foot_polygon", star)


def test_foot_polygon_must_contain_the_ankle():
    with pytest.raises(InvalidParameterError, match=r"contain the ankle \(0, 0\)"):
        load_params(
            overrides={"foot_polygon": [[-0.05, 0.01], [0.2, 0.01], [0.2, 0.1], [-0.05, 0.1]]}
        )


def test_foot_polygon_sets_heel_toe_width_and_refuses_both():
    params = load_params(overrides={"foot_polygon": FOOT})
    assert (params.heel, params.toe, params.foot_width) == (-0.05, 0.24, 0.1)
    with pytest.raises(InvalidParameterError, match="either foot_polygon or toe"):
        load_params(overrides={"foot_polygon": FOOT, "toe": 0.3})
    with pytest.raises(InvalidParameterError, match="vertex 1 must be a pair"):
        load_params(overrides={"foot_polygon": [[0, 0], [1], [0, 1]]})


def test_foot_polygon_from_toml(tmp_path):
    path = tmp_path / "body.toml"
    path.write_text(f"foot_polygon = {FOOT}\n")
    params = load_params(file=path)
    assert params.toe == 0.24
    assert params.to_dict()["foot_polygon"][2] == [0.24, 0.0]


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ({"foot_width": 0.0}, "foot_width must be > 0"),
        ({"stance_width": -0.1}, "stance_width must be > 0"),
        ({"stance_width": 2.5}, "stance_width must be < 2 leg_length"),
        ({"torque_max_roll": -1.0}, r"torque_max_roll must be in \[0, 100000\]"),
        ({"flywheel_inertia_roll": 0.0}, r"flywheel_inertia_roll must be in \[1e-06, 10000\]"),
        ({"flywheel_angle_max_roll": float("nan")}, "flywheel_angle_max_roll must be a finite"),
        ({"foot_polygon": "square"}, "foot_polygon must be a list"),
    ],
)
def test_bad_ground_parameters(override, message):
    with pytest.raises(InvalidParameterError, match=message):
        load_params(overrides=override)


def test_roll_axis_defaults_to_pitch():
    assert (P.flywheel_inertia_roll, P.torque_max_roll, P.flywheel_angle_max_roll) == (
        P.flywheel_inertia,
        P.torque_max,
        P.flywheel_angle_max,
    )


def test_double_support_is_the_hull_of_both_feet():
    support = Support.from_params(P)
    np.testing.assert_allclose(
        support.polygon.vertices, [[-0.05, -0.15], [0.15, -0.15], [0.15, 0.15], [-0.05, 0.15]]
    )
    left = Support.from_params(P, "left")
    assert left.polygon.area == pytest.approx(0.02)
    assert left.ankle == (0.0, 0.1)


def test_right_foot_is_the_mirror_of_the_left():
    params = load_params(
        overrides={"foot_polygon": [[-0.05, -0.03], [0.2, -0.05], [0.2, 0.06], [-0.05, 0.02]]}
    )
    right = Support.from_params(params, "right", right=FootPose(0.0, 0.0))
    np.testing.assert_allclose(
        sorted(map(tuple, right.polygon.vertices)),
        sorted((x, -y) for x, y in params.foot_polygon),
    )


def test_yawed_feet_in_double_support():
    support = Support.from_params(
        P, left=FootPose(0.0, 0.1, math.radians(20)), right=FootPose(0.0, -0.1, math.radians(-20))
    )
    # Splayed feet: the outer toe corner of the left foot is at (0.15, 0.05) turned by 20°.
    c, s = math.cos(math.radians(20)), math.sin(math.radians(20))
    corner = (0.15 * c - 0.05 * s, 0.1 + 0.15 * s + 0.05 * c)
    assert float(support.polygon.signed_distance(*corner)) == pytest.approx(0.0, abs=1e-15)
    assert support.polygon.ymax == pytest.approx(corner[1])
    assert support.yaw == pytest.approx(0.0)


def test_lifting_a_foot_keeps_that_sole_and_the_poses():
    """``Support.single`` from double support gives the single support ``from_params`` builds."""
    params = load_params(
        overrides={"foot_polygon": [[-0.05, -0.03], [0.2, -0.05], [0.2, 0.06], [-0.05, 0.02]]}
    )
    poses = {"left": FootPose(0.3, 0.2, 0.4), "right": FootPose(0.1, -0.1, -2.5)}
    double = Support.from_params(params, **poses)
    for side in ("left", "right"):
        lifted = double.single(side)
        built = Support.from_params(params, side, **poses)
        assert lifted.stance == side and (lifted.left, lifted.right) == (double.left, double.right)
        np.testing.assert_array_equal(lifted.polygon.vertices, built.polygon.vertices)
        np.testing.assert_array_equal(lifted.polygon.offsets, built.polygon.offsets)
        assert lifted.single(side) is lifted and lifted.soles is None
        # From the other single support the sole is placed anew: the same numbers.
        other = built.single("right" if side == "left" else "left")
        np.testing.assert_array_equal(
            other.polygon.vertices, double.single(other.stance).polygon.vertices
        )
    for bad in ("double", "both", None, 1):
        with pytest.raises(InvalidParameterError, match="stance must be 'left' or 'right'"):
            double.single(bad)


def test_double_support_refuses_overlapping_or_distant_feet():
    with pytest.raises(InvalidParameterError, match=r"the feet overlap by 0\.05 m"):
        Support.from_params(load_params(overrides={"stance_width": 0.05}))
    with pytest.raises(InvalidParameterError, match="the feet overlap"):
        Support.from_params(P, left=FootPose(0.0, 0.0), right=FootPose(0.0, 0.0))
    with pytest.raises(InvalidParameterError, match="ankles are 3 m apart"):
        Support.from_params(P, left=FootPose(3.0, 0.0), right=FootPose(0.0, 0.0))
    # One foot on the ground: where the other hangs does not matter; touching feet are fine.
    Support.from_params(P, "left", left=FootPose(0.0, 0.0), right=FootPose(0.0, 0.0))
    Support.from_params(load_params(overrides={"stance_width": 0.1}))


def test_pose_limits_and_yaw_in_radians():
    assert FootPose(0.0, 0.0, -math.pi).yaw == -math.pi
    assert FootPose(0.0, 0.0, math.pi).yaw == math.pi
    for degrees in (10.0, -90.0, 7.0, math.pi + 1e-9):  # degrees by mistake, or past ±π
        with pytest.raises(InvalidParameterError, match=r"yaw must be within \[−π, π\] rad"):
            FootPose(0.0, 0.09, degrees)
    with pytest.raises(InvalidParameterError, match=r"yaw must be within \[−π, π\] rad"):
        FootPose.parse("--left-foot", "0,0.09,10")
    with pytest.raises(InvalidParameterError, match="foot pose x must be within"):
        FootPose(1e300, 0.0)


def test_bad_stance_and_pose():
    with pytest.raises(InvalidParameterError, match="stance must be one of"):
        Support.from_params(P, "both")
    with pytest.raises(InvalidParameterError, match="foot pose yaw must be a finite"):
        FootPose(0.0, 0.0, float("inf"))
    with pytest.raises(InvalidParameterError, match="--left-foot must be X,Y"):
        FootPose.parse("--left-foot", "1")
    with pytest.raises(InvalidParameterError, match="--left-foot must be X,Y or X,Y,YAW numbers"):
        FootPose.parse("--left-foot", "a,b")


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=3, max_size=30, unique=True)
)
def test_hull_contains_its_points_or_refuses(points):
    try:
        hull = convex_hull(points)
    except InvalidParameterError as error:
        assert "degenerate" in str(error)
        return
    xs, ys = np.array(points).T
    # Every input point is inside or on the hull, up to the merge of vertices closer than
    # MIN_EDGE (1 µm): a merged point lies at most that far outside.
    assert (hull.signed_distance(xs, ys) >= -MIN_EDGE).all()
    assert hull.area > 0


def test_grown_support_function():
    foot = rectangle(-0.05, 0.15, 0.1)
    grown = foot.grown(0.03, 0.01, yaw=0.3)
    for angle in np.linspace(0, 2 * math.pi, 17):
        d = np.array([math.cos(angle), math.sin(angle)])
        axes = np.array([[math.cos(0.3), math.sin(0.3)], [-math.sin(0.3), math.cos(0.3)]])
        expected = foot.support(*d) + 0.03 * abs(d @ axes[0]) + 0.01 * abs(d @ axes[1])
        assert grown.support(*d) == pytest.approx(expected, abs=1e-12)


def test_params_stay_hashable_and_comparable():
    a = load_params(overrides={"foot_polygon": FOOT})
    b = load_params(overrides={"foot_polygon": FOOT})
    assert a == b and hash(a) == hash(b)
    assert isinstance(BodyParams(**{**P.to_dict(), "foot_width": 0.12}), BodyParams)


def test_one_point_queries_equal_the_vectorised_ones():
    # The plain-Python path of a controller's tick against the numpy path, on random hulls:
    # inside, outside beside an edge and outside at a corner.
    rng = np.random.default_rng(7)
    for _ in range(200):
        polygon = convex_hull(rng.normal(size=(int(rng.integers(3, 12)), 2)))
        points = rng.normal(scale=2.0, size=(40, 2))
        exact = polygon.signed_distance(points[:, 0], points[:, 1])
        one = [polygon.point_signed_distance(float(x), float(y)) for x, y in points]
        np.testing.assert_allclose(one, exact, rtol=0.0, atol=1e-14)
        for (x, y), distance in zip(points, exact, strict=True):
            nx, ny = polygon.nearest_point(float(x), float(y))
            assert math.hypot(nx - x, ny - y) == pytest.approx(max(0.0, -distance), abs=1e-14)
    assert math.isnan(polygon.point_signed_distance(math.nan, 0.0))
