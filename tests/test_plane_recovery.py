"""Multi-step recovery on the ground plane: the recovery-plane controller on stepping-plane.

Ground truth is the closed loop itself: the plant (exact zero-order-hold LIPM with flywheels,
feet landing where and when commanded) knows nothing of the capture regions; the controller
follows the N-step plans and re-plans at every touchdown. The verdicts of ``classify`` must
then name the number of steps the closed loop takes, just inside and just outside every
boundary, in every direction.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from pushrecovery import load_params
from pushrecovery.control.base import Command, make_controller
from pushrecovery.control.recovery.plane import PlaneRecoveryController, hip_share
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import FootPose, Support
from pushrecovery.models.flywheel.plane import plane_discrete
from pushrecovery.sim.plane_stepping import PlaneSteppingPlant
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import classify

# 8 directions, none on an axis of symmetry.
DIRECTIONS = np.radians(np.arange(8) * 45.0 + 7.0)
NO_HIP = {"torque_max": 0.0, "torque_max_roll": 0.0}


def needed_steps(params, speed, angle):
    """Steps of the verdict for the CoM over the ankles' midpoint pushed to ``speed``."""
    verdict = classify(
        0.0, speed * math.cos(angle), params, y=0.0, ydot=speed * math.sin(angle)
    ).to_dict()
    if verdict["strategy"] == "fall":
        return math.inf
    return verdict["steps"] or 0


def boundary(params, steps, angle):
    """Bisect the push speed [m/s] where the verdict needs more than ``steps`` steps."""
    low, high = 0.0, 8.0
    for _ in range(36):
        middle = 0.5 * (low + high)
        low, high = (
            (middle, high) if needed_steps(params, middle, angle) <= steps else (low, middle)
        )
    return low, high


def run(params, speed, angle, duration=8.0):
    plant = PlaneSteppingPlant(params)
    start = plant.reset(0.0, speed * math.cos(angle), 0.0, speed * math.sin(angle))
    result = simulate(plant, PlaneRecoveryController(params), start, duration=duration)
    return result, len(result.footholds_xy) - 1


@pytest.mark.parametrize("hip", [True, False], ids=["hip", "no-hip"])
@pytest.mark.parametrize("steps", [0, 1, 2])
def test_the_closed_loop_takes_the_predicted_number_of_steps(steps, hip):
    params = load_params(overrides={"max_steps": 3} | ({} if hip else NO_HIP))
    for angle in DIRECTIONS if hip else DIRECTIONS[::2]:
        low, high = boundary(params, steps, angle)
        inside, taken = run(params, 0.995 * low, angle)
        assert inside.recovered and taken <= steps, (math.degrees(angle), taken)
        outside, taken = run(params, 1.005 * high, angle)
        assert not outside.recovered or taken > steps, (math.degrees(angle), taken)


def test_beyond_the_last_region_the_body_falls_and_just_inside_it_recovers():
    params = load_params()  # max_steps: where one more step adds < 1 mm
    for angle in DIRECTIONS[::2]:
        low, high = boundary(params, params.max_steps, angle)
        inside, taken = run(params, 0.995 * low, angle, duration=10.0)
        assert inside.recovered and taken <= params.max_steps
        outside, _ = run(params, 1.005 * high, angle, duration=10.0)
        assert outside.outcome.value == "fell"


def test_plans_are_followed_and_kept_within_reach_and_step_time():
    params = load_params()
    result, taken = run(params, 2.8, DIRECTIONS[1])
    assert result.recovered and taken >= 2
    feet = np.array(result.footholds_xy[1:])
    # Every foothold within reach of the foot before it (the first from a stance ankle).
    half = 0.5 * params.stance_width
    first_gap = min(math.hypot(feet[0, 0], feet[0, 1] - side) for side in (half, -half))
    assert first_gap <= params.max_step_length + 1e-12
    gaps = np.hypot(*np.diff(feet, axis=0).T)
    assert np.all(gaps <= params.max_step_length + 1e-12)
    # The CoP always on the support of its tick: on the foot under it at the end.
    final = result.final_state
    assert math.hypot(final[0] - feet[-1, 0], final[1] - feet[-1, 1]) < params.toe


def test_a_turned_and_moved_stance_gets_the_turned_and_moved_command(monkeypatch):
    """Any stance yaw and place re-plans from the regions and terms built at construction."""
    import pushrecovery.kernels.polygons as polygons
    import pushrecovery.surfaces.capture.plan as plans
    import pushrecovery.surfaces.n_step as n_step

    params = load_params()
    controller = PlaneRecoveryController(params)

    def built(*_, **__):
        raise AssertionError("a Minkowski sum built in the loop")

    for module, name in ((n_step, "minkowski_sum_unchecked"), (plans, "minkowski_sum_unchecked"),
                         (plans, "minkowski_sum_loop")):  # fmt: skip
        monkeypatch.setattr(module, name, built)
    compiled = polygons.minkowski_loop
    sums = []

    def cmp_region_only(shapes, counts, weights, offset):
        sums.append(counts.tolist())  # the support polygon and the hip's box: 4 corners
        return compiled(shapes, counts, weights, offset)

    monkeypatch.setattr(polygons, "minkowski_loop", cmp_region_only)
    push = np.array([0.9, 0.5])  # CoM velocity in the stance foot's frame [m/s]
    commands = {}
    for yaw, x, y in ((0.0, 0.0, 0.0), (0.7, 1.3, -0.4), (-2.9, -0.8, 2.1), (math.pi, 0.2, 0.3)):
        turn = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
        stance = FootPose(x, y, yaw)
        support = Support.from_params(params, "left", left=stance, right=stance)
        velocity = turn @ push
        state = np.array([x, y, 0.0, 0.0, velocity[0], velocity[1], 0.0, 0.0])
        controller.reset(state)
        controller.support = support
        command = controller.compute(0.0, state)
        assert controller.mode == "step" and command.swing == "right"
        local = turn.T @ (np.array(command.foothold) - (x, y))
        cop = turn.T @ (np.array([command.cop, command.cop_y]) - (x, y))
        commands[yaw] = np.concatenate([local, cop])
    for found in commands.values():
        assert np.abs(found - commands[0.0]).max() <= 1e-12
    # One compiled sum per new support, the CMP region's (its test), and no other.
    assert sums == [[4, 4]] * len(commands)


def test_the_hip_share_is_the_integral_of_the_bang_bang_profile():
    omega, spin_up = 3.13, 0.3

    def profile(s):
        return 1.0 if s < spin_up else (-1.0 if s < 2.0 * spin_up else 0.0)

    for elapsed in (0.0, 0.1, 0.299, 0.3, 0.45, 0.6, 0.9):

        def integrand(s, u=elapsed):
            return math.exp(-omega * (s - u)) * profile(s)

        pieces = ((elapsed, max(elapsed, spin_up)), (max(elapsed, spin_up), 2 * spin_up))
        expected = omega * sum(quad(integrand, a, b, epsabs=1e-13)[0] for a, b in pieces if b > a)
        assert hip_share(elapsed, spin_up, omega) == pytest.approx(expected, abs=1e-12)
    assert hip_share(0.0, spin_up, omega) == pytest.approx((1.0 - math.exp(-omega * spin_up)) ** 2)


def test_the_plant_is_the_exact_zero_order_hold_and_splits_a_tick_at_touchdown():
    params = load_params()
    plant = PlaneSteppingPlant(params)
    state = plant.reset(0.01, 0.3, -0.02, 0.1)
    command = Command(0.02, 10.0, cop_y=0.01, roll_torque=-5.0)
    a, b = plane_discrete(params, 1e-3)
    step = plant.step(command, 1e-3)
    np.testing.assert_allclose(
        step.state, a @ state + b @ np.array([0.02, 0.01, 10.0, -5.0]), atol=1e-15
    )
    np.testing.assert_allclose(step.applied, [0.02, 0.01, 10.0, -5.0])
    assert step.info.stance and plant.input_labels[:2] == ("cop_x", "cop_y")
    # A touchdown inside a tick: the same as two ticks split at the touchdown.
    lift = Command(0.0, foothold=(0.3, 0.15), touchdown=0.2005, swing="left")
    whole, split = PlaneSteppingPlant(params), PlaneSteppingPlant(params)
    hold = Command(0.0)
    for plant_ in (whole, split):
        plant_.begin(state)
        assert not plant_.step(lift, 1e-3).info.stance  # swinging
    for _ in range(199):
        whole.step(hold, 1e-3)
        split.step(hold, 1e-3)
    one = whole.step(hold, 1e-3).state
    split.step(hold, 5e-4)
    two = split.step(hold, 5e-4)
    np.testing.assert_allclose(one, two.state, atol=1e-14)
    assert two.info.stance and len(two.info.footholds) == 2
    assert whole.footholds_xy[-1] == (0.3, 0.15)
    assert whole.support.stance.value == "left"


def test_the_plant_enforces_step_time_reach_and_the_foot():
    params = load_params()
    plant = PlaneSteppingPlant(params)
    plant.reset(0.0, 0.0)
    # A foothold beyond reach lands at the reach; a touchdown sooner than min_step_time later.
    far = Command(5.0, cop_y=5.0, foothold=(5.0, 0.1), touchdown=0.01, swing="left")
    cop = plant.step(far, 1e-3).applied[:2]
    # The CoP is moved onto the right foot (the stance while the left swings).
    assert plant.support.polygon.signed_distance(*cop) >= -1e-12
    ticks = 1
    while plant.swinging:
        plant.step(Command(0.0), 1e-3)
        ticks += 1
    assert ticks * 1e-3 == pytest.approx(params.min_step_time, abs=1e-3)
    x, y = plant.footholds_xy[-1]
    assert math.hypot(x, y + 0.5 * params.stance_width) == pytest.approx(
        params.max_step_length, rel=2e-3
    )  # on the inscribed 64-gon of the reach disc


@pytest.mark.parametrize(
    ("command", "match"),
    [
        (Command(0.0, step_length=0.3), "foothold, not step_length"),
        (Command(0.0, foothold=(0.3, 0.1)), "needs swing 'left' or 'right'"),
        (Command(0.0, foothold=(0.3, 0.1), swing="double"), "needs swing"),
    ],
)
def test_bad_plane_commands_are_refused(command, match):
    plant = PlaneSteppingPlant(load_params())
    plant.reset(0.0, 0.0)
    with pytest.raises(InvalidParameterError, match=match):
        plant.step(command, 1e-3)


def test_models_and_controllers_must_fit():
    params = load_params()
    plane = make_plant("stepping-plane", params)
    start = plane.reset(0.0, 0.5)
    with pytest.raises(InvalidParameterError, match=r"needs the state .* lacks"):
        simulate(plane, make_controller("recovery", params), start, duration=1.0)
    sagittal = make_plant("stepping", params)
    with pytest.raises(InvalidParameterError, match="needs the state"):
        simulate(sagittal, PlaneRecoveryController(params), sagittal.reset(0, 1), duration=1)
    with pytest.raises(InvalidParameterError, match="shape"):
        plane.check_state(np.zeros(6))
    with pytest.raises(InvalidParameterError, match="theta_roll"):
        plane.check_state(np.array([0, 0, 0, 2.0, 0, 0, 0, 0.0]))
    with pytest.raises(InvalidParameterError, match="xdot"):
        plane.check_state(plane.reset(0.0, 1e3))


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (
            ["--model", "stepping", "--controller", "recovery", "--ydot", "1"],
            "need --model stepping-plane",
        ),
        (
            ["--model", "stepping-plane", "--controller", "recovery-plane", "--y", "5"],
            "y must satisfy",
        ),
        (
            ["--model", "stepping-plane", "--controller", "recovery-plane", "--ydot", "1e9"],
            "ydot must",
        ),
        (["--model", "stepping-plane", "--controller", "recovery"], "needs the state"),
    ],
)
def test_bad_plane_simulations_are_one_line_errors(args, match, capsys):
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["simulate", *args])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and match in err


def test_simulate_on_the_plane_reports_its_footholds(capsys):
    import json

    from pushrecovery.cli import main

    with pytest.raises(SystemExit):
        main(["simulate", "--model", "stepping-plane", "--controller", "recovery-plane",
              "--xdot", "2.2", "--ydot", "1.2", "--json"])  # fmt: skip
    data = json.loads(capsys.readouterr().out)
    assert data["recovered"] and data["predicted"]["steps"] == len(data["footholds_xy"]) - 1
    np.testing.assert_allclose(
        data["footholds_xy"][1], data["predicted"]["plan"]["footholds"][0], atol=1e-9
    )
