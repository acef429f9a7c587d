"""The stepping task of the whole-body controller (issue 19 item 3): a lateral capture step."""

import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.biped3d import biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.wbc import WholeBodyQP, foot_contact
from pushrecovery.sim.mujoco.humanoid3d.wbc_control import WholeBodyController
from pushrecovery.sim.mujoco.humanoid3d.wbc_push import bent_knee_qpos, push_biped3d
from pushrecovery.sim.mujoco.humanoid3d.wbc_step import StepSettings, quintic

#: The push, in CoP-region critical impulses (docs/plane.md): well outside the ankle region.
OUTSIDE = 1.5
#: DAQP's primal tolerance on rows in newtons, with room for rounding [N].
FORCE_TOL = 1e-5
#: How close the landed ankle must be to the last planned foothold [m].
PLACEMENT = 0.03
#: How much earlier or later than planned the foot may touch down [s].
TIMING = 0.05


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def model(params):
    return biped3d_model(params)


@pytest.fixture(scope="module")
def impulse(params):
    """OUTSIDE × m ω × the ray distance from the ankles' midpoint to P's left edge [N s]."""
    polygon = Support.from_params(params).polygon
    return OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, math.pi / 2)


@pytest.fixture(scope="module")
def runs(params, model, impulse):
    kwargs = {"duration": 2.5, "model": model, "step_settings": StepSettings(swing_time=0.2)}
    return {
        stepping: push_biped3d(params, impulse, math.pi / 2, stepping=stepping, **kwargs)
        for stepping in (False, True)
    }


def test_side_push_falls_without_stepping(runs):
    run = runs[False]
    assert run.controller.stepper is None
    assert run.com[-1, 2] < 0.6 or run.torso_tilt.max() > 1.0


def test_side_push_recovers_with_a_lateral_step(runs):
    run = runs[True]
    assert run.ok.all()
    assert run.com[-1, 2] > 0.9 and run.torso_tilt.max() < 0.5
    assert np.linalg.norm(run.com_velocity[-1, :2]) < 0.1
    steps = run.controller.stepper.steps
    assert len(steps) == 1
    step = steps[0]
    assert step.foot == "left_foot"
    assert step.landed[1] > 0.1 + 0.2  # the left ankle, at y = 0.1 before, moves left
    assert step.error < PLACEMENT
    assert abs(step.touchdown - step.planned_touchdown) < TIMING
    assert len(step.plans) > 1  # re-planned during the swing
    assert run.sole_lift[:, 0].max() > 0.02  # the left foot lifted; the right one stayed
    assert run.sole_lift[:, 1].max() < 0.01  # an edge of the stance sole rises a few mm


def test_wrenches_satisfy_friction_and_cop_rows_at_every_tick(runs):
    run = runs[True]
    for foot, rows in enumerate(f.constraint_rows() for f in run.controller.feet):
        assert np.all(run.wrenches[:, foot] @ rows.T <= FORCE_TOL)


def test_quintic_meets_its_ends():
    p0, v0, a0, p1 = np.array([0.0, 1.0]), np.array([0.5, 0.0]), np.array([0.0, 2.0]), np.ones(2)
    coeffs = quintic(p0, v0, a0, p1, 0.4)
    powers = 0.4 ** np.arange(6)
    assert np.allclose(powers @ coeffs, p1)
    assert np.allclose((np.arange(1, 6) * powers[:-1]) @ coeffs[1:], 0.0)
    assert np.allclose(coeffs[0], p0) and np.allclose(coeffs[1], v0)
    with pytest.raises(InvalidParameterError, match="duration"):
        quintic(p0, v0, a0, p1, 0.0)


def test_swing_foot_contacts_in_the_qp(model):
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    qp = WholeBodyQP(model, [foot_contact(model, data, n) for n in ("left_foot", "right_foot")])
    qp.set_contacts([False, True])
    solution = qp.solve(data, [])
    assert solution.ok and np.allclose(solution.wrenches[0], 0.0)
    with pytest.raises(InvalidParameterError, match="contacts"):
        qp.set_contacts([True])
    with pytest.raises(InvalidParameterError, match="contacts"):
        qp.set_contacts([1, 0])


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"stepping": True}, "stepping"),
        ({"stepping": "yes"}, "stepping"),
        ({"stepping": True, "params": "body"}, "stepping"),
        ({"step_settings": 0.2}, "step_settings"),
    ],
)
def test_bad_controller_inputs(model, kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        WholeBodyController(model, **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"swing_time": 0.0}, "swing_time"),
        ({"lift": -0.1}, "lift"),
        ({"weight": 0.0}, "weight"),
        ({"replan_fraction": 2.0}, "replan_fraction"),
        ({"contact": math.nan}, "contact"),
    ],
)
def test_bad_step_settings(kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        StepSettings(**kwargs)


def test_plant_controller_with_stepping(params):
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for

    plant = Biped3DPlant(params)
    assert wbc_for(plant, stepping=True).stepping
    assert not wbc_for(plant).stepping
