"""Offscreen rendering of a MuJoCo run: a filmstrip PNG and an animated GIF.

A plant records :class:`Frame` objects during a run (time, ``qpos`` and the overlay points in
the sagittal plane); :func:`render_run` replays them and writes ``FILE.png`` (a row of panels
evenly spaced in time, each labelled with its time) and ``FILE.gif`` (the run in real time).
The side camera looks at the plane y = 0 with x (forward) from left to right and z up. The
overlays are drawn as small spheres: CoM red, capture point blue, CoP green (on the floor).

OpenGL backend
--------------
MuJoCo picks its OpenGL backend from the environment variable ``MUJOCO_GL`` when
``mujoco`` is imported (module ``mujoco.rendering.classic.gl_context``), and creates the
context when a ``mujoco.Renderer`` is created. Before creating a renderer this module sets
``MUJOCO_GL=egl`` on Linux if the user has not set it (headless, works without a display;
``osmesa`` does not work everywhere). If ``mujoco`` was already imported with another value,
the backend selection module is re-executed (``importlib.reload``) so that the renderer follows
the current ``MUJOCO_GL``; nothing is changed when the user set ``MUJOCO_GL``. Nothing happens
at import of this module, so a missing OpenGL library can never break ``import mujoco``
for the physics. Any failure to create the OpenGL context is reported as a
:class:`~pushrecovery.errors.PushRecoveryError` naming ``MUJOCO_GL``.
"""

from __future__ import annotations

import importlib
import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError, PushRecoveryError

if TYPE_CHECKING:
    import mujoco
    from PIL import Image as PILImage

__all__ = [
    "Frame",
    "FrameLike",
    "View",
    "fit_view",
    "output_paths",
    "render_frames",
    "render_run",
    "require_offscreen_gl",
    "select_times",
    "subsample",
    "write_animation",
    "write_filmstrip",
]

#: RGBA colours of the overlay markers (also used by the legends).
COM_RGBA = (1.0, 0.0, 0.0, 1.0)
CAPTURE_POINT_RGBA = (0.1, 0.3, 1.0, 1.0)
COP_RGBA = (0.0, 0.8, 0.0, 1.0)
#: Legend entries: label and RGBA colour.
LEGEND = (("CoM", COM_RGBA), ("capture point", CAPTURE_POINT_RGBA), ("CoP", COP_RGBA))
#: Markers are moved this far towards the camera [m] (along the line of sight, so they are
#: drawn at the same pixel) so that the body does not hide them.
MARKER_OFFSET = 0.25
#: Marker radius as a fraction of the visible height.
MARKER_SCALE = 0.018
#: Default side camera angles [deg]: x from left to right, seen slightly from above.
AZIMUTH = 90.0
ELEVATION = -10.0
#: Backdrop: a light wall behind the plane y = 0, at this y [m], and its colour.
BACKDROP_DISTANCE = 3.0
BACKDROP_RGBA = (0.8, 0.86, 0.94, 1.0)
#: How long the last GIF frame is held before the animation loops [s].
HOLD_LAST = 1.0

_EXTENT_SAMPLES = 12
_LABEL_HEIGHT = 20
_LEGEND_HEIGHT = 22
_TITLE_HEIGHT = 22
_GAP = 4


@dataclass(frozen=True, eq=False)
class Frame:
    """One recorded instant of a run.

    Attributes
    ----------
    time : float
        Simulation time [s].
    qpos : NDArray[np.float64]
        Copy of ``data.qpos`` (shape ``(model.nq,)``).
    com : tuple[float, float]
        CoM position (x, z) in world coordinates [m].
    capture_point : float
        Capture point x on the floor [m] (drawn at z = 0; not drawn if not finite).
    cop : float
        CoP x on the floor [m]; NaN when the foot is off the floor (then not drawn).
    """

    time: float
    qpos: NDArray[np.float64]
    com: tuple[float, float]
    capture_point: float
    cop: float


#: A :class:`Frame` or a tuple of its fields in order (time, qpos, com, capture_point, cop),
#: as the plants record them (``MujocoPlant.frames``).
FrameLike = Frame | tuple[float, NDArray[np.float64], tuple[float, float], float, float]


def _as_frames(frames: Sequence[FrameLike]) -> list[Frame]:
    if len(frames) == 0:
        raise InvalidParameterError("frames must not be empty")
    out = []
    for f in frames:
        if isinstance(f, Frame):
            out.append(f)
        else:
            if len(f) != 5:
                raise InvalidParameterError(
                    "a frame must be a Frame or a tuple (time, qpos, com, capture_point, cop)"
                )
            t, qpos, com, capture_point, cop = f
            out.append(
                Frame(
                    float(t),
                    np.asarray(qpos, dtype=float),
                    (float(com[0]), float(com[1])),
                    float(capture_point),
                    float(cop),
                )
            )
    return out


@dataclass(frozen=True)
class View:
    """A free camera looking at the sagittal plane y = 0 (see :func:`fit_view`).

    Attributes
    ----------
    lookat : tuple[float, float, float]
        Point looked at, world coordinates [m].
    distance : float
        Camera distance from ``lookat`` [m].
    azimuth : float
        Camera azimuth [deg]; 90 puts x from left to right.
    elevation : float
        Camera elevation [deg]; negative looks down.
    """

    lookat: tuple[float, float, float]
    distance: float
    azimuth: float = AZIMUTH
    elevation: float = ELEVATION


# --- OpenGL --------------------------------------------------------------------------------
def _gl_name() -> str:
    return os.environ.get("MUJOCO_GL", "")


def _gl_error(exc: BaseException) -> PushRecoveryError:
    detail = (str(exc).strip().splitlines() or [""])[0] or type(exc).__name__
    if len(detail) > 120:
        detail = detail[:117] + "..."
    return PushRecoveryError(
        f"cannot render offscreen with MUJOCO_GL={_gl_name()!r} ({type(exc).__name__}: "
        f"{detail}); set MUJOCO_GL=egl (headless) or glfw (with a display)"
    )


def _mujoco_for_rendering() -> ModuleType:
    """Import ``mujoco`` with its OpenGL backend following ``MUJOCO_GL`` (egl by default)."""
    if sys.platform.startswith("linux"):
        os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco

        # The module the Renderer takes its GLContext class from (it looks the class up
        # there when a Renderer is created).
        renderer_module = sys.modules.get(getattr(mujoco.Renderer, "__module__", ""))
        gl_context = getattr(renderer_module, "gl_context", None)
        chosen = getattr(gl_context, "_MUJOCO_GL", None)
        if gl_context is not None and chosen is not None:
            if chosen != _gl_name().lower().strip():
                # mujoco was imported before MUJOCO_GL was set: select the backend again.
                importlib.reload(gl_context)
    except Exception as exc:  # an invalid MUJOCO_GL raises RuntimeError, a broken one others
        raise _gl_error(exc) from exc
    return mujoco


def _open_renderer(model: mujoco.MjModel, width: int, height: int) -> mujoco.Renderer:
    mj = _mujoco_for_rendering()
    buffer = (model.vis.global_.offwidth, model.vis.global_.offheight)
    if not (0 < width <= buffer[0] and 0 < height <= buffer[1]):
        raise InvalidParameterError(
            f"image size must be within the model's offscreen buffer {buffer[0]}x{buffer[1]} "
            f"px, got {width}x{height}"
        )
    try:
        return mj.Renderer(model, height=height, width=width)
    except Exception as exc:  # FatalError, ImportError, AttributeError, ... by backend
        raise _gl_error(exc) from exc


def require_offscreen_gl() -> None:
    """Check that offscreen rendering works (call it before a long run to fail early).

    Raises
    ------
    PushRecoveryError
        If no OpenGL context can be created; the message names ``MUJOCO_GL``.
    """
    mj = _mujoco_for_rendering()
    model = mj.MjModel.from_xml_string("<mujoco/>")
    _open_renderer(model, 8, 8).close()


# --- frames and camera ---------------------------------------------------------------------
def _times(frames: Sequence[Frame]) -> NDArray[np.float64]:
    times = np.array([f.time for f in frames], dtype=float)
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0.0):
        raise InvalidParameterError("frame times must be finite and non-decreasing")
    return times


def _nearest(times: NDArray[np.float64], targets: NDArray[np.float64]) -> list[int]:
    """Return the indices of the times nearest to the targets, without repeats, in order."""
    if len(times) == 1:
        return [0]
    right = np.clip(np.searchsorted(times, targets), 1, len(times) - 1)
    left = right - 1
    idx = np.where(np.abs(times[left] - targets) <= np.abs(times[right] - targets), left, right)
    return [int(i) for i in np.unique(idx)]


def _check_qpos(model: mujoco.MjModel, frame: Frame) -> None:
    if np.shape(frame.qpos) != (model.nq,):
        raise InvalidParameterError(
            f"frame qpos must have shape ({model.nq},), got {np.shape(frame.qpos)}"
        )


def subsample(frames: Sequence[FrameLike], fps: float) -> list[Frame]:
    """Frames nearest to a regular grid of ``fps`` frames per second (first and last kept).

    Parameters
    ----------
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing (e.g. recorded at 1 kHz).
    fps : float
        Target frame rate [1/s], > 0.

    Returns
    -------
    list[Frame]
        At most about ``duration * fps + 1`` frames.
    """
    if not (math.isfinite(fps) and fps > 0.0):
        raise InvalidParameterError(f"fps must be > 0 1/s, got {fps:g}")
    frames = _as_frames(frames)
    times = _times(frames)
    count = math.floor((times[-1] - times[0]) * fps + 1e-9) + 1
    targets = np.append(times[0] + np.arange(count) / fps, times[-1])
    return [frames[i] for i in _nearest(times, targets)]


def select_times(frames: Sequence[FrameLike], count: int) -> list[Frame]:
    """``count`` frames evenly spaced in time, from the first to the last.

    Parameters
    ----------
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing.
    count : int
        Number of frames wanted, >= 1 (fewer are returned if there are fewer distinct ones).

    Returns
    -------
    list[Frame]
        The frames nearest to ``count`` evenly spaced times.
    """
    if count < 1:
        raise InvalidParameterError(f"count must be >= 1, got {count}")
    frames = _as_frames(frames)
    times = _times(frames)
    return [frames[i] for i in _nearest(times, np.linspace(times[0], times[-1], count))]


def _body_extent(model: mujoco.MjModel, frames: Sequence[Frame]) -> NDArray[np.float64]:
    """World x and z of the corners of the bounding boxes of the moving geoms, ``(n, 2)`` [m].

    Geoms of the world body (floor, static scenery) are left out; up to ``_EXTENT_SAMPLES``
    frames evenly spaced in time are replayed.
    """
    mj = _mujoco_for_rendering()
    moving = np.flatnonzero(np.asarray(model.geom_bodyid) != 0)
    if moving.size == 0:
        return np.empty((0, 2))
    aabb = np.asarray(model.geom_aabb, dtype=float)[moving]
    data = mj.MjData(model)
    points = []
    for f in select_times(frames, _EXTENT_SAMPLES):
        data.qpos[:] = f.qpos
        mj.mj_kinematics(model, data)
        rot = np.asarray(data.geom_xmat, dtype=float)[moving].reshape(-1, 3, 3)
        centre = np.asarray(data.geom_xpos, dtype=float)[moving] + np.einsum(
            "gij,gj->gi", rot, aabb[:, :3]
        )
        half = np.einsum("gij,gj->gi", np.abs(rot), aabb[:, 3:])
        for sign in (-1.0, 1.0):
            points.append((centre + sign * half)[:, [0, 2]])
    return np.concatenate(points)


def fit_view(model: mujoco.MjModel, frames: Sequence[FrameLike], aspect: float) -> View:
    """Side view framing the floor, the moving bodies and the CoM and CoP over all ``frames``.

    The visible box spans the bounding boxes of the moving geoms (replayed at a few frames),
    the CoM and CoP paths and the floor (z = 0), with a 15 % margin; the capture point may
    leave the image.

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with (its free camera field of view
        ``vis.global_.fovy`` is used).
    frames : Sequence[FrameLike]
        Recorded frames.
    aspect : float
        Image width / height, > 0.

    Returns
    -------
    View
        Camera looking at the centre of the box from the side (azimuth 90 deg, elevation
        -10 deg), far enough for the box to fit.
    """
    if not (math.isfinite(aspect) and aspect > 0.0):
        raise InvalidParameterError(f"aspect must be > 0, got {aspect:g}")
    frames = _as_frames(frames)
    _times(frames)
    for f in frames:
        _check_qpos(model, f)
    com = np.array([f.com for f in frames], dtype=float).reshape(-1, 2)
    cop = np.array([(f.cop, 0.0) for f in frames], dtype=float)
    points = np.concatenate([com, cop, _body_extent(model, frames), [[com[0, 0], 0.0]]])
    points = points[np.all(np.isfinite(points), axis=1)]
    (x_lo, z_lo), (x_hi, z_hi) = points.min(axis=0), points.max(axis=0)
    z_lo = min(float(z_lo), 0.0)
    height = max(float(z_hi) - z_lo, 0.2)
    margin = 0.15 * height
    width = float(x_hi - x_lo) + 2.0 * margin
    height += 2.0 * margin
    half_tan = math.tan(math.radians(float(model.vis.global_.fovy)) / 2.0)
    distance = max(height / (2.0 * half_tan), width / (2.0 * half_tan * aspect))
    lookat = (0.5 * float(x_lo + x_hi), 0.0, 0.5 * float(z_lo + z_hi))
    return View(lookat=lookat, distance=distance)


def _add_geom(
    mj: Any,
    scene: Any,
    kind: Any,
    size: tuple[float, float, float],
    pos: NDArray[np.float64],
    rgba: tuple[float, float, float, float],
    emission: float,
) -> None:
    """Append a decoration geom to ``scene`` (silently skipped when the scene is full)."""
    if scene.ngeom >= scene.maxgeom:
        return
    geom = scene.geoms[scene.ngeom]
    mj.mjv_initGeom(
        geom,
        kind,
        np.array(size, dtype=float),
        np.asarray(pos, dtype=float),
        np.eye(3).ravel(),
        np.array(rgba, dtype=np.float32),
    )
    geom.category = mj.mjtCatBit.mjCAT_DECOR
    geom.emission = emission
    geom.specular = 0.0
    geom.castshadow = 0
    scene.ngeom += 1


def _backdrop_emission(model: mujoco.MjModel) -> float:
    """Emission that brings the backdrop to about its own colour whatever the lights.

    Estimates the light on a wall facing the camera (-y): the headlight (ambient and diffuse)
    plus each light's ambient and diffuse (as if directional) terms.
    """
    head = model.vis.headlight
    light = float(np.mean(head.ambient) + np.mean(head.diffuse)) if head.active else 0.0
    for k in range(model.nlight):
        direction = np.asarray(model.light_dir[k], dtype=float)
        facing = max(0.0, float(direction[1]) / max(float(np.linalg.norm(direction)), 1e-9))
        light += float(np.mean(model.light_ambient[k]) + np.mean(model.light_diffuse[k]) * facing)
    return max(0.0, 1.0 - light)


def _decorate(
    mj: Any, scene: Any, frame: Frame | None, view: View, radius: float, backdrop: float
) -> None:
    """Add the backdrop and the CoM, capture point and CoP markers of ``frame`` to ``scene``.

    Each marker is moved ``MARKER_OFFSET`` towards the camera along its line of sight, so it
    is drawn at its true pixel but in front of the body. The CoP marker is smaller and nearer
    the camera than the capture point's, so both show when they coincide. ``backdrop`` is the
    backdrop's emission.
    """
    eye = 0.5 * (np.array(scene.camera[0].pos) + np.array(scene.camera[1].pos))
    x, _, z = view.lookat
    far = 4.0 * view.distance
    _add_geom(
        mj, scene, mj.mjtGeom.mjGEOM_BOX, (far, 0.01, far),
        np.array([x, BACKDROP_DISTANCE, z]), BACKDROP_RGBA, backdrop,
    )  # fmt: skip
    if frame is None:
        return
    markers = (
        ((frame.com[0], frame.com[1]), COM_RGBA, 1.0, 0.0),
        ((frame.capture_point, 0.0), CAPTURE_POINT_RGBA, 1.0, 0.0),
        ((frame.cop, 0.0), COP_RGBA, 0.6, 1.5),
    )
    for (px, pz), rgba, scale, nearer in markers:
        point = np.array([px, 0.0, pz], dtype=float)
        if not np.all(np.isfinite(point)):
            continue
        ray = (eye - point) / np.linalg.norm(eye - point)
        pos = point + (MARKER_OFFSET + nearer * radius) * ray
        _add_geom(mj, scene, mj.mjtGeom.mjGEOM_SPHERE, (scale * radius, 0, 0), pos, rgba, 0.5)


def render_frames(
    model: mujoco.MjModel,
    frames: Sequence[FrameLike],
    *,
    width: int = 320,
    height: int = 240,
    view: View | None = None,
    markers: bool = True,
    shadows: bool = False,
) -> list[NDArray[np.uint8]]:
    """Render each frame (``qpos`` replayed with ``mj_forward``) from the side.

    A light backdrop is drawn behind the plane y = 0 (at y = ``BACKDROP_DISTANCE``).

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with.
    frames : Sequence[FrameLike]
        Frames to render (all of them: subsample first with :func:`subsample`).
    width, height : int
        Image size [px], within the model's offscreen buffer (640x480 by default).
    view : View or None
        Camera; default :func:`fit_view` of ``frames``.
    markers : bool
        Draw the CoM (red), capture point (blue) and CoP (green) markers.
    shadows : bool
        Render shadows (off by default: about 8 times slower with software OpenGL).

    Returns
    -------
    list[NDArray[np.uint8]]
        One ``(height, width, 3)`` RGB image per frame.

    Raises
    ------
    PushRecoveryError
        If offscreen OpenGL is unavailable (message names ``MUJOCO_GL``).
    """
    frames = _as_frames(frames)
    _times(frames)
    for f in frames:
        _check_qpos(model, f)
    view = view if view is not None else fit_view(model, frames, width / height)
    mj = _mujoco_for_rendering()
    renderer = _open_renderer(model, width, height)
    data = mj.MjData(model)
    camera = mj.MjvCamera()
    camera.type = mj.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = view.lookat
    camera.distance = view.distance
    camera.azimuth = view.azimuth
    camera.elevation = view.elevation
    half_tan = math.tan(math.radians(float(model.vis.global_.fovy)) / 2.0)
    radius = MARKER_SCALE * 2.0 * view.distance * half_tan
    backdrop = _backdrop_emission(model)
    images: list[NDArray[np.uint8]] = []
    try:
        for f in frames:
            data.qpos[:] = f.qpos
            mj.mj_forward(model, data)
            renderer.update_scene(data, camera=camera)
            scene = renderer.scene
            scene.flags[mj.mjtRndFlag.mjRND_SHADOW] = shadows
            _decorate(mj, scene, f if markers else None, view, radius, backdrop)
            images.append(renderer.render().copy())
    finally:
        renderer.close()
    return images


# --- images ----------------------------------------------------------------------------------
def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError, ImportError):  # old Pillow or no FreeType: bitmap font
        return ImageFont.load_default()


def _rgb(rgba: tuple[float, float, float, float]) -> tuple[int, int, int]:
    return (round(255 * rgba[0]), round(255 * rgba[1]), round(255 * rgba[2]))


def _draw_legend(draw: Any, x: int, y: int, height: int, font: Any) -> None:
    """Coloured dots and names of the markers, starting at (x, y) in a strip of ``height``."""
    r = max(3, height // 4)
    cy = y + height // 2
    for name, rgba in LEGEND:
        draw.ellipse((x, cy - r, x + 2 * r, cy + r), fill=_rgb(rgba))
        x += 2 * r + 4
        draw.text((x, cy), name, fill=(0, 0, 0), font=font, anchor="lm")
        x += int(draw.textlength(name, font=font)) + 12


def _check_images(images: Sequence[NDArray[np.uint8]], times: Sequence[float]) -> None:
    if len(images) == 0 or len(images) != len(times):
        raise InvalidParameterError(
            f"need as many times as images (>= 1), got {len(times)} and {len(images)}"
        )
    shape = np.shape(images[0])
    if len(shape) != 3 or shape[2] != 3 or any(np.shape(im) != shape for im in images):
        raise InvalidParameterError("images must be RGB arrays of one shape (height, width, 3)")


def _save(image: PILImage.Image, path: Path, **options: Any) -> Path:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        image.save(path, **options)
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {path}: {exc.strerror or exc}") from exc
    return path


def write_filmstrip(
    images: Sequence[NDArray[np.uint8]],
    times: Sequence[float],
    path: Path,
    *,
    title: str | None = None,
) -> Path:
    """Write the images side by side, each labelled ``t = ... s``, with a legend, as a PNG.

    Parameters
    ----------
    images : Sequence[NDArray[np.uint8]]
        RGB images of one shape ``(height, width, 3)``.
    times : Sequence[float]
        Time of each image [s].
    path : Path
        Output file (PNG, 256-colour palette to keep it small); parents are created.
    title : str or None
        Optional line of text above the panels.

    Returns
    -------
    Path
        ``path``.
    """
    from PIL import Image, ImageDraw

    _check_images(images, times)
    h, w = np.shape(images[0])[:2]
    n = len(images)
    top = _TITLE_HEIGHT if title else 0
    canvas = Image.new(
        "RGB", (n * w + (n + 1) * _GAP, top + _LABEL_HEIGHT + h + _LEGEND_HEIGHT + _GAP), "white"
    )
    draw = ImageDraw.Draw(canvas)
    font = _font(13)
    if title:
        draw.text((_GAP, top // 2), title, fill=(0, 0, 0), font=_font(15), anchor="lm")
    for k, (image, t) in enumerate(zip(images, times, strict=True)):
        x = _GAP + k * (w + _GAP)
        label = f"t = {t:.2f} s"
        draw.text(
            (x + w // 2, top + _LABEL_HEIGHT // 2), label, fill=(0, 0, 0), font=font, anchor="mm"
        )
        canvas.paste(Image.fromarray(np.asarray(image, dtype=np.uint8)), (x, top + _LABEL_HEIGHT))
    _draw_legend(draw, _GAP, top + _LABEL_HEIGHT + h, _LEGEND_HEIGHT, font)
    paletted = canvas.quantize(colors=256, dither=Image.Dither.NONE)
    return _save(paletted, Path(path), optimize=True)


def write_animation(
    images: Sequence[NDArray[np.uint8]], times: Sequence[float], path: Path
) -> Path:
    """Write the images as a looping GIF played in real time, with time label and legend.

    Parameters
    ----------
    images : Sequence[NDArray[np.uint8]]
        RGB images of one shape ``(height, width, 3)``.
    times : Sequence[float]
        Time of each image [s], non-decreasing; frame delays follow them (rounded to the
        GIF's 10 ms unit without drift); the last frame is held ``HOLD_LAST`` s.
    path : Path
        Output file (GIF); parents are created.

    Returns
    -------
    Path
        ``path``.
    """
    from PIL import Image, ImageDraw

    _check_images(images, times)
    t = np.asarray(times, dtype=float)
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0.0):
        raise InvalidParameterError("times must be finite and non-decreasing")
    ticks = np.round((t - t[0]) * 100.0).astype(int)  # centiseconds, rounded without drift
    delays = [max(10, int(10 * d)) for d in np.diff(ticks)] + [round(1000 * HOLD_LAST)]
    h, w = np.shape(images[0])[:2]
    font = _font(12)
    frames = []
    for image, time in zip(images, t, strict=True):
        canvas = Image.new("RGB", (w, h + _LEGEND_HEIGHT), "white")
        canvas.paste(Image.fromarray(np.asarray(image, dtype=np.uint8)), (0, 0))
        draw = ImageDraw.Draw(canvas)
        _draw_legend(draw, _GAP, h, _LEGEND_HEIGHT, font)
        draw.text(
            (w - _GAP, h + _LEGEND_HEIGHT // 2),
            f"t = {time:.2f} s",
            fill=(0, 0, 0),
            font=font,
            anchor="rm",
        )
        frames.append(canvas)
    # One palette for all frames, so the static background stays identical between frames
    # and the GIF stores only the changed rectangle of each frame.
    palette = frames[0].quantize(colors=128, dither=Image.Dither.NONE)
    paletted = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    return _save(
        paletted[0],
        Path(path),
        save_all=True,
        append_images=paletted[1:],
        duration=delays,
        loop=0,
        optimize=False,
    )


# --- all together --------------------------------------------------------------------------
def output_paths(path: Path) -> tuple[Path, Path]:
    """Filmstrip and animation paths for ``--render FILE``: ``FILE.png`` and ``FILE.gif``.

    A ``.png`` or ``.gif`` suffix of ``path`` is replaced, any other suffix is kept
    (``run.v2`` gives ``run.v2.png``).
    """
    path = Path(path)
    base = path.with_suffix("") if path.suffix.lower() in (".png", ".gif") else path
    return base.with_name(base.name + ".png"), base.with_name(base.name + ".gif")


def render_run(
    model: mujoco.MjModel,
    frames: Sequence[FrameLike],
    path: Path,
    *,
    panels: int = 7,
    panel_size: tuple[int, int] = (180, 240),
    fps: float = 25.0,
    size: tuple[int, int] = (320, 240),
    title: str | None = None,
) -> tuple[Path, Path]:
    """Write the filmstrip PNG and the animated GIF of a recorded run.

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with.
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing (any rate, e.g. every step at 1 kHz).
    path : Path
        ``FILE``, ``FILE.png`` or ``FILE.gif``: both ``FILE.png`` and ``FILE.gif`` are written
        (see :func:`output_paths`).
    panels : int
        Number of filmstrip panels, evenly spaced in time from the first to the last frame.
    panel_size : tuple[int, int]
        Filmstrip panel (width, height) [px].
    fps : float
        GIF frame rate [1/s], in (0, 50] (browsers slow down faster GIFs); the recorded frames
        are subsampled to it (25 fps is exact in the GIF's 10 ms delay unit).
    size : tuple[int, int]
        GIF frame (width, height) [px] (a legend strip is added below).
    title : str or None
        Optional title line of the filmstrip.

    Returns
    -------
    tuple[Path, Path]
        Paths of the PNG filmstrip and of the GIF.

    Raises
    ------
    PushRecoveryError
        If offscreen OpenGL is unavailable (message names ``MUJOCO_GL``) or a file cannot be
        written; :class:`~pushrecovery.errors.InvalidParameterError` on bad arguments.
    """
    if not (math.isfinite(fps) and 0.0 < fps <= 50.0):
        raise InvalidParameterError(f"fps must be in (0, 50] 1/s, got {fps:g}")
    png, gif = output_paths(path)
    frames = _as_frames(frames)
    strip = select_times(frames, panels)
    strip_images = render_frames(
        model,
        strip,
        width=panel_size[0],
        height=panel_size[1],
        view=fit_view(model, frames, panel_size[0] / panel_size[1]),
    )
    write_filmstrip(strip_images, [f.time for f in strip], png, title=title)
    movie = subsample(frames, fps)
    movie_images = render_frames(
        model, movie, width=size[0], height=size[1], view=fit_view(model, frames, size[0] / size[1])
    )
    write_animation(movie_images, [f.time for f in movie], gif)
    return png, gif
