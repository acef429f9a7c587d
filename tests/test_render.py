"""Rendering of MuJoCo runs: filmstrip PNG, GIF, overlay markers, OpenGL errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.sim.mujoco import render
from pushrecovery.sim.mujoco.render import Frame

mujoco = pytest.importorskip("mujoco")

# A 1 m slab on a hinge at the floor: an inverted pendulum that falls forward (+x).
MODEL = """
<mujoco>
  <option timestep="0.001"/>
  <worldbody>
    <light pos="0 -2 3" dir="0 1 -1" directional="true"/>
    <geom name="floor" type="plane" size="3 1 0.1" rgba="0.6 0.6 0.6 1"/>
    <body name="slab" pos="0 0 0">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="box" pos="0 0 0.5" size="0.03 0.08 0.5" mass="10" rgba="0.7 0.7 0.5 1"
            contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""
DURATION = 0.8  # [s], recorded at 1 kHz


def is_red(im: np.ndarray) -> np.ndarray:
    r, g, b = (im[..., k].astype(int) for k in range(3))
    return (r > 180) & (g < 70) & (b < 70)


def is_green(im: np.ndarray) -> np.ndarray:
    r, g, b = (im[..., k].astype(int) for k in range(3))
    return (g > 150) & (r < 80) & (b < 80)


def is_blue(im: np.ndarray) -> np.ndarray:
    r, g, b = (im[..., k].astype(int) for k in range(3))
    return (b > 180) & (r < 80) & (g < 130)


@pytest.fixture(scope="module")
def gl() -> None:
    try:
        render.require_offscreen_gl()
    except PushRecoveryError as exc:
        pytest.skip(f"offscreen OpenGL unavailable: {exc}")


@pytest.fixture(scope="module")
def run() -> tuple[object, list[Frame]]:
    model = mujoco.MjModel.from_xml_string(MODEL)
    data = mujoco.MjData(model)
    data.qpos[0] = 0.05
    frames: list[Frame] = []
    for _ in range(round(DURATION / model.opt.timestep)):
        mujoco.mj_step(model, data)
        mujoco.mj_subtreeVel(model, data)
        x, _, z = data.subtree_com[1]
        xdot = data.subtree_linvel[1][0]
        capture = x + xdot / math.sqrt(9.81 / z)
        cop = 0.0 if data.time < 0.5 * DURATION else math.nan  # the foot "lifts" halfway
        frames.append(Frame(data.time, data.qpos.copy(), (x, z), capture, cop))
    return model, frames


def test_render_run_writes_png_filmstrip_and_gif(gl: None, run, tmp_path: Path) -> None:
    model, frames = run
    # The plants record plain tuples in Frame's field order: accepted too.
    as_tuples = [(f.time, f.qpos, f.com, f.capture_point, f.cop) for f in frames]
    png, gif = render.render_run(model, as_tuples, tmp_path / "out" / "run.png", title="test")
    assert (png, gif) == (tmp_path / "out" / "run.png", tmp_path / "out" / "run.gif")
    assert png.stat().st_size < 300_000
    with Image.open(png) as im:
        assert im.format == "PNG"
        width, height = im.size
        strip = np.asarray(im.convert("RGB"))
    assert width > 6 * 180 and height >= 240
    assert is_red(strip).sum() > 7 * 10  # a CoM marker in each of the 7 panels (and legend)
    with Image.open(gif) as im:
        assert im.format == "GIF"
        assert im.n_frames == round(DURATION * 25) + 1  # 25 fps, first and last frames
        durations = []
        for k in range(im.n_frames):
            im.seek(k)
            durations.append(im.info["duration"])
    assert durations[:-1] == [40] * (len(durations) - 1)
    assert durations[-1] == 1000  # the last frame is held


def test_markers_are_drawn(gl: None, run) -> None:
    model, frames = run
    first, late = frames[0], frames[-1]
    view = render.fit_view(model, frames, 320 / 240)  # one camera for the whole run
    plain = render.render_frames(model, [first], view=view, markers=False)[0]
    marked, lifted = render.render_frames(model, [first, late], view=view)
    assert plain.shape == marked.shape == (240, 320, 3) and marked.dtype == np.uint8
    assert not is_red(plain).any() and not is_green(plain).any()
    red = is_red(marked)
    assert red.sum() > 20
    # The CoM (1 m up) is drawn in the upper part of the image, the CoP low down.
    rows = np.nonzero(red)[0]
    assert rows.mean() < 0.5 * marked.shape[0]
    assert np.nonzero(is_green(marked))[0].mean() > 0.6 * marked.shape[0]
    assert is_blue(marked).sum() > 5
    # Late in the run the CoP is NaN (not drawn) and the CoM has moved forward (right).
    assert not is_green(lifted).any()
    assert np.nonzero(is_red(lifted))[1].mean() > np.nonzero(red)[1].mean() + 10


def test_gl_failure_is_a_pushrecovery_error(gl: None, run, monkeypatch) -> None:
    model, frames = run

    def broken(*args: object, **kwargs: object) -> None:
        raise mujoco.FatalError("an OpenGL platform library has not been loaded")

    monkeypatch.setattr(mujoco, "Renderer", broken)
    with pytest.raises(PushRecoveryError, match="MUJOCO_GL") as info:
        render.render_frames(model, frames[:1])
    assert "\n" not in str(info.value)


def test_backend_is_selected_again_if_mujoco_was_imported_first(gl: None, monkeypatch) -> None:
    # As if mujoco had been imported with another MUJOCO_GL (here: with no OpenGL backend):
    # the renderer's backend module is re-executed with the current MUJOCO_GL.
    import sys

    gl_context = sys.modules[mujoco.Renderer.__module__].gl_context
    monkeypatch.setattr(gl_context, "_MUJOCO_GL", "not-the-current-value")
    monkeypatch.setattr(gl_context, "GLContext", None)
    render.require_offscreen_gl()
    assert gl_context.GLContext is not None


def test_output_paths() -> None:
    assert render.output_paths(Path("a/run.png")) == (Path("a/run.png"), Path("a/run.gif"))
    assert render.output_paths(Path("run.GIF")) == (Path("run.png"), Path("run.gif"))
    assert render.output_paths(Path("run")) == (Path("run.png"), Path("run.gif"))
    assert render.output_paths(Path("run.v2")) == (Path("run.v2.png"), Path("run.v2.gif"))


def test_subsample_and_select_times() -> None:
    qpos = np.zeros(1)
    frames = [Frame(k * 1e-3, qpos, (0.0, 1.0), 0.0, 0.0) for k in range(1001)]
    movie = render.subsample(frames, 30.0)
    times = np.array([f.time for f in movie])
    assert times[0] == 0.0 and times[-1] == 1.0
    assert len(movie) == 31  # 0, 1/30, ..., 30/30 (the last frame, kept once)
    strip = render.select_times(frames, 7)
    np.testing.assert_allclose([f.time for f in strip], np.linspace(0.0, 1.0, 7), atol=1e-3)
    assert len(render.subsample(frames[:1], 25.0)) == 1
    with pytest.raises(InvalidParameterError):
        render.subsample([], 25.0)
    with pytest.raises(InvalidParameterError):
        render.subsample(frames, 0.0)
    with pytest.raises(InvalidParameterError):
        render.select_times(frames[::-1], 3)
