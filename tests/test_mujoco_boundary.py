"""The MuJoCo floor's and the whole-body controller's entries refuse bad input (issue 38).

Their public entries take MuJoCo's own objects: each checks them by type and size once, where
a plant, a controller, an audit or an image is built, and names the parameter. The per-tick
parts (tasks, limits, the QP, the stepper, the engine's helpers) are outside ``__all__``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import mujoco
import numpy as np
import pytest

from pushrecovery.control.wbc.bodies import body_id, body_names, check_data, check_qpos
from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError
from pushrecovery.presets import load_params
from pushrecovery.sim.critical import bisect_critical
from pushrecovery.sim.mujoco.contact_audit import ContactAudit
from pushrecovery.sim.mujoco.humanoid3d.mjcf import load_mjcf
from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, Humanoid3DPlant
from pushrecovery.sim.mujoco.lab import LabRecorder, plate_areas
from pushrecovery.sim.mujoco.pendulums import MujocoFootPlant
from pushrecovery.sim.mujoco.render.frames import subsample
from pushrecovery.sim.mujoco.render.output import output_paths, write_filmstrip

P = load_params()


@pytest.fixture(scope="module")
def plant() -> Biped3DPlant:
    return Biped3DPlant(P)


def test_mujoco_objects_are_checked_by_type_and_size(plant: Biped3DPlant) -> None:
    model = plant.model
    with pytest.raises(ParameterTypeError, match="model must be a MjModel, got dict"):
        body_id({}, "torso")
    with pytest.raises(InvalidParameterError, match="no body 'nose'"):
        body_id(model, "nose")
    with pytest.raises(ParameterTypeError, match="data must be a MjData"):
        check_data(model, np.zeros(3))
    ball = mujoco.MjModel.from_xml_string("<mujoco><worldbody><body><freejoint/><geom size='.1'/>"
                                          "</body></worldbody></mujoco>")  # fmt: skip
    with pytest.raises(InvalidParameterError, match="data must be made for model"):
        check_data(model, mujoco.MjData(ball))
    with pytest.raises(InvalidParameterError, match=rf"qpos must be {model.nq} numbers"):
        check_qpos(model, np.zeros(3))
    with pytest.raises(InvalidParameterError, match="qpos must be finite"):
        check_qpos(model, np.full(model.nq, math.nan))
    with pytest.raises(InvalidParameterError, match="feet must be distinct"):
        body_names(model, ("left_foot", "left_foot"), "feet")
    with pytest.raises(ParameterTypeError, match="feet must be a sequence"):
        body_names(model, "left_foot", "feet")


def test_plants_and_audits_refuse_what_they_cannot_build(plant: Biped3DPlant) -> None:
    model, data = plant.model, plant.data
    qpos = plant.qpos
    with pytest.raises(InvalidParameterError, match="qpos must be"):
        Humanoid3DPlant(P, model, qpos[:5], plant.feet, "torso", "torso")
    with pytest.raises(InvalidParameterError, match="no body 'head'"):
        Humanoid3DPlant(P, model, qpos, plant.feet, "head", "torso")
    with pytest.raises(ParameterTypeError, match="model must be a MjModel"):
        ContactAudit("biped3d", data, plant.feet, qpos, 700.0)
    with pytest.raises(InvalidParameterError, match="no body 'hand'"):
        ContactAudit(model, data, ("left_foot", "hand"), qpos, 700.0)
    with pytest.raises(ParameterTypeError, match="params must be a BodyParams"):
        MujocoFootPlant(math.nan)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match=r"cop_margin must be in \[0, 0.05\]"):
        MujocoFootPlant(P, cop_margin=0.2)
    foot = MujocoFootPlant(P)
    with pytest.raises(InvalidParameterError, match="model_name 'biped' does not name"):
        LabRecorder(foot, "biped", plate_areas(0.0), frames=10, per_frame=10, decimation=1)
    with pytest.raises(InvalidParameterError, match="frames \\* per_frame must be at most 1e7"):
        LabRecorder(foot, "foot", plate_areas(0.0), frames=10**6, per_frame=100, decimation=1)


def test_an_mjcf_path_that_is_not_a_file_is_refused(tmp_path: Path) -> None:
    fifo = tmp_path / "robot.xml"
    os.mkfifo(fifo)
    with pytest.raises(InvalidParameterError, match="not a regular file"):
        load_mjcf(fifo)  # it would block MuJoCo's reader for ever
    with pytest.raises(InvalidParameterError, match="file not found"):
        load_mjcf(tmp_path / "none.xml")
    with pytest.raises(ParameterTypeError, match="path must be a str or PathLike"):
        load_mjcf(b"robot.xml")  # type: ignore[arg-type]


def test_the_critical_impulse_search_ends_whatever_the_runs_say() -> None:
    calls = []

    def never(impulse: float) -> tuple[bool, str]:
        calls.append(impulse)
        return False, "ankle"

    # Nothing stands, however small: the lower end shrinks to the tolerance and stops there.
    low, bracket, used = bisect_critical(never, 5.0, 10.0, 0.01, grow=1.3, shrink=0.5)
    assert (low, used) == (0.0, "ankle") and bracket[1] <= 0.01 * 2 and len(calls) < 20
    with pytest.raises(InvalidParameterError, match="grow must be in"):
        bisect_critical(never, 0.0, 10.0, 0.01, grow=1.0 + 1e-12)
    with pytest.raises(InvalidParameterError, match="low must be < high"):
        bisect_critical(never, 10.0, 10.0, 0.01)
    with pytest.raises(ParameterTypeError, match="stands must be callable"):
        bisect_critical(None, 0.0, 10.0, 0.01)  # type: ignore[arg-type]


def test_frames_and_images_are_checked_before_any_drawing(tmp_path: Path) -> None:
    frames = [(0.001 * k, np.zeros(3), (0.0, 1.0), 0.0, 0.0) for k in range(10)]
    with pytest.raises(InvalidParameterError, match=r"fps must be in \[0, 10000\]"):
        subsample(frames, 1e15)  # a grid of 1e13 points, refused
    with pytest.raises(ParameterTypeError, match="frames must be a sequence"):
        subsample(math.nan, 25.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="a frame's time must be a finite number"):
        subsample([(math.nan, *frames[0][1:])], 25.0)
    image = np.zeros((4, 4, 3), dtype=np.uint8)
    with pytest.raises(InvalidParameterError, match="images must be uint8 RGB arrays"):
        write_filmstrip([image.astype(float)], [0.0], tmp_path / "a.png")
    with pytest.raises(InvalidParameterError, match="times must have entries in"):
        write_filmstrip([image], [1e300], tmp_path / "a.png")
    with pytest.raises(InvalidParameterError, match="path must name a file"):
        output_paths(Path(""))
    assert write_filmstrip([image], [0.0], tmp_path / "a.png").stat().st_size > 0
    with pytest.raises(InputFileError):  # the analysis readers share the file check
        from pushrecovery.arguments import input_file

        input_file("path", tmp_path)
