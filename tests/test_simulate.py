"""Simulator, plants, controllers' contract and the critical-push search."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import AnklePD, Command, Controller, make_controller
from pushrecovery.control.registry import CONTROLLER_NAMES
from pushrecovery.models.lipm import lipm_state
from pushrecovery.sim.critical import NotRecoverableError, critical_push
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

PARAMS = load_params()


class FixedCop(Controller):
    name = "fixed"

    def __init__(self, params, cop):
        super().__init__(params)
        self.cop = cop

    def reset(self, state):
        pass

    def compute(self, t, state):
        return Command(self.cop)


def test_lipm_plant_is_exact_zoh():
    run = simulate(
        make_plant("lipm", PARAMS),
        FixedCop(PARAMS, 0.1),
        np.array([0.02, 0.3]),
        duration=0.5,
        control_period=0.01,
    )
    x, v = lipm_state(run.time, 0.02, 0.3, 0.1, PARAMS.omega)
    np.testing.assert_allclose(run.states[:, 0], x, rtol=1e-12)
    np.testing.assert_allclose(run.states[:, 1], v, rtol=1e-12)


def test_plant_clips_cop_to_the_foot():
    run = simulate(
        make_plant("pendulum", PARAMS), FixedCop(PARAMS, 0.5), np.array([0.0, 0.0]), duration=0.1
    )
    assert np.all(run.cops == PARAMS.toe)


def test_lipm_rejects_flywheel_torque():
    class Hip(FixedCop):
        def compute(self, t, state):
            return Command(0.0, flywheel_torque=5.0)

    with pytest.raises(InvalidParameterError, match="flywheel_torque must be 0"):
        simulate(make_plant("lipm", PARAMS), Hip(PARAMS, 0.0), np.array([0.0, 0.0]))


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"duration": 0.0}, "duration must be > 0"),
        ({"duration": math.nan}, "duration must be a finite number"),
        ({"control_period": -1e-3}, "control_period must be > 0"),
        ({"duration": 1.0, "control_period": 2.0}, "control_period must be <= duration"),
    ],
)
def test_bad_simulation_options(kwargs, words):
    with pytest.raises(InvalidParameterError, match=words):
        simulate(
            make_plant("lipm", PARAMS),
            make_controller("ankle-pd", PARAMS),
            np.array([0.0, 0.1]),
            **kwargs,
        )


@pytest.mark.parametrize(
    ("state", "words"),
    [
        ([math.nan, 0.0], "initial_state"),
        ([0.0, math.inf], "initial_state"),
        ([0.0, 0.0, 0.0], "state must be"),
    ],
)
def test_bad_initial_state(state, words):
    with pytest.raises(InvalidParameterError, match=words):
        simulate(make_plant("lipm", PARAMS), make_controller("ankle-pd", PARAMS), np.array(state))


def test_pendulum_needs_com_above_ankle_horizon():
    with pytest.raises(InvalidParameterError, match=r"\|x\| < com_height"):
        simulate(
            make_plant("pendulum", PARAMS),
            make_controller("ankle-pd", PARAMS),
            np.array([1.2, 0.0]),
        )


def test_outcomes():
    plant, ctrl = make_plant("lipm", PARAMS), make_controller("ankle-pd", PARAMS)
    assert simulate(plant, ctrl, np.array([0.0, 0.2])).outcome.value == "recovered"
    assert simulate(plant, ctrl, np.array([0.0, 0.6])).outcome.value == "fell"
    # Too short to settle or fall.
    assert simulate(plant, ctrl, np.array([0.0, 0.2]), duration=0.05).outcome.value == "undecided"


def test_unknown_names():
    with pytest.raises(InvalidParameterError, match="model must be one of"):
        make_plant("biped", PARAMS)
    with pytest.raises(InvalidParameterError, match="controller must be one of"):
        make_controller("hip", PARAMS)


def test_pd_gain_validation():
    mgl = PARAMS.weight * PARAMS.com_height
    with pytest.raises(InvalidParameterError, match="stiffness must be > m g L"):
        AnklePD(PARAMS, stiffness=0.9 * mgl)
    with pytest.raises(InvalidParameterError, match="damping must be >= 0"):
        AnklePD(PARAMS, damping=-1.0)
    with pytest.raises(InvalidParameterError, match="stiffness must be a finite number"):
        AnklePD(PARAMS, stiffness=math.nan)


@pytest.mark.parametrize("name", sorted(CONTROLLER_NAMES))
@given(
    x=st.floats(-0.9, 0.9),
    v=st.floats(-5, 5),
    t=st.floats(0, 10),
    theta=st.floats(-1.0, 1.0),
    rate=st.floats(-20, 20),
)
def test_controller_contract(name, x, v, t, theta, rate):
    controller = make_controller(name, PARAMS)
    if "y" in controller.state_labels:  # the ground plane
        plane_contract(controller, x, v, t, theta, rate)
        return
    hip = controller.strategy in ("hip", "step")
    state = {
        "ankle": np.array([x, v]),
        "hip": np.array([x, theta, v, rate]),
        "step": np.array([x, theta, PARAMS.com_height, v, rate, 0.0]),
    }[controller.strategy]
    controller.reset(state)
    command = controller.compute(t, state)
    assert math.isfinite(command.cop) and math.isfinite(command.flywheel_torque)
    assert command.step_length is None or abs(command.step_length) <= PARAMS.max_step_length
    assert PARAMS.heel <= command.cop <= PARAMS.toe
    assert abs(command.flywheel_torque) <= PARAMS.torque_max
    if not hip:
        assert command.flywheel_torque == 0.0


def plane_contract(controller, x, v, t, theta, rate):
    """Ground plane: CoP on the feet, torques within limits, footholds within reach."""
    from pushrecovery.ground.support import Support

    state = np.array([x, -0.5 * x, theta, -theta, v, 0.5 * v, rate, -rate])
    controller.reset(state)
    command = controller.compute(t, state)
    double = Support.from_params(PARAMS).polygon
    values = (command.cop, command.cop_y, command.flywheel_torque, command.roll_torque)
    assert all(math.isfinite(value) for value in values)
    assert double.signed_distance(command.cop, command.cop_y) >= -1e-12
    assert abs(command.flywheel_torque) <= PARAMS.torque_max
    assert abs(command.roll_torque) <= PARAMS.torque_max_roll
    if command.foothold is not None:
        half = 0.5 * PARAMS.stance_width * (1.0 if command.swing == "right" else -1.0)
        gap = math.hypot(command.foothold[0], command.foothold[1] - half)
        assert gap <= PARAMS.max_step_length + 1e-12
        assert command.touchdown >= t + PARAMS.min_step_time - 1e-12


def test_saturated_controller_brakes_on_the_edge_then_holds():
    controller = make_controller("ankle-saturated", PARAMS)
    controller.reset(np.array([0.0, 0.3]))
    assert controller.compute(0.0, np.array([0.0, 0.3])).cop == PARAMS.toe
    stopped = controller.compute(1.0, np.array([0.05, -1e-4]))
    assert stopped.cop == pytest.approx(0.05 - 1e-4 / PARAMS.omega)
    backward = make_controller("ankle-saturated", PARAMS)
    backward.reset(np.array([0.0, -0.1]))
    assert backward.compute(0.0, np.array([0.0, -0.1])).cop == PARAMS.heel


def test_impulse_push():
    assert Push.from_impulse(36.0, 72.0).delta_velocity == 0.5
    assert Push(0.5).impulse(72.0) == 36.0
    with pytest.raises(InvalidParameterError, match="impulse must be a finite number"):
        Push.from_impulse(math.nan, 72.0)


def test_critical_push_lipm_matches_eq4_to_tolerance():
    found = critical_push(PARAMS, "lipm", "ankle-saturated", 0.02, "forward", tolerance=1e-5)
    low, high = found.bracket
    assert low < found.predicted_velocity <= high + 1e-12
    assert high - low <= 1e-5


def test_critical_push_rejects_bad_start():
    with pytest.raises(InvalidParameterError, match="x must lie on the foot"):
        critical_push(PARAMS, "lipm", "ankle-pd", 0.2, "forward")
    with pytest.raises(InvalidParameterError, match="direction must be"):
        critical_push(PARAMS, "lipm", "ankle-pd", 0.0, "up")
    mgl = PARAMS.weight * PARAMS.com_height
    # A soft, under-damped PD cannot even hold a standing body near the toe.
    with pytest.raises(NotRecoverableError, match="without a push"):
        critical_push(
            PARAMS,
            "lipm",
            "ankle-pd",
            0.14,
            "forward",
            controller_options={"stiffness": 1.25 * mgl, "damping": 68.0},
        )


def test_summary_reports_the_applied_cop_range():
    run = simulate(
        make_plant("lipm", PARAMS), FixedCop(PARAMS, 0.1), np.array([0.1, 0.0]), duration=0.2
    )
    assert run.to_dict()["peak_cop"] == {"min": 0.1, "max": 0.1}


def test_a_plant_whose_state_turns_nan_diverges() -> None:
    # A non-finite state from the model is its numbers breaking down, not bad input.
    import math

    import numpy as np
    import pytest

    from pushrecovery import load_params
    from pushrecovery.control.base import make_controller
    from pushrecovery.errors import SimulationDiverged
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate

    params = load_params()
    plant = make_plant("lipm", params)
    advance = plant._advance

    def breaking(command, dt):
        state, applied = advance(command, dt)
        return (np.array([math.nan, 0.0]) if plant_time[0] > 0.05 else state), applied

    plant_time = [0.0]

    def counting(command, dt):
        plant_time[0] += dt
        return breaking(command, dt)

    plant._advance = counting
    with pytest.raises(SimulationDiverged, match=r"not finite at t = 0\.05"):
        simulate(plant, make_controller("ankle-pd", params), plant.reset(0.0, 0.1), duration=1.0)
