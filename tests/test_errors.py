"""Bugs stay bugs: only user errors become the CLI's one-line message (issue 15, item 8).

Each test plants a fault inside the library (a programming error, not bad input) and checks
that it surfaces as the exception it is, instead of being reported as "infeasible", as a
user's mistake, or through an ``AssertionError``.
"""

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.cli import main
from pushrecovery.control.mpc import MPCController
from pushrecovery.errors import PushRecoveryError, SimulationDiverged


def test_a_bug_in_a_command_keeps_its_traceback(monkeypatch, capsys):
    import pushrecovery.surfaces.bounds as bounds

    def broken(*args, **kwargs):
        raise ValueError("a bug: not the user's input")

    monkeypatch.setattr(bounds, "bounds_data", broken)
    with pytest.raises(ValueError, match="a bug"):
        main(["bounds"])
    assert "pushrecovery: error" not in capsys.readouterr().err


def test_user_errors_are_still_one_line(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["classify", "--x", "0", "--xdot", "0", "--mass", "-1"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("pushrecovery: error: ") and err.count("\n") == 1


@pytest.mark.parametrize("solver", ["daqp", "quadprog"])
def test_a_bug_in_the_mpc_is_not_reported_as_infeasible(monkeypatch, solver):
    controller = MPCController(load_params(), solver=solver)
    state = np.array([0.0, 0.0, 0.5, 0.0])
    controller.reset(state)
    assert controller.plan(state).feasible

    def broken(*args, **kwargs):
        raise TypeError("a bug in the QP's vectors")

    monkeypatch.setattr(controller.qp, "vectors", broken)
    monkeypatch.setattr(controller.qp, "vectors_into", broken)
    # The default route's sparse solvers too (they come before the condensed QP).
    for solver in (controller.riccati, controller.interior):
        if solver is not None:
            monkeypatch.setattr(solver, "solve", broken)
    with pytest.raises(TypeError, match="a bug"):
        controller.plan(state)


def test_divergence_has_its_own_error():
    assert issubclass(SimulationDiverged, PushRecoveryError)
    assert issubclass(SimulationDiverged, RuntimeError)
    assert not issubclass(SimulationDiverged, ValueError)  # not the user's value


def test_mujoco_divergence_raises_simulation_diverged():
    pytest.importorskip("mujoco")
    from pushrecovery.control.base import Command
    from pushrecovery.sim.registry import make_plant

    plant = make_plant("torso", load_params(), "mujoco")
    plant.reset(0.0, 0.0)
    plant.data.qvel[:] = 1e12  # no body moves like this: MuJoCo's accelerations blow up
    with pytest.raises(SimulationDiverged, match="unstable"):
        for _ in range(50):
            plant.step(Command(0.0), 1e-3)


def test_a_biped_layout_mismatch_is_a_bug_not_an_assertion(monkeypatch):
    pytest.importorskip("mujoco")
    from pushrecovery.sim.mujoco import biped
    from pushrecovery.sim.mujoco.biped import plant as biped_plant

    original = biped.biped_model

    def swapped(params):
        # The same model with the two legs' names swapped: the joints are not where expected.
        spec = original(params)

        def swap(name):
            for a, b in (("left_", "right_"), ("right_", "left_")):
                if name.startswith(a):
                    return b + name[len(a) :]
            return name

        elements = (*spec.joints, *spec.bodies, *spec.geoms, *spec.actuators)
        for element in elements:  # through temporary names: names must stay unique
            element.name = "tmp_" + swap(element.name)
        for element in elements:
            element.name = element.name[len("tmp_") :]
        for actuator in spec.actuators:
            actuator.target = swap(actuator.target)
        return spec

    monkeypatch.setattr(biped_plant, "biped_model", swapped)
    with pytest.raises(RuntimeError, match="not at index") as error:
        biped.MujocoBipedPlant(load_params())
    assert not isinstance(error.value, AssertionError | PushRecoveryError)
