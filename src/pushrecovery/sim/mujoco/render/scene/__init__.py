"""Rendering frames off-screen with MuJoCo: the view, the overlay markers, the render loop."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.control.wbc.bodies import check_model
from pushrecovery.errors import InvalidParameterError

if TYPE_CHECKING:
    import mujoco
from pushrecovery.sim.mujoco.render.frames import (
    Frame,
    FrameLike,
    _as_frames,
    _checked_times,
    select_times,
)
from pushrecovery.sim.mujoco.render.gl import _mujoco_for_rendering, _open_renderer

__all__ = [
    "AZIMUTH",
    "BACKDROP_DISTANCE",
    "BACKDROP_RGBA",
    "CAPTURE_POINT_RGBA",
    "COM_RGBA",
    "COP_RGBA",
    "ELEVATION",
    "LEGEND",
    "MARKER_OFFSET",
    "MARKER_SCALE",
    "View",
    "fit_view",
    "render_frames",
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
_EXTENT_SAMPLES = 12


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


def check_size(name: str, size: object) -> tuple[int, int]:
    """Return ``size`` as (width, height) [px], positive whole numbers, or raise naming ``name``."""
    if (
        not isinstance(size, tuple | list)
        or len(size) != 2
        or not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size)
    ):
        raise InvalidParameterError(f"{name} must be (width, height), positive integers [px]")
    return int(size[0]), int(size[1])


def check_aspect(aspect: object) -> float:
    """Return an image's width / height in [1e-3, 1e3], or raise naming ``aspect``."""
    return bounded_float("aspect", aspect, 1e-3, 1e3)


def _check_qpos(model: mujoco.MjModel, frame: Frame) -> None:
    if np.shape(frame.qpos) != (model.nq,):
        raise InvalidParameterError(
            f"frame qpos must have shape ({model.nq},), got {np.shape(frame.qpos)}"
        )


def _moving_boxes(model: mujoco.MjModel, frames: Sequence[Any]) -> Iterator[tuple[Any, ...]]:
    """Replay each frame (``mj_kinematics``); yield it and its moving geoms' bounding boxes.

    Moving: not the world body's (floor, static scenery). The boxes: rotations ``(g, 3, 3)``,
    centres ``(g, 3)`` [m] and half sizes ``(g, 3)`` [m].
    """
    mj = _mujoco_for_rendering()
    moving = np.flatnonzero(np.asarray(model.geom_bodyid) != 0)
    aabb = np.asarray(model.geom_aabb, dtype=float)[moving]
    data = mj.MjData(model)
    for f in frames:
        data.qpos[:] = f.qpos
        mj.mj_kinematics(model, data)
        rot = np.asarray(data.geom_xmat, dtype=float)[moving].reshape(-1, 3, 3)
        centre = np.asarray(data.geom_xpos, dtype=float)[moving] + np.einsum(
            "gij,gj->gi", rot, aabb[:, :3]
        )
        yield f, rot, centre, aabb[:, 3:]


def _body_extent(model: mujoco.MjModel, frames: Sequence[Frame]) -> NDArray[np.float64]:
    """World x and z of the corners of the moving geoms' boxes, ``(n, 2)`` [m].

    At up to ``_EXTENT_SAMPLES`` frames evenly spaced in time (:func:`_moving_boxes`).
    """
    if not np.any(np.asarray(model.geom_bodyid) != 0):
        return np.empty((0, 2))
    points = []
    for _, rot, centre, size in _moving_boxes(model, select_times(frames, _EXTENT_SAMPLES)):
        half = np.einsum("gij,gj->gi", np.abs(rot), size)
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
        Image width / height, in [1e-3, 1e3].

    Returns
    -------
    View
        Camera looking at the centre of the box from the side (azimuth 90 deg, elevation
        -10 deg), far enough for the box to fit.
    """
    check_model(model)
    aspect = check_aspect(aspect)
    frames = _as_frames(frames)
    _checked_times([f.time for f in frames])
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


def _wall_emission(model: mujoco.MjModel, normal: NDArray[np.float64]) -> float:
    """Emission that brings a wall facing ``normal`` to about its own colour whatever the lights.

    Estimates the light on the wall: the headlight (ambient and diffuse) plus each light's
    ambient and diffuse (as if directional) terms.
    """
    head = model.vis.headlight
    light = float(np.mean(head.ambient) + np.mean(head.diffuse)) if head.active else 0.0
    for k in range(model.nlight):
        direction = np.asarray(model.light_dir[k], dtype=float)
        facing = max(0.0, -float(direction @ normal) / max(float(np.linalg.norm(direction)), 1e-9))
        light += float(np.mean(model.light_ambient[k]) + np.mean(model.light_diffuse[k]) * facing)
    return max(0.0, 1.0 - light)


def _render_each(
    model: mujoco.MjModel,
    frames: Sequence[Any],
    size: tuple[int, int],
    distance: float,
    aim: Callable[[Any, Any], None],
    decorate: Callable[[Any, Any, Any, float], None],
    shadows: bool,
) -> list[NDArray[np.uint8]]:
    """Replay each frame (``mj_forward``) and render it from the free camera.

    Images of (width, height) ``size`` [px]; ``aim(camera, frame)`` places the camera,
    ``decorate(mj, scene, frame, radius)`` adds the overlays, ``radius`` [m] being
    ``MARKER_SCALE`` of the height seen at ``distance`` [m].
    """
    mj = _mujoco_for_rendering()
    renderer = _open_renderer(model, size[0], size[1])
    data = mj.MjData(model)
    camera = mj.MjvCamera()
    camera.type = mj.mjtCamera.mjCAMERA_FREE
    half_tan = math.tan(math.radians(float(model.vis.global_.fovy)) / 2.0)
    radius = MARKER_SCALE * 2.0 * distance * half_tan
    images: list[NDArray[np.uint8]] = []
    try:
        for f in frames:
            data.qpos[:] = f.qpos
            mj.mj_forward(model, data)
            aim(camera, f)
            renderer.update_scene(data, camera=camera)
            scene = renderer.scene
            scene.flags[mj.mjtRndFlag.mjRND_SHADOW] = shadows
            decorate(mj, scene, f, radius)
            images.append(renderer.render().copy())
    finally:
        renderer.close()
    return images


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
    check_model(model)
    require_type("view", view, (View, type(None)))
    frames = _as_frames(frames)
    _checked_times([f.time for f in frames])
    for f in frames:
        _check_qpos(model, f)
    seen = view if view is not None else fit_view(model, frames, width / height)
    backdrop = _wall_emission(model, np.array([0.0, -1.0, 0.0]))  # the wall behind y = 0

    def aim(camera: Any, frame: Frame) -> None:
        camera.lookat[:] = seen.lookat
        camera.distance, camera.azimuth, camera.elevation = (
            seen.distance, seen.azimuth, seen.elevation,
        )  # fmt: skip

    def decorate(mj: Any, scene: Any, frame: Frame, radius: float) -> None:
        _decorate(mj, scene, frame if markers else None, seen, radius, backdrop)

    return _render_each(model, frames, (width, height), seen.distance, aim, decorate, shadows)
