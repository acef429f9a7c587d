"""MuJoCo biped (model ``biped``): the recovery controller unchanged on a planar biped that
steps, against the analytic stepping model."""

import dataclasses

import mujoco
import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.mujoco.biped import LEG_MASS, MujocoBipedPlant, biped_model
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import RestCriterion, simulate
from pushrecovery.surfaces.step import step_critical_velocity, step_thresholds

P = load_params()
# Landing vs commanded step length [m]. The swing foot lands where the leg geometry puts it;
# what separates the two is the swing leg's tracking at touchdown (≤ 2 mrad of leg angle: 2 mm
# at the foot) and the foot's pitch then (a few mrad: its toe or heel meets the floor ≤ 1 mm
# early). Measured: ≤ 1 mm for the pushes here, ≤ 3 mm up to ±2 m/s, 7.6 mm at −2.4 m/s.
LANDING_TOLERANCE = 5e-3


def recovery(params=P, first_step=None):
    """The recovery controller, recording its step commands (optionally replacing the first)."""
    controller = make_controller("recovery", params)
    controller.steps = []
    compute = controller.compute

    def recorded(t, state):
        command = compute(t, state)
        if command.step_length is not None:
            if first_step is not None and not controller.steps:
                command = dataclasses.replace(command, step_length=first_step)
            controller.steps.append(command.step_length)
        return command

    controller.compute = recorded
    return controller


def run(v=0.0, impulse=None, duration=5.0, rest=None, first_step=None):
    plant = MujocoBipedPlant(P)
    state = plant.reset(0.0, v if impulse is None else 0.0)
    if impulse is not None:
        plant.apply_push(Push.from_impulse(impulse, P.mass, scheduled=True))
    controller = recovery(first_step=first_step)
    result = simulate(plant, controller, state, duration=duration, rest=rest)
    return plant, controller, result


def analytic(v, duration=5.0):
    plant = make_plant("stepping", P)
    state = plant.reset(0.0, v)
    return simulate(plant, make_controller("recovery", P), state, duration=duration)


def test_model_maps_the_paper_parameters():
    plant = MujocoBipedPlant(P)
    model, data = plant.model, plant.data
    mujoco.mj_forward(model, data)
    assert model.body_subtreemass[0] == pytest.approx(P.mass)
    torso = model.body("torso")
    assert torso.mass[0] == pytest.approx(P.mass - 2 * LEG_MASS)
    assert 2 * LEG_MASS / P.mass < 0.03  # light legs: the paper's are massless
    # The torso is the flywheel: its CoM at the hip, inertia I about it.
    assert np.allclose(torso.ipos, 0.0) and torso.inertia[1] == pytest.approx(P.flywheel_inertia)
    # Standing straight, the hip is L above the ankles.
    for leg in ("left", "right"):
        ankle = data.xanchor[model.joint(f"{leg}_ankle").id]
        assert data.xpos[torso.id][2] - ankle[2] == pytest.approx(P.com_height)


# Bodies whose leg is not as long as the CoM is high: the report's non-default body and
# the preset with legs 10 % shorter and longer.
UNEQUAL = [
    {"mass": 45.0, "com_height": 0.7, "leg_length": 0.72},
    {"leg_length": 0.9},
    {"leg_length": 1.1},
]


@pytest.mark.parametrize("overrides", [{}, *UNEQUAL])
def test_legs_of_any_length_keep_the_com_height(overrides):
    # Legs ℓ long put the hip ℓ above the ankles, and the torso's CoM c above the hip with
    # m_u c = m (L − ℓ): the whole body's CoM stands at L − Σ m_i d_i / m, d_i the depth of
    # each leg segment's CoM below the hip (by hand from the segments' shapes: thigh capsule
    # ℓ/2 long from the hip, shank capsule ℓ/2 − 4 cm long from the knee, foot box under the
    # ankle), against MuJoCo's subtree CoM.
    from pushrecovery.sim.mujoco.models import FOOT_HALF_THICKNESS

    params = load_params(overrides=overrides)
    leg, mass = params.leg_length, params.mass
    model = biped_model(params).compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    ankle = data.xanchor[model.joint("left_ankle").id][2]
    assert data.xpos[model.body("torso").id][2] - ankle == pytest.approx(leg, abs=1e-12)
    depths = 0.5 * leg / 2, 0.5 * leg + (0.5 * leg - 0.04) / 2, leg + FOOT_HALF_THICKNESS
    lowering = 2.0 * sum(m * d for m, d in zip((0.5, 0.3, 0.2), depths, strict=True)) / mass
    com = data.subtree_com[0][2] - ankle
    assert com == pytest.approx(params.com_height - lowering, abs=1e-12)
    # c itself, by hand for the first body: 45 (0.70 − 0.72) / (45 − 2 kg of legs) m.
    if overrides.get("mass") == 45.0:
        assert model.body("torso").ipos[2] == pytest.approx(45.0 * -0.02 / 43.0, rel=1e-12)


def test_legs_too_short_or_long_for_the_com_are_refused():
    for leg in (0.4, 2.0):
        with pytest.raises(InvalidParameterError, match="within ±leg_length/2 of its hip"):
            biped_model(load_params(overrides={"leg_length": leg}))


@pytest.mark.parametrize(
    ("overrides", "v", "steps"),
    [(UNEQUAL[0], 0.3, 0), (UNEQUAL[0], 0.8, 0), (UNEQUAL[1], 0.3, 0), (UNEQUAL[1], 1.2, 1),
     (UNEQUAL[2], 0.3, 0), (UNEQUAL[2], 1.2, 1)],
)  # fmt: skip
def test_unequal_legs_recover_as_predicted(overrides, v, steps):
    # The ankle (0.3 m/s), the hip (0.8 m/s on the 45 kg body) and one step (1.2 m/s on the
    # preset with legs 10 % shorter or longer), as the surfaces predict. (The 45 kg body's
    # steps land hard enough to slide its foot 1-6 cm: slipped, docs/validation.md.)
    from pushrecovery.surfaces.classify import classify

    params = load_params(overrides=overrides)
    plant = MujocoBipedPlant(params)
    state = plant.reset(0.0, v)
    controller = recovery(params)
    result = simulate(plant, controller, state, duration=5.0)
    assert classify(0.0, v, params).steps == steps
    assert result.recovered and len(controller.steps) == steps
    if controller.steps:
        landed = result.footholds[1] - result.footholds[0]
        assert landed == pytest.approx(controller.steps[0], abs=LANDING_TOLERANCE)


def test_stands_still_for_two_seconds():
    # At rest for the whole 2 s: the run is "recovered" only when the rest lasted 2 s.
    _, controller, result = run(duration=2.5, rest=RestCriterion(duration=2.0))
    assert result.recovered and result.time[-1] == pytest.approx(2.0)
    assert controller.steps == [] and len(result.footholds) == 1
    assert np.abs(result.states[:, 0]).max() < 1e-3  # CoM over the ankles [m]
    assert np.abs(result.torques).max() == 0.0  # no hip


def test_push_inside_the_ankle_region_needs_no_step():
    _, controller, result = run(0.2)
    assert result.recovered and controller.steps == [] and len(result.footholds) == 1
    assert np.abs(result.torques).max() == 0.0
    assert analytic(0.2).recovered


@pytest.mark.parametrize("v", [1.0, -0.8])
def test_push_beyond_the_hip_takes_one_step_as_commanded(v):
    back, forward = step_thresholds(P)
    assert back < v < forward  # one step recovers ...
    plant, controller, result = run(v)
    assert result.recovered
    assert len(controller.steps) == 1 and len(result.footholds) == 2
    landed = result.footholds[1] - result.footholds[0]
    assert landed == pytest.approx(controller.steps[0], abs=LANDING_TOLERANCE)
    assert np.sign(landed) == np.sign(v)
    # It ends at rest over the new foot, lower (Eq. 20), with the trailing leg lifted.
    assert result.final_state[2] < plant._standing_height() and result.final_state[5] == 0.0
    reference = analytic(v)  # ... and so it does in the analytic stepping model
    assert reference.recovered and len(reference.footholds) == 2


def test_push_as_a_real_force():
    # 72 N s over 10 ms on the torso: 1 m/s for 72 kg, beyond the hip region.
    _, controller, result = run(impulse=72.0)
    assert result.recovered and len(controller.steps) == 1
    landed = result.footholds[1] - result.footholds[0]
    assert landed == pytest.approx(controller.steps[0], abs=LANDING_TOLERANCE)
    _, controller, small = run(impulse=-7.2)  # −0.1 m/s: the ankle alone
    assert small.recovered and controller.steps == []


def test_push_far_beyond_the_step_limit_falls():
    for v in (4.0, -4.0):
        _, _, result = run(v)
        assert result.outcome.value == "fell"
        assert analytic(v).outcome.value == "fell"


def test_a_second_step_swaps_the_legs():
    # A first step forced short of Eq. (21) leaves the capture point ahead of the new foot:
    # the controller steps again, with the other leg, as the analytic model would.
    plant, controller, result = run(1.0, first_step=0.3)
    assert result.recovered and len(controller.steps) == 2 and len(result.footholds) == 3
    steps = np.diff(result.footholds)
    assert steps == pytest.approx(controller.steps, abs=LANDING_TOLERANCE)
    assert plant.gait.stance == (0,)  # right leg first, then left


def test_bad_states():
    plant = MujocoBipedPlant(P)
    with pytest.raises(InvalidParameterError, match="state must be"):
        plant.check_state(np.zeros(4))
    with pytest.raises(InvalidParameterError, match="zdot = 0"):
        plant.check_state(np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.1]))


@pytest.mark.parametrize("v", [1.6, 2.0, 2.4])
def test_forward_pushes_from_ahead_of_the_ankle_recover(v):
    # From x0 = 0.05 a 10 ms push of m v along the leaning legs lifts the feet (its component
    # along them, m v / 10 ms · sin α, is about the weight at 2 m/s), and the landing's contact
    # builds a step after the sole reaches the floor: these pushes used to fall (the
    # bisection found 1.89 m/s against the single-step limit 2.60 m/s).
    assert v < step_critical_velocity(0.05, 1.0, P)  # one step recovers it (2.60 m/s)
    plant = MujocoBipedPlant(P)
    plant.reset(0.05, 0.0)
    state = plant.apply_push(Push(v))
    controller = recovery()
    result = simulate(plant, controller, state, duration=3.0)
    assert result.recovered and len(controller.steps) == 1
    landed = result.footholds[1] - result.footholds[0]
    assert landed == pytest.approx(controller.steps[0], abs=LANDING_TOLERANCE)


@pytest.mark.parametrize("overrides", [{}, *UNEQUAL])
def test_biped_kinematics_match_subtree_com(overrides):
    # The plant's own CoM kinematics (the state it reports) against MuJoCo's subtree_com and
    # subtree_linvel of the same model, over random configurations: a change of a segment's
    # mass or length in the model that the plant does not follow fails here (with unequal
    # legs, the torso's CoM off the hip too).
    plant = MujocoBipedPlant(load_params(overrides=overrides))
    model, data = plant.model, plant.data
    rng = np.random.default_rng(42)
    worst_x = worst_v = 0.0
    for _ in range(200):
        data.qpos[:] = rng.uniform(-0.6, 0.6, model.nq)
        data.qpos[4::3] = rng.uniform(0.0, 1.0, 2)  # knees bend one way
        data.qvel[:] = rng.uniform(-2.0, 2.0, model.nv)
        mujoco.mj_forward(model, data)
        mujoco.mj_subtreeVel(model, data)
        q, v = data.qpos.tolist(), data.qvel.tolist()
        for i, leg in enumerate(("left", "right")):
            x, z, xdot, zdot = plant._com(q, v, i)
            ankle = data.xanchor[model.joint(f"{leg}_ankle").id]
            com, velocity = data.subtree_com[0], data.subtree_linvel[0]
            worst_x = max(worst_x, abs(x - (com[0] - ankle[0])), abs(z - (com[2] - ankle[2])))
        worst_v = max(worst_v, abs(xdot - velocity[0]), abs(zdot - velocity[2]))
    assert worst_x < 1e-12 and worst_v < 1e-12


@pytest.mark.parametrize(("v", "steps"), [(-2.75, 2), (-3.0, 3)])
def test_backward_pushes_take_the_predicted_steps_without_scuffing(v, steps):
    # The report's campaign pushes (a force at the torso). The second swing passes under a
    # hip lowered by the first landing: a swing leg that shortened only as steep as it was
    # then scuffed the floor 0.36 m short, in front of the stance foot, and the body fell.
    # The leg now shortens for the steepest angle it reaches within the knee's lag.
    from pushrecovery.sim.critical import pushed_state
    from pushrecovery.surfaces.classify import classify

    assert classify(0.0, v, P).steps == steps
    plant = MujocoBipedPlant(P)
    controller = recovery()
    result = simulate(plant, controller, pushed_state(plant, 0.0, v, force=True), duration=5.0)
    # At rest on its feet after the predicted steps. Its stiff landings (tens of body weights
    # for a millisecond) slide a foot 10-12 mm over the run, past the 1 cm limit: slipped,
    # not recovered (docs/validation.md); no more than that.
    assert result.outcome.value == "slipped" and 0.01 < result.physics.foot_slip < 0.015
    assert len(controller.steps) == steps
    # Every step lands behind the one before (the scuff landed the second one in front).
    assert np.all(np.diff(result.footholds) < 0.0)
