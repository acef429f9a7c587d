r"""Rendering a 3-D run from a tracking camera at any azimuth, with the balance overlays.

:func:`render_frames3d` replays :class:`~pushrecovery.sim.mujoco.render.overlay3d.Frame3D`
frames with ``mj_forward`` and draws each frame's overlays
(:func:`~pushrecovery.sim.mujoco.render.overlay3d.overlay_markers`: CoM, capture point, CoP,
support polygon) as MuJoCo decoration geoms, in front of a light backdrop wall.

**Camera** (:class:`Camera3D`). It stands at azimuth φ (0 in front of the body, +x; 90 on its
left, +y: the push's convention) and elevation θ above the horizon (positive looks down), at
one distance for the whole run, and looks at the CoM's ground point (x, y) of each frame at a
fixed height: it tracks the body. MuJoCo's free camera takes azimuth φ + 180° and elevation
−θ. :func:`fit_camera3d` picks the distance and the height so that the moving geoms' bounding
boxes (relative to the CoM's ground point, over the run) fit with a margin, by the pinhole
model: a point at (x, y) in the camera's right/up axes and at depth D + p·f (f the viewing
direction) is in the image when abs(x) <= (D + p·f) tan(fovx/2) and abs(y) <= (D + p·f)
tan(fovy/2).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.control.wbc.bodies import check_model
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.sim.mujoco.render.frames import _checked_times, select_indices
from pushrecovery.sim.mujoco.render.overlay3d import Frame3D, Marker, overlay_markers
from pushrecovery.sim.mujoco.render.scene import (
    BACKDROP_DISTANCE,
    BACKDROP_RGBA,
    _add_geom,
    _moving_boxes,
    _render_each,
    _wall_emission,
    check_aspect,
)

if TYPE_CHECKING:
    import mujoco

FloatArray = NDArray[np.float64]

__all__ = ["Camera3D", "View3D", "fit_camera3d", "render_frames3d"]

#: Margin around the body in the fitted view, as a fraction of its size.
_MARGIN = 0.12
_EXTENT_SAMPLES = 12


@dataclass(frozen=True)
class Camera3D:
    """Where the tracking camera stands (module docstring).

    Attributes
    ----------
    azimuth : float
        φ, the camera's direction from the body [deg] in [−360, 360]: 0 in front (+x), 90 on
        its left (+y), −90 on its right (the side view of the planar pictures).
    elevation : float
        θ, above the horizon [deg] in [−30, 89]: positive looks down.
    """

    azimuth: float = -90.0
    elevation: float = 20.0

    def __post_init__(self) -> None:
        bounded_float("azimuth", self.azimuth, -360.0, 360.0, "deg")
        bounded_float("elevation", self.elevation, -30.0, 89.0, "deg")


@dataclass(frozen=True)
class View3D:
    """A fitted tracking camera: :class:`Camera3D` with its distance and height [m]."""

    camera: Camera3D
    distance: float
    height: float


def _axes(camera: Camera3D) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return the viewing direction f (eye to target), right r and up u unit vectors."""
    phi, theta = math.radians(camera.azimuth), math.radians(camera.elevation)
    # From the target to the eye: (cos φ cos θ, sin φ cos θ, sin θ); f is its opposite.
    forward = -np.array([math.cos(phi) * math.cos(theta), math.sin(phi) * math.cos(theta),
                         math.sin(theta)])  # fmt: skip
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def camera_eye(view: View3D, target: ArrayLike) -> FloatArray:
    """Return the eye of ``view`` looking at ``target`` (x, y of the CoM, z ignored) [m]."""
    forward, _, _ = _axes(view.camera)
    point = np.asarray(target, dtype=float).reshape(-1)
    look = np.array([float(point[0]), float(point[1]), view.height])
    return look - view.distance * forward


def _check_frames(model: mujoco.MjModel, frames: Sequence[Frame3D]) -> None:
    check_model(model)
    if isinstance(frames, str | bytes) or not isinstance(frames, Sequence):
        raise ParameterTypeError(
            f"frames must be a sequence of Frame3D, got {type(frames).__name__}"
        )
    if len(frames) == 0:
        raise InvalidParameterError("frames must not be empty")
    for f in frames:
        if not isinstance(f, Frame3D):
            raise InvalidParameterError(f"frames must be Frame3D, got {type(f).__name__}")
        if np.shape(f.qpos) != (model.nq,):
            raise InvalidParameterError(
                f"frame qpos must have shape ({model.nq},), got {np.shape(f.qpos)}"
            )
    _checked_times([f.time for f in frames])


def _body_points(model: mujoco.MjModel, frames: Sequence[Frame3D]) -> FloatArray:
    """Corners of the moving geoms' boxes relative to each frame's CoM ground point, (n, 3)."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    points = []
    sampled = [frames[k] for k in select_indices([f.time for f in frames], _EXTENT_SAMPLES)]
    for f, rot, centre, size in _moving_boxes(model, sampled):
        corners = centre[:, None, :] + np.einsum(
            "gij,gkj->gki", rot, signs[None, :, :] * size[:, None, :]
        )
        offset = np.array([f.com[0], f.com[1], 0.0])
        points.append(corners.reshape(-1, 3) - offset)
        points.append(np.array([[0.0, 0.0, f.floor], [0.0, 0.0, f.com[2]]]))
    return np.concatenate(points) if points else np.zeros((1, 3))


def fit_camera3d(
    model: mujoco.MjModel, frames: Sequence[Frame3D], camera: Camera3D, aspect: float
) -> View3D:
    """Return the tracking view in which the body stays in frame (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with (its ``vis.global_.fovy``).
    frames : Sequence[Frame3D]
        The run (up to 12 frames evenly spaced in time are replayed).
    camera : Camera3D
        Azimuth and elevation.
    aspect : float
        Image width / height, in [1e-3, 1e3].
    """
    aspect = check_aspect(aspect)
    require_type("camera", camera, Camera3D)
    _check_frames(model, frames)
    points = _body_points(model, frames)
    points = points[np.all(np.isfinite(points), axis=1)]
    z_lo, z_hi = float(points[:, 2].min()), float(points[:, 2].max())
    height = 0.5 * (z_lo + z_hi)
    size = max(z_hi - z_lo, float(np.ptp(points[:, 0])), float(np.ptp(points[:, 1])), 0.2)
    forward, right, up = _axes(camera)
    rel = points - np.array([0.0, 0.0, height])
    tan_y = math.tan(math.radians(float(model.vis.global_.fovy)) / 2.0)
    tan_x = tan_y * aspect
    margin = _MARGIN * size
    need = (
        np.maximum((np.abs(rel @ right) + margin) / tan_x, (np.abs(rel @ up) + margin) / tan_y)
        - rel @ forward
    )
    return View3D(camera, distance=float(need.max()), height=height)


def _add_line(mj: Any, scene: Any, marker: Marker) -> None:
    if scene.ngeom >= scene.maxgeom:
        return
    a, b = (np.asarray(p, dtype=float) for p in marker.points)
    if float(np.linalg.norm(b - a)) < 1e-9:
        return
    geom = scene.geoms[scene.ngeom]
    _add_geom(mj, scene, mj.mjtGeom.mjGEOM_CAPSULE, (marker.radius, 0.0, 0.0), a,
              marker.rgba, 0.5)  # fmt: skip
    mj.mjv_connector(geom, mj.mjtGeom.mjGEOM_CAPSULE, marker.radius, a, b)


def _add_backdrop(mj: Any, scene: Any, view: View3D, look: FloatArray, emission: float) -> None:
    """Add a light wall facing the camera, ``BACKDROP_DISTANCE`` behind what it looks at."""
    if scene.ngeom >= scene.maxgeom:
        return
    forward, right, _ = _axes(view.camera)
    level = np.array([forward[0], forward[1], 0.0])
    level /= np.linalg.norm(level)
    far = 4.0 * view.distance
    rot = np.column_stack([right, [0.0, 0.0, 1.0], -level])  # the box's z: the wall's normal
    _add_geom(mj, scene, mj.mjtGeom.mjGEOM_BOX, (far, far, 0.01),
              look + BACKDROP_DISTANCE * level, BACKDROP_RGBA, emission)  # fmt: skip
    scene.geoms[scene.ngeom - 1].mat[:] = rot


def render_frames3d(
    model: mujoco.MjModel,
    frames: Sequence[Frame3D],
    *,
    width: int = 320,
    height: int = 240,
    camera: Camera3D | None = None,
    view: View3D | None = None,
    markers: bool = True,
    shadows: bool = False,
) -> list[NDArray[np.uint8]]:
    """Render each frame from the tracking camera, with the overlays (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with.
    frames : Sequence[Frame3D]
        The frames to render (all of them).
    width, height : int
        Image size [px], within the model's offscreen buffer.
    camera : Camera3D or None
        Azimuth and elevation (default :class:`Camera3D`); ignored when ``view`` is given.
    view : View3D or None
        A fitted view (default :func:`fit_camera3d` of ``frames``).
    markers : bool
        Draw the CoM, capture point, CoP and support polygon.
    shadows : bool
        Render shadows (off by default: slow with software OpenGL).

    Returns
    -------
    list[NDArray[np.uint8]]
        One ``(height, width, 3)`` RGB image per frame (errors as
        :func:`~pushrecovery.sim.mujoco.render.scene.render_frames`'s).
    """
    _check_frames(model, frames)
    require_type("camera", camera, (Camera3D, type(None)))
    require_type("view", view, (View3D, type(None)))
    seen = view or fit_camera3d(model, frames, camera or Camera3D(), width / max(height, 1))
    forward, _, _ = _axes(seen.camera)
    level = np.array([forward[0], forward[1], 0.0]) / math.hypot(forward[0], forward[1])
    backdrop = _wall_emission(model, -level)

    def aim(cam: Any, f: Frame3D) -> None:
        cam.lookat[:] = (f.com[0], f.com[1], seen.height)
        cam.distance = seen.distance
        cam.azimuth = seen.camera.azimuth + 180.0
        cam.elevation = -seen.camera.elevation

    def decorate(mj: Any, scene: Any, f: Frame3D, radius: float) -> None:
        scene.flags[mj.mjtRndFlag.mjRND_REFLECTION] = shadows  # with the shadows: both slow
        look = np.array([f.com[0], f.com[1], seen.height], dtype=float)
        _add_backdrop(mj, scene, seen, look, backdrop)
        for marker in overlay_markers(f, camera_eye(seen, f.com), radius) if markers else ():
            if len(marker.points) == 1:
                _add_geom(mj, scene, mj.mjtGeom.mjGEOM_SPHERE, (marker.radius, 0, 0),
                          np.array(marker.points[0]), marker.rgba, 0.5)  # fmt: skip
            else:
                _add_line(mj, scene, marker)

    return _render_each(model, frames, (width, height), seen.distance, aim, decorate, shadows)
