r"""Pictures of a pushed 3-D humanoid: frames of a recorded run, a filmstrip PNG and a GIF.

:func:`run_frames` turns a run recorded by
``run_push3d(plant, controller, push, record=True)`` into
:class:`~pushrecovery.sim.mujoco.render.scene.humanoid.Frame3D` (the overlays' points), replaying
each chosen row on a copy of the model (``qpos``, ``qvel`` and the held ``ctrl``, then
``mj_forward``; the run's own ``MjData`` is not touched):

* CoM c and its velocity ċ: the run's state (``plant.state_labels``); capture point
  ξ = c_xy + ċ_xy/ω with the plant's ω = sqrt(g/z₀) (z₀ its standing CoM height above the
  soles, as its fall set);
* CoP: measured from the floor's contact forces on the feet, p = Σ f_z,i p_i / Σ f_z,i over
  the foot–floor contacts (points p_i on the floor, normal forces f_z,i from
  ``mj_contactForce``: the floor's moment about a point of its own plane has no horizontal
  part from the tangential forces); NaN when no foot touches the floor;
* support polygon: the convex hull of the sole points (``measure.sole_points``) of the feet
  with a contact of normal force above :data:`CONTACT_FORCE`.

:func:`render_push3d` writes ``FILE.png`` (a filmstrip: panels at the given times or evenly
spaced, each labelled with its time) and ``FILE.gif`` (the run in real time), the tracking
camera of :mod:`~pushrecovery.sim.mujoco.render.scene.humanoid` at the chosen azimuth and elevation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, positive_float, require_type, sample_array
from pushrecovery.control.wbc.bodies import body_id, check_model, sole_points
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import convex_hull
from pushrecovery.sim.mujoco.humanoid3d.measure import subtree
from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant
from pushrecovery.sim.mujoco.humanoid3d.runs3d import pushed_rows
from pushrecovery.sim.mujoco.render.frames import (
    nearest_indices,
    select_indices,
    subsample_indices,
)
from pushrecovery.sim.mujoco.render.output import output_paths, write_animation, write_filmstrip
from pushrecovery.sim.mujoco.render.overlay3d import LEGEND3D, Frame3D
from pushrecovery.sim.mujoco.render.scene import check_size
from pushrecovery.sim.mujoco.render.scene.humanoid import Camera3D, fit_camera3d, render_frames3d
from pushrecovery.sim.result import SimulationResult

FloatArray = NDArray[np.float64]

__all__ = ["CONTACT_FORCE", "Recording3D", "default_camera", "render_recording3d", "run_frames"]

#: A foot supports the body when the floor pushes it with more than this [N].
CONTACT_FORCE = 1.0


def default_camera(azimuth: float, elevation: float = 25.0) -> Camera3D:
    """Return the camera that sees a push at ``azimuth`` [deg] go from left to right.

    It stands 90° clockwise of the push (φ = ψ − 90: on the body's right for a forward push,
    in front of it for a push to the left), ``elevation`` [deg] above the horizon.
    """
    psi = bounded_float("azimuth", azimuth, -360.0, 360.0, "deg")
    return Camera3D(azimuth=(psi - 90.0 + 180.0) % 360.0 - 180.0, elevation=elevation)


@dataclass(frozen=True, eq=False)
class Recording3D:
    """A recorded 3-D run with what it takes to replay it (one row per recorded tick).

    Build it with :meth:`of_plant_run` (``run_push3d(..., record=True)``).

    Attributes
    ----------
    model : mujoco.MjModel
        The model the run was simulated on.
    feet : tuple of str
        The foot bodies.
    omega : float
        ω = sqrt(g/z₀) of the capture point [1/s].
    floor : float
        Floor height [m].
    azimuth : float
        The push's azimuth [deg] (0 forward, 90 left): the default camera's reference.
    time : float array, shape (n,)
        [s], non-decreasing.
    qpos, qvel, ctrl : float arrays, shapes (n, nq), (n, nv), (n, nu)
        MuJoCo's state and the motor commands held at each row: ``qpos`` [m] for slide and
        free-joint positions, [-] for the free joint's unit quaternion, [rad] for hinges;
        ``qvel`` [m/s] and [rad/s] likewise; ``ctrl`` the motors' torques [N m] (gear 1).
    com, com_velocity : float arrays, shape (n, 3)
        Whole-body CoM [m] and its velocity [m/s].
    """

    model: Any
    feet: tuple[str, ...]
    omega: float
    floor: float
    azimuth: float
    time: FloatArray
    qpos: FloatArray
    qvel: FloatArray
    ctrl: FloatArray
    com: FloatArray
    com_velocity: FloatArray

    def __post_init__(self) -> None:
        check_model(self.model)
        model, n = self.model, sample_array("time", self.time).size
        shapes = {"qpos": (n, model.nq), "qvel": (n, model.nv), "ctrl": (n, model.nu),
                  "com": (n, 3), "com_velocity": (n, 3)}  # fmt: skip
        if n == 0:
            raise InvalidParameterError("the recording must hold at least one row")
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise InvalidParameterError(
                    f"{name} must have shape {shape}, got {np.shape(getattr(self, name))}"
                )
        positive_float("omega", self.omega, "1/s")

    @classmethod
    def of_plant_run(cls, plant: Humanoid3DPlant, run: SimulationResult) -> Recording3D:
        """Return the recording of ``run_push3d(plant, ..., record=True)``.

        Its rows are :func:`~.runs3d.pushed_rows`: the standing start, the state after the
        push and every tick after it.
        """
        require_type("plant", plant, Humanoid3DPlant)
        rows = pushed_rows(run)
        extras = run.extras
        assert extras is not None  # pushed_rows refuses a run without
        if extras.qpos is None or extras.qvel is None or extras.ctrl is None:
            raise InvalidParameterError(
                "run has no recorded states to render: run_push3d(..., record=True)"
            )
        states = run.states[rows]
        return cls(plant.model, tuple(plant.feet), plant.omega, plant.floor, extras.push.azimuth,
                   run.time[rows], extras.qpos[rows], extras.qvel[rows], extras.ctrl[rows],
                   states[:, :3], states[:, 3:6])  # fmt: skip


def _feet_geoms(model: Any, feet: Sequence[str]) -> list[set[int]]:
    """Return, per foot, the geoms of the foot body and the bodies below it."""
    out = []
    for foot in feet:
        bodies = set(subtree(model, body_id(model, foot)))
        out.append({g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in bodies})
    return out


def _contacts(model: Any, data: Any, feet: list[set[int]]) -> tuple[
    tuple[float, float], list[int]
]:  # fmt: skip
    """Return the CoP on the floor and the feet the floor pushes (module docstring)."""
    import mujoco

    force = np.zeros(6)
    moment, total = np.zeros(2), 0.0
    pushed = np.zeros(len(feet))
    for i in range(int(data.ncon)):
        contact = data.contact[i]
        pair = (int(contact.geom1), int(contact.geom2))
        for k, geoms in enumerate(feet):
            inside = [g in geoms for g in pair]
            if inside[0] == inside[1]:
                continue  # not a foot against something else
            other = pair[1] if inside[0] else pair[0]
            if int(model.geom_bodyid[other]) != 0:
                continue  # against another body, not the floor
            mujoco.mj_contactForce(model, data, i, force)
            frame = np.asarray(contact.frame, dtype=float).reshape(3, 3)
            # Force on geom2 from geom1, in the contact frame: turn it into the force on the foot.
            world = frame.T @ force[:3] * (1.0 if inside[1] else -1.0)
            fz = float(world[2])
            if fz <= 0.0:
                continue
            moment += fz * np.asarray(contact.pos[:2], dtype=float)
            total += fz
            pushed[k] += fz
    cop = (float(moment[0] / total), float(moment[1] / total)) if total > 0.0 else (math.nan,) * 2
    return (cop[0], cop[1]), [k for k in range(len(feet)) if pushed[k] > CONTACT_FORCE]


def _outline(points: FloatArray) -> tuple[tuple[float, float], ...]:
    """Return the convex hull's vertices; the farthest two points if it has no area."""
    try:
        vertices = convex_hull(points).vertices
    except InvalidParameterError:  # a foot on one edge: a segment
        gaps = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=-1)
        i, j = np.unravel_index(int(np.argmax(gaps)), gaps.shape)
        vertices = points[[i, j]]
    return tuple((float(x), float(y)) for x, y in vertices)


def run_frames(recording: Recording3D, rows: Sequence[int] | None = None) -> list[Frame3D]:
    """Return the frames of ``recording`` at ``rows`` (default all), module docstring.

    Parameters
    ----------
    recording : Recording3D
        The run.
    rows : sequence of int, optional
        Indices into ``recording.time``, increasing.

    Raises
    ------
    InvalidParameterError
        If a row is out of range or the rows are not increasing.
    """
    import mujoco

    require_type("recording", recording, Recording3D)
    rec = recording
    n = len(rec.time)
    chosen = list(range(n)) if rows is None else [int(r) for r in rows]
    if any(not 0 <= r < n for r in chosen) or np.any(np.diff(chosen) <= 0):
        raise InvalidParameterError(f"rows must be increasing indices in [0, {n - 1}]")
    model = rec.model
    data = mujoco.MjData(model)
    feet = _feet_geoms(model, rec.feet)
    foot_ids = [body_id(model, foot) for foot in rec.feet]
    frames = []
    for r in chosen:
        data.qpos[:], data.qvel[:], data.ctrl[:] = rec.qpos[r], rec.qvel[r], rec.ctrl[r]
        mujoco.mj_forward(model, data)
        cop, touching = _contacts(model, data, feet)
        support: tuple[tuple[float, float], ...] = ()
        if touching:
            soles = np.vstack([sole_points(model, data, foot_ids[k]) for k in touching])
            support = _outline(soles[:, :2])
        c, v = rec.com[r], rec.com_velocity[r]
        frames.append(
            Frame3D(
                time=float(rec.time[r]),
                qpos=np.array(rec.qpos[r], dtype=float),
                com=(float(c[0]), float(c[1]), float(c[2])),
                capture_point=(float(c[0] + v[0] / rec.omega), float(c[1] + v[1] / rec.omega)),
                cop=cop,
                support=support,
                floor=rec.floor,
            )
        )
    return frames


def filmstrip_rows(time: FloatArray, times: Sequence[float] | None, panels: int) -> list[int]:
    """Return the rows of ``time`` nearest the filmstrip's ``times`` [s] (or ``panels``).

    Without ``times``, ``panels`` times evenly spaced from the first row to the last.

    Raises
    ------
    InvalidParameterError
        If ``times`` holds no or more than 20 values, is not finite and increasing, or leaves
        the run's [first, last] time; or ``panels`` is not an integer in [1, 20].
    """
    time = np.asarray(time, dtype=float)
    if times is None:
        if isinstance(panels, bool) or not isinstance(panels, int) or not 1 <= panels <= 20:
            raise InvalidParameterError(f"panels must be an integer in [1, 20], got {panels!r}")
        return select_indices(time, panels)
    try:
        wanted = np.asarray(times, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidParameterError("times must be numbers [s]") from None
    first, last = float(time[0]), float(time[-1])
    if not 1 <= wanted.size <= 20:
        raise InvalidParameterError(f"times must hold 1 to 20 frame times, got {wanted.size}")
    if not np.all(np.isfinite(wanted)) or np.any(np.diff(wanted) <= 0.0):
        raise InvalidParameterError("times must be finite and increasing [s]")
    if wanted[0] < first - 1e-9 or wanted[-1] > last + 1e-9:
        raise InvalidParameterError(
            f"times must be within the run, [{first:.3f}, {last:.3f}] s, got "
            f"[{wanted[0]:g}, {wanted[-1]:g}] s"
        )
    return nearest_indices(time, wanted)


def render_recording3d(
    recording: Recording3D,
    path: Path | str,
    *,
    camera: Camera3D | None = None,
    times: Sequence[float] | None = None,
    panels: int = 6,
    panel_size: tuple[int, int] = (200, 250),
    fps: float = 25.0,
    size: tuple[int, int] = (360, 270),
    title: str | None = None,
    gif: bool = True,
) -> tuple[Path, Path | None]:
    """Write the filmstrip PNG and the GIF of a recorded 3-D run (module docstring).

    Parameters
    ----------
    recording : Recording3D
        The run (:meth:`Recording3D.of_plant_run`).
    path : Path
        ``FILE``, ``FILE.png`` or ``FILE.gif``: writes ``FILE.png`` and ``FILE.gif``.
    camera : Camera3D, optional
        Default :func:`default_camera` of the push's azimuth.
    times : sequence of float, optional
        The filmstrip's frame times [s] within the run (nearest recorded rows); default
        ``panels`` evenly spaced.
    panels : int
        Panels when ``times`` is None, in [1, 20].
    panel_size, size : (int, int)
        Filmstrip panel and GIF frame (width, height) [px], within the model's offscreen
        buffer.
    fps : float
        GIF frame rate [1/s], in (0, 50].
    title : str, optional
        The filmstrip's title line.
    gif : bool
        Write the GIF too.

    Returns
    -------
    (Path, Path or None)
        The PNG and the GIF (None when ``gif`` is False).

    Raises
    ------
    PushRecoveryError
        If offscreen OpenGL is unavailable (naming ``MUJOCO_GL``) or a file cannot be written;
        :class:`~pushrecovery.errors.InvalidParameterError` on bad arguments.
    """
    require_type("recording", recording, Recording3D)
    if not (isinstance(fps, int | float) and math.isfinite(fps) and 0.0 < fps <= 50.0):
        raise InvalidParameterError(f"fps must be in (0, 50] 1/s, got {fps!r}")
    panel_size, size = check_size("panel_size", panel_size), check_size("size", size)
    camera = default_camera(recording.azimuth) if camera is None else camera
    require_type("camera", camera, Camera3D)
    rows = filmstrip_rows(recording.time, times, panels)
    png, animation = output_paths(Path(path))
    movie = run_frames(recording, subsample_indices(recording.time, fps))
    strip = run_frames(recording, rows)
    model = recording.model
    view = fit_camera3d(model, movie, camera, panel_size[0] / panel_size[1])
    images = render_frames3d(model, strip, width=panel_size[0], height=panel_size[1], view=view)
    write_filmstrip(images, [f.time for f in strip], png, title=title, legend=LEGEND3D)
    if not gif:
        return png, None
    view = fit_camera3d(model, movie, camera, size[0] / size[1])
    images = render_frames3d(model, movie, width=size[0], height=size[1], view=view)
    write_animation(images, [f.time for f in movie], animation, legend=LEGEND3D)
    return png, animation
