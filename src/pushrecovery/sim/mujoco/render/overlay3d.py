r"""The overlays of a 3-D picture: the CoM, capture point, CoP and support polygon as geoms.

A :class:`Frame3D` is one instant of a 3-D run (time, ``qpos`` and the overlay points, world
frame: x forward, y left, z up [m]). :func:`overlay_markers` returns its overlays as
:class:`Marker` (spheres and lines, no OpenGL needed), which
:func:`~pushrecovery.sim.mujoco.render.scene.humanoid.render_frames3d` adds to MuJoCo's scene as
decoration geoms:

* the **CoM** (red sphere), a thin red line down to its ground projection and a red sphere
  there;
* the **capture point** ξ = c_xy + ċ_xy/ω (blue sphere on the floor) and a thin blue line from
  the CoM's ground projection to it (ċ_xy/ω);
* the **CoP** (green sphere on the floor, smaller, drawn in front of the capture point's);
* the **support polygon**, the convex hull of the soles in contact (magenta outline on the
  floor).

**Markers in front of the body.** Each marker point p is drawn at
p' = e + (1 − :data:`PULL`)(p − e), e the camera's eye: on the same line of sight, so at p's
pixel (a segment between two pulled points projects onto the segment between the true
points' pixels), but nearer the camera than the body, which would hide the floor markers. The
sizes are scaled by (1 − PULL) so that they look as large as at p.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.mujoco.render.scene import CAPTURE_POINT_RGBA, COM_RGBA, COP_RGBA

FloatArray = NDArray[np.float64]

__all__ = ["LEGEND3D", "PULL", "SUPPORT_RGBA", "Frame3D", "Marker"]

#: Colour of the support polygon's outline.
SUPPORT_RGBA = (0.85, 0.1, 0.85, 1.0)
#: Legend entries of the 3-D pictures: label and RGBA colour.
LEGEND3D = (
    ("CoM", COM_RGBA),
    ("capture point", CAPTURE_POINT_RGBA),
    ("CoP", COP_RGBA),
    ("support polygon", SUPPORT_RGBA),
)
#: Fraction of the way from each marker point to the camera's eye it is drawn at [-].
PULL = 0.3
#: Lines' radius and the CoP's and the CoM's spheres' radii, as fractions of a marker's.
_LINE, _COP, _COM = 0.22, 0.6, 0.8


@dataclass(frozen=True, eq=False)
class Frame3D:
    """One recorded instant of a 3-D run (world frame, x forward, y left, z up).

    Attributes
    ----------
    time : float
        Simulation time [s].
    qpos : NDArray[np.float64]
        ``data.qpos`` (shape ``(model.nq,)``), in MuJoCo's units: [m] for slide and free-joint
        positions, [-] for the free joint's unit quaternion, [rad] for hinges.
    com : tuple[float, float, float]
        Whole-body CoM [m].
    capture_point : tuple[float, float]
        ξ = c_xy + ċ_xy/ω on the floor [m] (not drawn if not finite).
    cop : tuple[float, float]
        Centre of pressure on the floor [m]; NaN when no foot touches it (not drawn).
    support : tuple of (float, float)
        Vertices of the support polygon (convex hull of the soles in contact) [m], in order;
        empty when no foot touches the floor.
    floor : float
        Height of the floor [m].
    """

    time: float
    qpos: FloatArray
    com: tuple[float, float, float]
    capture_point: tuple[float, float]
    cop: tuple[float, float]
    support: tuple[tuple[float, float], ...] = ()
    floor: float = 0.0


@dataclass(frozen=True)
class Marker:
    """One overlay geom: a sphere (``points`` one point) or a line (two), pulled in front.

    Attributes
    ----------
    name : str
        What it shows (``com``, ``com ground``, ``com line``, ``capture point``,
        ``capture line``, ``cop``, ``support``).
    points : tuple of (float, float, float)
        Where it is drawn (already pulled towards the eye) [m].
    radius : float
        Sphere or line radius [m].
    rgba : tuple of 4 floats
        Colour.
    """

    name: str
    points: tuple[tuple[float, float, float], ...]
    radius: float
    rgba: tuple[float, float, float, float]


def overlay_markers(frame: Frame3D, eye: ArrayLike, radius: float) -> list[Marker]:
    """Return the overlay geoms of ``frame`` seen from ``eye`` (module docstring).

    Parameters
    ----------
    frame : Frame3D
        The instant.
    eye : sequence of 3 floats
        The camera's position [m].
    radius : float
        Marker radius at the markers' true places [m], > 0 (drawn (1 − PULL) times it).
    """
    radius = bounded_float("radius", radius, 1e-6, 10.0, "m")
    e = np.asarray(eye, dtype=float)
    if e.shape != (3,) or not np.all(np.isfinite(e)):
        raise InvalidParameterError("eye must be 3 finite coordinates [m]")
    scale = (1.0 - PULL) * radius
    z = frame.floor

    def pull(point: ArrayLike, extra: float = 0.0) -> tuple[float, float, float]:
        p = np.asarray(point, dtype=float)
        moved = e + (1.0 - PULL) * (p - e)
        if extra:
            moved += extra * (e - moved) / np.linalg.norm(e - moved)
        return (float(moved[0]), float(moved[1]), float(moved[2]))

    out: list[Marker] = []
    com = np.asarray(frame.com, dtype=float)
    ground = (com[0], com[1], z)
    if np.all(np.isfinite(com)):
        out += [
            Marker("com", (pull(com),), _COM * scale, COM_RGBA),
            Marker("com line", (pull(com), pull(ground)), _LINE * scale, COM_RGBA),
            Marker("com ground", (pull(ground),), scale, COM_RGBA),
        ]
    xi = np.asarray(frame.capture_point, dtype=float)
    if np.all(np.isfinite(xi)):
        point = (xi[0], xi[1], z)
        out.append(Marker("capture point", (pull(point),), scale, CAPTURE_POINT_RGBA))
        if np.all(np.isfinite(com)):
            out.append(Marker("capture line", (pull(ground), pull(point)), _LINE * scale,
                              CAPTURE_POINT_RGBA))  # fmt: skip
    cop = np.asarray(frame.cop, dtype=float)
    if np.all(np.isfinite(cop)):
        # Nearer the eye than the capture point's sphere: both show when they coincide.
        out.append(Marker("cop", (pull((cop[0], cop[1], z), 1.5 * scale),), _COP * scale,
                          COP_RGBA))  # fmt: skip
    corners = list(frame.support)
    for k, (a, b) in enumerate(zip(corners, corners[1:] + corners[:1], strict=True)):
        if len(corners) < 2 or (len(corners) == 2 and k == 1):
            break
        out.append(Marker("support", (pull((a[0], a[1], z)), pull((b[0], b[1], z))),
                          _LINE * scale, SUPPORT_RGBA))  # fmt: skip
    return out
