"""Pictures of the 3-D humanoids: overlays, tracking camera, filmstrip and GIF, bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for
from pushrecovery.sim.mujoco.humanoid3d.render3d import (
    Recording3D,
    default_camera,
    filmstrip_rows,
    render_recording3d,
    run_frames,
)
from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d
from pushrecovery.sim.mujoco.render import require_offscreen_gl
from pushrecovery.sim.mujoco.render.frames import subsample_indices
from pushrecovery.sim.mujoco.render.overlay3d import PULL, Frame3D, overlay_markers
from pushrecovery.sim.mujoco.render.scene.humanoid import (
    Camera3D,
    View3D,
    camera_eye,
    fit_camera3d,
    render_frames3d,
)
from pushrecovery.sim.push import Push3D

pytest.importorskip("mujoco")

#: The push of the recorded run [N s] and its azimuth [deg]: to the left, well inside the ankle
#: region (its 2-D critical impulse there is 33.8 N s for the paper body).
IMPULSE, AZIMUTH = 15.0, 90.0
#: The run after the push [s]: it comes to rest before (at rest over its feet for 0.5 s).
AFTER = 3.0


def is_magenta(im: np.ndarray) -> np.ndarray:
    r, g, b = (im[..., k].astype(int) for k in range(3))
    return (r > 150) & (b > 150) & (g < 90)


def is_green(im: np.ndarray) -> np.ndarray:
    r, g, b = (im[..., k].astype(int) for k in range(3))
    return (g > 150) & (r < 80) & (b < 80)


@pytest.fixture(scope="module")
def gl() -> None:
    try:
        require_offscreen_gl()
    except PushRecoveryError as exc:
        pytest.skip(f"offscreen OpenGL unavailable: {exc}")


@pytest.fixture(scope="module")
def plant() -> Biped3DPlant:
    return Biped3DPlant(load_params())


@pytest.fixture(scope="module")
def recording(plant: Biped3DPlant) -> Recording3D:
    run = run_push3d(plant, wbc_for(plant), Push3D(IMPULSE, AZIMUTH), duration=AFTER,
                     record=True)  # fmt: skip
    return Recording3D.of_plant_run(plant, run)


def pixel(camera: Camera3D, eye: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Pinhole projection (x right, y up, per unit depth), axes from the angles directly."""
    phi, theta = math.radians(camera.azimuth), math.radians(camera.elevation)
    back = np.array([math.cos(phi) * math.cos(theta), math.sin(phi) * math.cos(theta),
                     math.sin(theta)])  # fmt: skip  # from the target to the eye
    right = np.array([-math.sin(phi), math.cos(phi), 0.0])  # horizontal, 90° left of -back
    up = np.cross(back, right)
    d = point - eye
    depth = -d @ back
    return np.array([d @ right, d @ up]) / depth


def test_overlays_sit_on_the_lines_of_sight_of_the_true_points() -> None:
    # A CoM 1 m up at (0.1, 0.05) moving at (0.3, -0.2) m/s, ω = 3 1/s: ξ = c + ċ/ω.
    com, velocity, omega = np.array([0.1, 0.05, 1.0]), np.array([0.3, -0.2]), 3.0
    xi = com[:2] + velocity / omega
    frame = Frame3D(0.0, np.zeros(1), tuple(com), tuple(xi), (0.12, 0.0),
                    ((-0.05, -0.15), (0.15, -0.15), (0.15, 0.15), (-0.05, 0.15)))  # fmt: skip
    camera = Camera3D(azimuth=-60.0, elevation=30.0)
    view = View3D(camera, distance=4.0, height=0.8)
    eye = camera_eye(view, com)
    # The eye stands at the camera's azimuth and elevation from what it looks at.
    look = eye - np.array([com[0], com[1], 0.8])
    assert np.linalg.norm(look) == pytest.approx(4.0)
    assert math.degrees(math.atan2(look[1], look[0])) == pytest.approx(-60.0)
    assert math.degrees(math.asin(look[2] / 4.0)) == pytest.approx(30.0)
    markers = {m.name: m for m in overlay_markers(frame, eye, 0.02) if len(m.points) == 1}
    truth = {
        "com": com,
        "com ground": np.array([com[0], com[1], 0.0]),
        "capture point": np.array([xi[0], xi[1], 0.0]),
        "cop": np.array([0.12, 0.0, 0.0]),
    }
    for name, point in truth.items():
        drawn = np.array(markers[name].points[0])
        # Same pixel to 1e-9 (per unit depth), nearer the camera than the true point.
        assert np.allclose(pixel(camera, eye, drawn), pixel(camera, eye, point), atol=1e-9)
        assert np.linalg.norm(drawn - eye) < (1.0 - 0.9 * PULL) * np.linalg.norm(point - eye)
    # The outline's segments join the polygon's corners, each on its line of sight.
    edges = [m for m in overlay_markers(frame, eye, 0.02) if m.name == "support"]
    assert len(edges) == 4
    for edge, corner in zip(edges, frame.support, strict=True):
        start = np.array(edge.points[0])
        true = np.array([corner[0], corner[1], 0.0])
        assert np.allclose(pixel(camera, eye, start), pixel(camera, eye, true), atol=1e-9)
    # Nothing is drawn for what is not finite (the CoP in flight, an empty support).
    flying = Frame3D(0.0, np.zeros(1), tuple(com), tuple(xi), (math.nan, math.nan), ())
    names = {m.name for m in overlay_markers(flying, eye, 0.02)}
    assert "cop" not in names and "support" not in names and "capture point" in names


def test_replayed_frames_measure_cop_support_and_capture_point(
    plant: Biped3DPlant, recording: Recording3D
) -> None:
    params = plant.params
    # Standing at reset, just after the push (0.1 s + 10 ms), and at rest at the end.
    first, pushed, last = run_frames(recording, [0, 1, len(recording.time) - 1])
    assert pushed.time == pytest.approx(0.11)
    # At rest (|ċ| <= 5 mm/s for 0.5 s): the floor's CoP is under the CoM, to 3 mm.
    assert np.allclose(last.cop, last.com[:2], atol=3e-3)
    # Both soles down: the support polygon is the hull of both feet of the params.
    expected = Support.from_params(params).polygon.vertices
    got = np.array(first.support)
    assert got.shape == expected.shape
    for corner in expected:
        assert np.min(np.linalg.norm(got - corner, axis=1)) < 1e-3
    # Just after the push the capture point leads the CoM by (J/m)/ω along the push (the
    # plants' velocity change is within +2..+4 % of J/m: 6 % here).
    lead = np.subtract(pushed.capture_point, pushed.com[:2])
    along = np.array([math.cos(math.radians(AZIMUTH)), math.sin(math.radians(AZIMUTH))])
    assert lead @ along == pytest.approx(IMPULSE / params.mass / plant.omega, rel=0.06)


def test_default_camera_sees_the_push_go_left_to_right() -> None:
    assert default_camera(0.0).azimuth == pytest.approx(-90.0)  # on the body's right
    assert default_camera(90.0).azimuth == pytest.approx(0.0)  # in front
    assert abs(default_camera(270.0).azimuth) == pytest.approx(180.0)  # behind
    assert abs(default_camera(-90.0).azimuth) == pytest.approx(180.0)


def test_fitted_view_keeps_the_body_in_frame(plant: Biped3DPlant, recording: Recording3D) -> None:
    frames = run_frames(recording, [0, len(recording.time) - 1])
    camera = Camera3D(30.0, 20.0)
    view = fit_camera3d(plant.model, frames, camera, 0.8)
    tan_y = math.tan(math.radians(float(plant.model.vis.global_.fovy)) / 2.0)
    for f in frames:
        eye = camera_eye(view, f.com)
        top = np.array([f.com[0], f.com[1], 1.7])  # above the torso's top (1.68 m)
        for point in (top, np.array([f.com[0], f.com[1], 0.0])):
            x, y = pixel(camera, eye, point)
            assert abs(y) < tan_y and abs(x) < 0.8 * tan_y


def test_filmstrip_and_gif_are_written(gl: None, recording: Recording3D, tmp_path: Path) -> None:
    png, gif = render_recording3d(recording, tmp_path / "run.png", panels=4,
                                  panel_size=(120, 160), fps=20.0, size=(160, 120))  # fmt: skip
    assert (png, gif) == (tmp_path / "run.png", tmp_path / "run.gif")
    with Image.open(png) as im:
        width, height = im.size
        strip = np.asarray(im.convert("RGB"))
    assert width == 4 * 120 + 5 * 4  # four panels and five 4 px gaps
    assert height > 160
    assert is_magenta(strip).sum() > 4 * 5  # a support outline in each panel (and the legend)
    duration = float(recording.time[-1] - recording.time[0])
    with Image.open(gif) as im:
        assert im.size == (160, 120 + 22)  # the frame and the legend strip
        # 20 fps from the first frame, and the last one: floor(T * 20) + 1 (+ 1 off the grid).
        grid = math.floor(duration * 20.0 + 1e-9) + 1
        assert im.n_frames in (grid, grid + 1)
        assert im.n_frames == len(subsample_indices(recording.time, 20.0))


def test_markers_can_be_left_out(gl: None, plant: Biped3DPlant, recording: Recording3D) -> None:
    (frame,) = run_frames(recording, [0])
    view = fit_camera3d(plant.model, [frame], Camera3D(-45.0, 30.0), 1.0)
    plain, marked = (render_frames3d(plant.model, [frame], width=160, height=160, view=view,
                                     markers=m)[0] for m in (False, True))  # fmt: skip
    assert not is_magenta(plain).any() and not is_green(plain).any()
    assert is_magenta(marked).sum() > 10 and is_green(marked).sum() > 3


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Camera3D(azimuth=400.0), "azimuth"),
        (lambda: Camera3D(elevation=95.0), "elevation"),
        (lambda: Camera3D(elevation=math.nan), "elevation"),
        (lambda: default_camera(math.inf), "azimuth"),
    ],
)
def test_bad_cameras_are_refused(make, match) -> None:
    with pytest.raises(InvalidParameterError, match=match):
        make()


def test_bad_frames_and_options_are_refused(
    plant: Biped3DPlant, recording: Recording3D, tmp_path: Path
) -> None:
    time = recording.time
    bad_times = (
        ([], "1 to 20"),
        ([0.2, 0.1], "increasing"),
        ([0.1, math.nan], "finite"),
        ([0.1, 9.0], "within the run"),
        (["x"], "numbers"),
    )
    for times, match in bad_times:
        with pytest.raises(InvalidParameterError, match=match):
            filmstrip_rows(time, times, 6)
    with pytest.raises(InvalidParameterError, match="panels"):
        filmstrip_rows(time, None, 0)
    with pytest.raises(InvalidParameterError, match="rows"):
        run_frames(recording, [0, len(time)])
    with pytest.raises(InvalidParameterError, match="rows"):
        run_frames(recording, [3, 2])
    for kwargs, match in (({"fps": 0.0}, "fps"), ({"panel_size": (0, 10)}, "panel_size"),
                          ({"size": (10,)}, "size"), ({"camera": "side"}, "camera")):  # fmt: skip
        with pytest.raises((InvalidParameterError, ParameterTypeError), match=match):
            render_recording3d(recording, tmp_path / "bad", **kwargs)
    assert not list(tmp_path.iterdir())
    frame = run_frames(recording, [0])[0]
    with pytest.raises(InvalidParameterError, match="radius"):
        overlay_markers(frame, (0.0, -3.0, 1.0), 0.0)
    with pytest.raises(InvalidParameterError, match="eye"):
        overlay_markers(frame, (0.0, -3.0), 0.02)
    with pytest.raises(InvalidParameterError, match="aspect"):
        fit_camera3d(plant.model, [frame], Camera3D(), 0.0)
    with pytest.raises(InvalidParameterError, match="qpos"):
        fit_camera3d(plant.model, [Frame3D(0.0, np.zeros(3), (0, 0, 1), (0, 0), (0, 0))],
                     Camera3D(), 1.0)  # fmt: skip


def test_an_unrecorded_run_is_refused(plant: Biped3DPlant) -> None:
    run = run_push3d(plant, wbc_for(plant), Push3D(5.0, 0.0), duration=0.01)
    with pytest.raises(InvalidParameterError, match="record=True"):
        Recording3D.of_plant_run(plant, run)


def test_cli_renders_a_3d_run(gl: None, tmp_path: Path) -> None:
    from pushrecovery.cli.app import cli

    result = CliRunner().invoke(cli, [
        "humanoid", "simulate", "--model", "biped3d", "--azimuth", "90", "--push",
        "10", "--duration", "0.3", "--render", str(tmp_path / "side"), "--view-elevation",
        "30", "--frame-times", "0,0.2,0.4", "--json",
    ])  # fmt: skip
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["render"] == [str(tmp_path / "side.png"), str(tmp_path / "side.gif")]
    assert data["view"] == {"azimuth": 0.0, "elevation": 30.0}
    with Image.open(tmp_path / "side.png") as im:
        assert im.size[0] == 3 * 200 + 4 * 4  # the three frame times, 200 px panels


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--view-elevation", "95", "--render", "x"], "--view-elevation must be in"),
        (["--view-azimuth", "nan", "--render", "x"], "--view-azimuth"),
        (["--frame-times", "0.3,0.1", "--render", "x"], "--frame-times"),
        (["--frame-times", "a", "--render", "x"], "--frame-times"),
        (["--view-azimuth", "10"], "apply to --render of the 3-D humanoids"),
    ],
)
def test_cli_bad_camera_flags_are_one_line_and_exit_2(capsys, args, match) -> None:
    base = ["humanoid", "simulate", "--model", "biped3d", "--push", "10"]
    code, err = run_cli(capsys, *base, *args)
    assert code == 2 and match in err and err.count("\n") == 1 and "Traceback" not in err


def test_cli_camera_flags_need_a_3d_model(capsys) -> None:
    code, err = run_cli(capsys, "simulate", "--xdot", "0.1", "--frame-times", "0.1")
    assert code == 2 and err.count("\n") == 1
    assert "use 'pushrecovery humanoid simulate --frame-times 0.1'" in err


def run_cli(capsys, *args: str) -> tuple[int, str]:
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as caught:
        main(list(args))
    return caught.value.code, capsys.readouterr().err
