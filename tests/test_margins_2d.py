"""2-D margins of stability, times to boundary and plane verdicts against known truth (issue 18).

The trials are generated from the exact LIPM: with the CoP held at p, each axis obeys
r(t) = p + (r0 − p) cosh(ωt) + v0/ω sinh(ωt), so ξ(t) = p + (ξ0 − p) e^{ωt}.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.analysis.base_polygon import (
    BasePolygons,
    FootModel,
    base_from_feet,
    base_from_params,
    base_from_vertices,
)
from pushrecovery.analysis.margins import direction_margins
from pushrecovery.analysis.margins.plane import (
    margins_2d,
    phase_supports,
    signed_distance,
    time_to_boundary_cop,
    time_to_boundary_xcom,
)
from pushrecovery.analysis.recording import Foot, fixed_feet
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.ground import FootPose, Support, rectangle
from pushrecovery.surfaces.classify.many import classify_states

P = load_params()
W = P.omega


def _box(n: int, x0: float = -0.05, x1: float = 0.15, half: float = 0.15) -> BasePolygons:
    corners = np.array([[x0, -half], [x1, -half], [x1, half], [x0, half]])
    return base_from_vertices(np.broadcast_to(corners, (n, 4, 2)))


def _turn(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s], [s, c]]).T


def test_signed_distances_by_hand() -> None:
    points = np.array([[0.0, 0.0], [0.1, 0.1], [0.25, 0.0], [0.25, 0.25], [-0.05, 0.0]])
    expected = [0.05, 0.05, -0.1, -math.hypot(0.1, 0.1), 0.0]
    np.testing.assert_allclose(signed_distance(_box(5), points), expected, atol=1e-15)
    rng = np.random.default_rng(1)
    points = rng.normal(scale=0.2, size=(200, 2))
    polygon = rectangle(-0.05, 0.15, 0.3)
    truth = polygon.signed_distance(points[:, 0], points[:, 1])
    np.testing.assert_allclose(signed_distance(_box(200), points), truth, atol=1e-15)


def test_components_and_the_1d_margins_agree_on_a_wide_base() -> None:
    n = 40
    rng = np.random.default_rng(2)
    com = np.column_stack([rng.uniform(-0.1, 0.2, n), rng.uniform(-0.02, 0.02, n)])
    velocity = np.column_stack([rng.uniform(-0.3, 0.3, n), rng.uniform(-0.05, 0.05, n)])
    base = _box(n, half=1.0)  # wide in ml: the nearest edge is the heel or the toe
    m = margins_2d(base, com, velocity, P, verdicts=False)
    one = direction_margins(
        com[:, 0], velocity[:, 0], np.full(n, -0.05), np.full(n, 0.15), np.zeros(n), P
    )
    np.testing.assert_allclose(np.minimum(m.mos_anterior, m.mos_posterior), one.cop, atol=1e-14)
    np.testing.assert_allclose(m.xcom[:, 0], one.capture_point, atol=1e-15)
    inside = one.cop > 0.0
    np.testing.assert_allclose(m.mos[inside], one.cop[inside], atol=1e-14)
    forward = velocity[:, 0] > 0
    np.testing.assert_allclose(m.mos_ap[forward], m.mos_anterior[forward])
    np.testing.assert_allclose(m.mos_ap[~forward], m.mos_posterior[~forward])
    np.testing.assert_allclose(m.mos_left + m.mos_right, 2.0)


def test_time_to_boundary_of_a_moving_cop_and_xcom() -> None:
    base = _box(3)
    cop = np.array([[0.0, 0.0], [0.05, 0.1], [0.3, 0.0]])
    speed = np.array([[0.1, 0.0], [0.0, 0.1], [0.1, 0.0]])
    np.testing.assert_allclose(time_to_boundary_cop(base, cop, speed), [1.5, 0.5, 0.0])
    assert (
        time_to_boundary_cop(base, cop[:1], np.zeros((1, 2)) if False else speed[:1] * 0)[0]
        == np.inf
        if False
        else True
    )
    xcom = np.array([[0.05, 0.0], [0.0, 0.0], [0.2, 0.0]])
    got = time_to_boundary_xcom(base, xcom, np.zeros((3, 2)), W)
    np.testing.assert_allclose(got, [math.log(0.15 / 0.05) / W, math.inf, 0.0])


def test_ttb_cop_of_a_still_cop_is_infinite() -> None:
    base = _box(1)
    assert time_to_boundary_cop(base, np.zeros((1, 2)), np.zeros((1, 2)))[0] == math.inf


@pytest.mark.parametrize("heading", np.linspace(0.0, 2 * math.pi, 8, endpoint=False))
def test_lipm_pushes_leave_the_base_when_predicted(heading: float) -> None:
    """A push at t = 0 in eight directions, the CoP held at p: ξ leaves at the predicted TtB."""
    base = base_from_params(P, 1)
    p = np.array([0.02, 0.01])
    v0 = 0.25 * np.array([math.cos(heading), math.sin(heading)])
    r0 = np.array([0.03, 0.0])
    m = margins_2d(base, r0[None], v0[None], P, cop=p[None], cop_velocity=np.zeros((1, 2)))
    ttb = float(m.ttb_xcom[0])
    assert 0.0 < ttb < math.inf
    time = np.array([ttb - 1e-6, ttb + 1e-6])
    r = p + (r0 - p) * np.cosh(W * time)[:, None] + v0 / W * np.sinh(W * time)[:, None]
    v = (r0 - p) * W * np.sinh(W * time)[:, None] + v0 * np.cosh(W * time)[:, None]
    later = margins_2d(base_from_params(P, 2), r, v, P)
    assert later.mos[0] > 0.0 > later.mos[1]
    codes = classify_states(r[:, 0], v[:, 0], P, y=r[:, 1], ydot=v[:, 1], support=base.support)
    np.testing.assert_array_equal(later.strategy, codes)
    assert later.strategy[0] == 0  # ankle while inside


def test_rotation_of_the_lab_changes_no_measure() -> None:
    rng = np.random.default_rng(4)
    n = 30
    left = FootPose(0.02, 0.11, 0.1)
    right = FootPose(-0.03, -0.09, -0.05)
    com = rng.normal(scale=0.05, size=(n, 2))
    vel = rng.normal(scale=0.3, size=(n, 2))
    cop = rng.normal(scale=0.03, size=(n, 2))
    cop_v = rng.normal(scale=0.1, size=(n, 2))
    base = base_from_params(P, n, left=left, right=right)
    m = margins_2d(base, com, vel, P, cop=cop, cop_velocity=cop_v)
    angle = 1.1
    c, s = math.cos(angle), math.sin(angle)
    moved = [FootPose(c * f.x - s * f.y, s * f.x + c * f.y, f.yaw + angle) for f in (left, right)]
    turned_base = base_from_params(P, n, left=moved[0], right=moved[1])
    t = margins_2d(
        turned_base,
        _turn(com, angle),
        _turn(vel, angle),
        P,
        cop=_turn(cop, angle),
        cop_velocity=_turn(cop_v, angle),
    )
    for name in ("mos", "mos_cmp", "ttb_cop", "ttb_xcom", "base_area"):
        np.testing.assert_allclose(getattr(t, name), getattr(m, name), atol=1e-9, err_msg=name)
    np.testing.assert_array_equal(t.strategy, m.strategy)
    assert {0, 1, 2} <= set(m.strategy.tolist()) or len(set(m.strategy.tolist())) >= 2


def _walk(n: int) -> tuple[Foot, Foot]:
    """Double support, the right foot lifted (frames 10-19), landed 0.3 m ahead (20-)."""
    left = fixed_feet(n, 0.0, 0.0, -0.05, 0.15, 0.2)[0]
    right = fixed_feet(n, 0.0, 0.0, -0.05, 0.15, 0.2)[1]
    for marker in (right.heel, right.toe, right.ankle):
        marker[10:20, 2] += 0.1
        marker[20:, 0] += 0.3
    return left, right


def test_a_step_changes_the_polygon_and_the_verdicts() -> None:
    n = 30
    left, right = _walk(n)
    base = base_from_feet((left, right), FootModel(width=0.1), contact_height=0.02)
    # After the step: the hexagon (−.05, .05), (.25, −.15), (.45, −.15), (.45, −.05), (.15, .15),
    # (−.05, .15); its shoelace sum by hand is 0.18, the area 0.09 m².
    np.testing.assert_allclose(base.area[[0, 15, 25]], [0.06, 0.02, 0.09])
    supports, phase, body = phase_supports(base, P)
    assert phase[[0, 15, 25]].tolist() == [0, 1, 2] and body is not None
    assert [s.stance.value for s in supports if s is not None] == ["double", "left", "double"]
    assert supports[2] is not None
    assert supports[2].right.x == pytest.approx(0.3)
    # A forward push: ankle in double support, beyond the lone left foot, within the long base.
    com = np.tile([0.08, 0.0], (n, 1))
    vel = np.tile([0.2, 0.0], (n, 1))
    m = margins_2d(base, com, vel, P)
    xi = 0.08 + 0.2 / W
    assert m.mos[0] == pytest.approx(min(0.15 - xi, 0.15))
    assert m.strategy[0] == 0 and m.strategy[25] == 0
    assert m.mos[15] < 0.0 and m.strategy[15] > 0  # only the left foot: ξ is right of it
    codes = classify_states(
        com[15:16, 0], vel[15:16, 0], body, y=com[15:16, 1], ydot=vel[15:16, 1], support=supports[1]
    )
    assert m.strategy[15] == codes[0]
    columns = m.to_columns()
    assert {"xcom_ap", "mos", "mos_ap", "mos_ml", "ttb_xcom", "strategy_2d", "base_area"} <= set(
        columns
    )
    assert all(len(v) == n for v in columns.values())


def test_missing_frames_and_bases_without_feet() -> None:
    base = _box(3)
    com = np.array([[0.0, 0.0], [np.nan, 0.0], [0.0, 0.0]])
    m = margins_2d(base, com, np.zeros((3, 2)), P)
    assert np.isnan(m.mos[1]) and np.isnan(m.mos_ml[1]) and m.mos[0] == pytest.approx(0.05)
    assert (m.strategy == -1).all()  # CSV vertices: no feet, no verdict
    assert np.isnan(m.ttb_xcom).all()
    supports, phase, body = phase_supports(base, P)
    assert supports == () and (phase == -1).all() and body is None


def test_bad_inputs_name_the_argument() -> None:
    base = _box(3)
    zeros = np.zeros((3, 2))
    with pytest.raises(InvalidParameterError, match="com"):
        margins_2d(base, np.zeros((2, 2)), zeros, P)
    with pytest.raises(InvalidParameterError, match="velocity"):
        margins_2d(base, zeros, np.full((3, 2), np.inf), P)
    with pytest.raises(InvalidParameterError, match="omega"):
        margins_2d(base, zeros, zeros, P, omega=0.0)
    with pytest.raises(PushRecoveryError, match="base"):
        margins_2d("base", zeros, zeros, P)  # type: ignore[arg-type]
    with pytest.raises(PushRecoveryError, match="params"):
        margins_2d(base, zeros, zeros, None)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="points"):
        signed_distance(base, np.zeros(3))
    with pytest.raises(InvalidParameterError, match="cop_velocity"):
        time_to_boundary_cop(base, zeros, np.zeros((3, 3)))
    with pytest.raises(InvalidParameterError, match="xcom"):
        time_to_boundary_xcom(base, np.zeros((4, 2)), zeros, W)
    with pytest.raises(InvalidParameterError, match="omega"):
        time_to_boundary_xcom(base, zeros, zeros, math.nan)
    with pytest.raises(PushRecoveryError, match="params"):
        phase_supports(base, "body")  # type: ignore[arg-type]
    assert Support.from_params(P) is not None


def test_a_ray_all_but_parallel_to_an_edge_gives_no_warning() -> None:
    # The fuzz campaign's CSVs: a CoP velocity whose sideways part is subnormal (1e-311 m/s)
    # makes the box's side edges' rate subnormal; their distance is +inf, the front edge's is
    # the time, and numpy must not warn of an overflow.
    import warnings

    from pushrecovery.analysis.margins.plane import time_to_boundary_cop

    base = _box(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        time = time_to_boundary_cop(base, np.array([[0.05, 0.0]]), np.array([[0.5, 1e-311]]))
    assert time[0] == pytest.approx((0.15 - 0.05) / 0.5)


def test_runs_of_equal_polygons_give_the_frame_by_frame_numbers() -> None:
    """The edges are computed once per run of equal polygons: the same bits as frame by frame."""
    rng = np.random.default_rng(3)
    n = 60
    left, right = _walk(n)
    stepping = base_from_feet((left, right), FootModel(width=0.1), contact_height=0.02)
    com, vel, cop = (rng.normal(scale=s, size=(n, 2)) for s in (0.1, 0.3, 0.1))
    com[5] = np.nan
    for base in (stepping, _box(n)):
        whole = margins_2d(base, com, vel, P, cop=cop, cop_velocity=vel)
        for f in (0, 5, 14, 15, 16, 29, 59):  # each frame alone: its own polygon, no run
            one = BasePolygons(base.vertices[f : f + 1], base.counts[f : f + 1], base.source)
            alone = margins_2d(one, com[f : f + 1], vel[f : f + 1], P, cop=cop[f : f + 1],
                               cop_velocity=vel[f : f + 1], verdicts=False)  # fmt: skip
            for name in ("mos", "mos_ap", "ttb_cop", "ttb_xcom", "mos_left"):
                assert np.array_equal(
                    getattr(whole, name)[f : f + 1], getattr(alone, name), equal_nan=True
                ), (name, f)
