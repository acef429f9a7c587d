"""Properties of the planar CoP (ankle) and CMP (hip) margins (hypothesis, derandomised).

Symmetry (mirror y → −y, rotation of feet and state together), monotonicity in the foot (a
bigger foot or a wider stance never shrinks a region), CMP ⊇ CoP, and monotonicity in the push
size along any direction (the margin is concave along every line: the signed distance to a
convex set).
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.ground import FootPose, Support, convex_hull
from pushrecovery.surfaces.plane import cmp_margin_xy, cop_margin_xy

# Margins are signed distances of O(0.1-1 m) points, computed with a few dozen flops (and a hull
# or a rotation of O(1 m) coordinates): 1e-12 m is ~1e4 ulps of 1 m, far below any real error
# (a wrongly placed edge or box moves margins by ≥ 1e-4 m in these ranges).
ROUND = 1e-12

lengths = st.floats(0.02, 0.25)
positions = st.floats(-1.0, 1.0)
velocities = st.floats(-2.0, 2.0)
stances = st.sampled_from(["left", "right", "double"])


@st.composite
def roll_axes(draw):
    """Roll-axis overrides, different from the pitch axis (or zero torque)."""
    return {
        "torque_max_roll": draw(st.sampled_from([0.0, 20.0, 50.0, 100.0, 180.0])),
        "flywheel_inertia_roll": draw(st.floats(1.0, 20.0)),
        "flywheel_angle_max_roll": draw(st.floats(0.2, 1.5)),
    }


@st.composite
def polygon_feet(draw, symmetric=False):
    """A convex foot around its ankle: the hull of 8 points at jittered headings, as vertices.

    Within 0.09 m of the ankle, so that feet 0.2 m apart never overlap (which is refused).
    """
    radii = draw(st.lists(st.floats(0.02, 0.09), min_size=8, max_size=8))
    jitter = draw(st.lists(st.floats(-0.3, 0.3), min_size=8, max_size=8))
    headings = [2 * math.pi * k / 8 + j for k, j in enumerate(jitter)]
    points = [(r * math.cos(h), r * math.sin(h)) for r, h in zip(radii, headings, strict=True)]
    if symmetric:
        points += [(x, -y) for x, y in points]
    return convex_hull(points).to_list()


def margins(x, y, xdot, ydot, support, params):
    return (
        float(cop_margin_xy(x, y, xdot, ydot, support, params)),
        float(cmp_margin_xy(x, y, xdot, ydot, support, params)),
    )


@given(
    foot=polygon_feet(),
    roll=roll_axes(),
    stance_width=st.floats(0.19, 0.5),  # feet within 0.09 m of their ankles never overlap
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_mirror_maps_left_onto_right_and_double_onto_itself(foot, roll, stance_width, state):
    # Any foot: the right foot is the left one mirrored, so y → −y swaps the single stances.
    p = load_params(overrides={"foot_polygon": foot, "stance_width": stance_width, **roll})
    x, y, xdot, ydot = state
    for stance, image in (("left", "right"), ("right", "left"), ("double", "double")):
        here = margins(x, y, xdot, ydot, Support.from_params(p, stance), p)
        there = margins(x, -y, xdot, -ydot, Support.from_params(p, image), p)
        assert there == pytest.approx(here, abs=ROUND)


@given(
    heel=st.floats(-0.1, -0.01),
    toe=st.floats(0.02, 0.3),
    width=st.floats(0.03, 0.2),
    foot=polygon_feet(symmetric=True),
    use_polygon=st.booleans(),
    yaw=st.floats(-1.0, 1.0),
    roll=roll_axes(),
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_symmetric_foot_is_mirror_symmetric_about_its_own_axis(
    heel, toe, width, foot, use_polygon, yaw, roll, state
):
    # A foot symmetric about its x axis, alone: mirroring the state about the foot's axis (the
    # line through the ankle along its heading) leaves both margins unchanged.
    shape = (
        {"foot_polygon": foot} if use_polygon else {"heel": heel, "toe": toe, "foot_width": width}
    )
    p = load_params(overrides={**shape, **roll})
    ankle = np.array([0.1, 0.2])
    support = Support.from_params(p, "left", left=FootPose(*ankle, yaw))
    axis = np.array([math.cos(yaw), math.sin(yaw)])
    reflect = 2.0 * np.outer(axis, axis) - np.eye(2)  # reflection about the foot's axis
    x, y, xdot, ydot = state
    r, v = np.array([x, y]), np.array([xdot, ydot])
    r_image, v_image = ankle + reflect @ (r - ankle), reflect @ v
    here = margins(*r, *v, support, p)
    there = margins(*r_image, *v_image, support, p)
    assert there == pytest.approx(here, abs=ROUND)


@given(
    foot=polygon_feet(),
    roll=roll_axes(),
    stance=stances,
    left=st.tuples(st.floats(-0.2, 0.2), st.floats(0.1, 0.3), st.floats(-1.0, 1.0)),
    right=st.tuples(st.floats(-0.2, 0.2), st.floats(-0.3, -0.1), st.floats(-1.0, 1.0)),
    turn=st.floats(-math.pi, math.pi),
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_rotating_feet_and_state_together_keeps_margins(
    foot, roll, stance, left, right, turn, state
):
    # The margins are geometric: turning the feet's poses and the CoM state by the same yaw
    # about the origin changes nothing (the hip box turns with the stance's heading).
    p = load_params(overrides={"foot_polygon": foot, **roll})
    c, s = math.cos(turn), math.sin(turn)

    def rotate(vx, vy):
        return c * vx - s * vy, s * vx + c * vy

    def turned(pose):
        # The same heading, wrapped into [-pi, pi] (a FootPose refuses more than half a turn).
        return FootPose(*rotate(pose[0], pose[1]), math.remainder(pose[2] + turn, 2 * math.pi))

    here = Support.from_params(p, stance, left=FootPose(*left), right=FootPose(*right))
    there = Support.from_params(p, stance, left=turned(left), right=turned(right))
    x, y, xdot, ydot = state
    assert margins(*rotate(x, y), *rotate(xdot, ydot), there, p) == pytest.approx(
        margins(x, y, xdot, ydot, here, p), abs=ROUND
    )


@given(
    heel=st.floats(-0.1, -0.01),
    toe=st.floats(0.02, 0.3),
    width=st.floats(0.03, 0.15),
    stance_width=st.floats(0.26, 0.6),  # wider than the widest foot below: no overlap
    more=st.tuples(
        st.floats(0.0, 0.1), st.floats(0.0, 0.1), st.floats(0.0, 0.1), st.floats(0.0, 0.3)
    ),
    roll=roll_axes(),
    stance=stances,
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_bigger_rectangular_foot_never_shrinks_a_region(
    heel, toe, width, stance_width, more, roll, stance, state
):
    small = load_params(
        overrides={
            "heel": heel,
            "toe": toe,
            "foot_width": width,
            "stance_width": stance_width,
            **roll,
        }
    )
    longer_heel, longer_toe, wider, spread = more
    bigger = [
        {"heel": heel - longer_heel},
        {"toe": toe + longer_toe},
        {"foot_width": width + wider},
    ]
    if stance == "double":  # a wider stance moves a single foot, but grows the double support
        bigger.append({"stance_width": stance_width + spread})
    before = margins(*state, Support.from_params(small, stance), small)
    for change in bigger:
        big = load_params(
            overrides={
                "heel": heel,
                "toe": toe,
                "foot_width": width,
                "stance_width": stance_width,
                **roll,
                **change,
            }
        )
        after = margins(*state, Support.from_params(big, stance), big)
        assert after[0] >= before[0] - ROUND
        assert after[1] >= before[1] - ROUND


@given(
    foot=polygon_feet(),
    extra=st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3)),
    roll=roll_axes(),
    stance=stances,
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_bigger_polygon_foot_never_shrinks_a_region(foot, extra, roll, stance, state):
    # The foot grown by one more vertex (its hull with a point anywhere) contains the old foot.
    small = load_params(overrides={"foot_polygon": foot, **roll})
    grown = convex_hull([*foot, extra]).to_list()
    big = load_params(overrides={"foot_polygon": grown, **roll})
    try:
        bigger = Support.from_params(big, stance)
    except InvalidParameterError:  # grown feet that overlap in double support are refused
        assume(False)
    before = margins(*state, Support.from_params(small, stance), small)
    after = margins(*state, bigger, big)
    assert after[0] >= before[0] - ROUND
    assert after[1] >= before[1] - ROUND


@given(
    foot=polygon_feet(),
    roll=roll_axes(),
    torque=st.floats(0.0, 300.0),
    stance=stances,
    yaw=st.floats(-math.pi, math.pi),
    state=st.tuples(positions, positions, velocities, velocities),
)
def test_hip_region_contains_ankle_region(foot, roll, torque, stance, yaw, state):
    p = load_params(overrides={"foot_polygon": foot, "torque_max": torque, **roll})
    support = Support.from_params(
        p, stance, left=FootPose(0.0, 0.1, yaw), right=FootPose(0.0, -0.1, -0.5 * yaw)
    )
    cop, cmp = margins(*state, support, p)
    assert cmp >= cop - ROUND
    if torque == 0.0 and roll["torque_max_roll"] == 0.0:  # no hip authority: the same region
        assert cmp == pytest.approx(cop, abs=ROUND)


@given(
    foot=polygon_feet(),
    roll=roll_axes(),
    stance=stances,
    heading=st.floats(-math.pi, math.pi),
    speeds=st.lists(st.floats(0.001, 6.0), min_size=3, max_size=12, unique=True),
)
def test_margins_fall_with_push_size_along_any_direction(foot, roll, stance, heading, speeds):
    # A push of speed v along a heading from rest over the stance's ankle puts ξ at
    # ankle + (v/ω) d. Beyond the region the margin only falls as v grows (a bigger push never
    # recovers when a smaller one does not), and it is concave in v everywhere.
    p = load_params(overrides={"foot_polygon": foot, **roll})
    support = Support.from_params(p, stance)
    x, y = support.ankle
    d = np.array([math.cos(heading), math.sin(heading)])
    v = np.array(sorted({0.0, *speeds, 10.0}))  # 10 m/s: ξ 3 m away, outside every region
    for margin_of in (cop_margin_xy, cmp_margin_xy):
        m = margin_of(x, y, v * d[0], v * d[1], support, p)
        assert m[0] > 0.0  # no push: ξ at the ankle, inside
        assert m[-1] < 0.0
        outside = np.flatnonzero(m <= 0.0)
        first = outside[0]
        assert np.all(m[first:] <= 0.0)  # once lost, lost for every bigger push
        assert np.all(np.diff(m[first:]) <= ROUND)
        # Concave along the line: each interior sample is above the chord of its neighbours.
        for i in range(1, len(v) - 1):
            w = (v[i] - v[i - 1]) / (v[i + 1] - v[i - 1])
            assert m[i] >= (1 - w) * m[i - 1] + w * m[i + 1] - ROUND


@pytest.mark.parametrize("corners", [3, 4, 5, 8, 9, 13])
def test_the_compiled_margin_equals_the_exact_signed_distance(corners):
    # Large arrays take the compiled kernel, whose edge loop is specialised for 4 and 8 edges
    # (tables padded by repeating a row) and general above; each must give the numpy signed
    # distance of ground.polygon, inside, beside edges and beside corners.
    from pushrecovery.ground import convex_polygon
    from pushrecovery.surfaces.plane import capture_margin_xy

    angle = np.linspace(0.0, 2.0 * math.pi, corners, endpoint=False) + 0.3
    ellipse = np.column_stack([0.15 * np.cos(angle) + 0.02, 0.08 * np.sin(angle)])  # convex
    polygon = convex_polygon("polygon", ellipse)
    rng = np.random.default_rng(corners)
    n = 1 << 16  # above the size that takes the compiled pass
    x, y = rng.normal(0.0, 0.08, n), rng.normal(0.0, 0.08, n)
    xdot, ydot = rng.normal(0.0, 0.1, n), rng.normal(0.0, 0.1, n)
    omega = 3.0
    compiled = capture_margin_xy(x, y, xdot, ydot, omega, polygon)
    exact = polygon.signed_distance(x + xdot / omega, y + ydot / omega)
    assert 0.2 < np.mean(compiled > 0.0) < 0.8  # both sides sampled
    np.testing.assert_allclose(compiled, exact, rtol=0.0, atol=ROUND)
