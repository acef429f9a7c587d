"""A gait lab around a MuJoCo plant: markers and force plates sampled as a lab records them.

:class:`LabRecorder` is an observer of :func:`~pushrecovery.sim.simulate.simulate` (it reads
the plant's MuJoCo data after every physics step); :func:`~pushrecovery.experiments.mocap.
record_push` runs the push and returns the :class:`MocapRecording`.

Lab frame and conventions
-------------------------
The lab frame is MuJoCo's world frame: **x forward** (anterior-posterior, AP), **y left**
(medio-lateral, ML), **z up**, the floor (and the plates' top surfaces) at z = 0 [m].

Time base: sample 0 is the start of the recording, ``quiet`` seconds of standing at rest at
``x0`` (after the plant's own settle) with the controller running; the push starts at
``truth["push_time"]`` = ``quiet`` (rounded to the 1 ms physics step). Every analog sample is
the snapshot of one physics step: the contact forces and the kinematics (markers, CoM) that
MuJoCo's step computed at its start, i.e. at the same instant.

Markers (Vicon Plug-in Gait labels), each (n_points, 3) [m]:

- ``CentreOfMass``: the whole model's CoM (``data.subtree_com[0]``), y = 0.
- ``LHEE``, ``LTOE``, ``LANK`` and ``RHEE``, ``RTOE``, ``RANK`` per foot: the ankle marker at
  the ankle joint, the heel marker at ``ankle + heel`` and the toe marker at ``ankle + toe``
  along the foot's own x axis (they tilt with the foot), all ``MARKER_HEIGHT`` = 0.01 m above
  the sole (where the ankle hinge sits, ``ANKLE_HEIGHT``). Left feet at y = +0.1 m, right feet
  at y = −0.1 m (stance width ``2 STANCE_HALF_WIDTH`` = 0.2 m). The models are sagittal: for
  ``foot`` and ``torso`` the single model foot stands for both feet side by side (L and R
  markers coincide in x and z; the real contacts stay at abs(y) ≤ 0.05 m, the sole's half width,
  so the plates' CoP is at y = 0, between the feet); for ``biped`` L is the model's ``left``
  leg (drawn at y = +0.1 m, which stands first and is the stance leg of the first step) and R
  its ``right`` leg (y = −0.1 m, the first swing leg).

Force plates (:data:`PLATE_LENGTH` AP × :data:`PLATE_WIDTH` ML, top at z = 0), like a walkway:
plate 1 centred (AP) under the initial stance foot (the middle of [heel, toe] around the
initial ankle) and at y = 0, so that the whole foot (both, for the biped) is on it; plate 2
directly in front of it. With the preset's foot a forward step of 0.55–1.25 m (ankle to
ankle) lands wholly on plate 2, a shorter one across the two; a backward step lands off the
plates, and what the floor carries there is missing from both (counted by
``truth["off_plate_samples"]``). Per plate and analog sample:

- the **force on the subject** (the floor's force on the soles) [N], +z up: ≈ (m g, 0, 0)
  standing;
- the **CoP** on the plate surface, z = 0 [m], from the moments of the contact forces about
  the plate's centre, NaN while the vertical force is below :data:`UNLOADED_FORCE`;
- the **free moment** about z at the CoP [N m] (≈ 0 for these planar models), 0 while unloaded;
- the four **corners** (4, 3) [m], counter-clockwise seen from above starting at the front-left
  corner: (+AP, +ML), (−AP, +ML), (−AP, −ML), (+AP, −ML).

Every contact between the floor and a body geom (normally a sole; after a fall also the rest of
the body) is assigned to the plate whose area contains its point. A force push acts at the
pushed body's centre of mass (``plant.apply_push``), not through the floor: the plates see
it only through the dynamics, as a real plate would (Newton: J + ∫F_x dt = m Δv).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type, whole_number
from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import Step
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT
from pushrecovery.sim.mujoco.plant import MujocoPlant

__all__ = [
    "MARKER_HEIGHT",
    "MARKER_LABELS",
    "PLATE_LENGTH",
    "PLATE_WIDTH",
    "STANCE_HALF_WIDTH",
    "UNLOADED_FORCE",
    "LabRecorder",
    "MocapRecording",
    "PlateArea",
    "plate_areas",
]

FloatArray = NDArray[np.float64]
#: One plate's channels: force on the subject (n, 3) [N], CoP (n, 3) [m], free moment (n,)
#: [N m], corners (4, 3) [m].
Plate = tuple[FloatArray, FloatArray, FloatArray, FloatArray]

#: Half the distance between the left and right foot markers [m] (stance width 0.2 m).
STANCE_HALF_WIDTH = 0.1
#: Height of the heel and toe markers above the sole [m] (that of the ankle hinge).
MARKER_HEIGHT = 0.01
#: Plate size along x (AP) and along y (ML) [m].
PLATE_LENGTH = 0.9
PLATE_WIDTH = 0.6
#: Vertical force below which a plate counts as unloaded: CoP NaN, free moment 0 [N].
UNLOADED_FORCE = 20.0
#: Marker labels in the order of :attr:`MocapRecording.markers`.
MARKER_LABELS = ("CentreOfMass", "LHEE", "LTOE", "LANK", "RHEE", "RTOE", "RANK")

# Per model, per side: (label prefix, foot body, ankle joint, marker y [m]). The single foot of
# `foot` and `torso` carries both sides' markers.
_ONE_FOOT = (("L", "foot", "ankle", STANCE_HALF_WIDTH), ("R", "foot", "ankle", -STANCE_HALF_WIDTH))
_FEET: dict[str, tuple[tuple[str, str, str, float], ...]] = {
    "foot": _ONE_FOOT,
    "torso": _ONE_FOOT,
    "biped": (
        ("L", "left_foot", "left_ankle", STANCE_HALF_WIDTH),
        ("R", "right_foot", "right_ankle", -STANCE_HALF_WIDTH),
    ),
}


# eq=False: the fields are arrays, whose == is elementwise.
@dataclass(frozen=True, slots=True, eq=False)
class MocapRecording:
    """A push as a gait lab records it (module docstring for frames and conventions).

    Attributes
    ----------
    point_rate : float
        Marker rate [Hz].
    markers : dict of str to ndarray
        Label → (n_points, 3) lab positions [m], x forward (AP), y left (ML), z up
        (:data:`MARKER_LABELS`).
    analog_rate : float
        Force-plate rate [Hz], an integer multiple of ``point_rate``.
    plates : tuple
        Per plate: (force on the subject (n_analog, 3) [N], CoP (n_analog, 3) lab [m], NaN
        while unloaded (vertical force < :data:`UNLOADED_FORCE`), free moment about z at the
        CoP (n_analog,) [N m], corners (4, 3) lab [m]); n_analog = n_points · analog_rate /
        point_rate.
    mass : float
        Total mass of the model [kg] (the body plus the feet, legs and rod of the model).
    truth : dict
        What the simulation did and needed (:func:`record_push`).
    """

    point_rate: float
    markers: dict[str, FloatArray]
    analog_rate: float
    plates: tuple[Plate, ...]
    mass: float
    truth: dict[str, object]

    @property
    def point_time(self) -> FloatArray:
        """Time of each marker frame from the start of the recording [s]."""
        n = len(self.markers[MARKER_LABELS[0]])
        return np.arange(n, dtype=np.float64) / self.point_rate

    @property
    def analog_time(self) -> FloatArray:
        """Time of each force-plate sample from the start of the recording [s]."""
        n = len(self.plates[0][0]) if self.plates else 0
        return np.arange(n, dtype=np.float64) / self.analog_rate


@dataclass(frozen=True, slots=True)
class PlateArea:
    """A plate's centre on the floor and half sizes (x, y) [m]."""

    centre: FloatArray
    half: tuple[float, float]

    def corners(self) -> FloatArray:
        """Return the four corners (4, 3) [m], counter-clockwise from the front-left one."""
        cx, cy, _ = self.centre
        hx, hy = self.half
        return np.array(
            [[cx + hx, cy + hy, 0.0], [cx - hx, cy + hy, 0.0], [cx - hx, cy - hy, 0.0],
             [cx + hx, cy - hy, 0.0]]
        )  # fmt: skip


def plate_areas(first_centre_x: float) -> tuple[PlateArea, PlateArea]:
    """Return the walkway: plate 1 centred at ``first_centre_x`` [m], plate 2 in front of it."""
    first_centre_x = bounded_float("first_centre_x", first_centre_x, -1e3, 1e3, "m")
    half = (0.5 * PLATE_LENGTH, 0.5 * PLATE_WIDTH)
    return (
        PlateArea(np.array([first_centre_x, 0.0, 0.0]), half),
        PlateArea(np.array([first_centre_x + PLATE_LENGTH, 0.0, 0.0]), half),
    )


class LabRecorder:
    """Samples markers and plate loads after every physics step: an observer of the run.

    Parameters
    ----------
    plant : MujocoPlant
        The plant whose MuJoCo data is read.
    model_name : {"foot", "torso", "biped"}
        Which feet carry the markers.
    plates : tuple of PlateArea
        The plates on the floor.
    frames, per_frame, decimation : int
        Marker frames to record (at most 1e6), analog samples per frame and physics steps per
        analog sample (each at most 1000; frames × per_frame at most 1e7).
    """

    def __init__(
        self,
        plant: MujocoPlant,
        model_name: str,
        plates: tuple[PlateArea, ...],
        *,
        frames: int,
        per_frame: int,
        decimation: int,
    ) -> None:
        import mujoco

        require_type("plant", plant, MujocoPlant)
        if model_name not in _FEET:
            raise InvalidParameterError(
                f"model_name must be one of {sorted(_FEET)}, got {model_name!r:.40}"
            )
        if (
            not isinstance(plates, tuple | list)
            or not plates
            or not all(isinstance(p, PlateArea) for p in plates)
        ):
            raise ParameterTypeError("plates must be a non-empty tuple of PlateArea")
        frames = whole_number("frames", frames, 1, 10**6)
        per_frame = whole_number("per_frame", per_frame, 1, 1000)
        decimation = whole_number("decimation", decimation, 1, 1000)
        if frames * per_frame > 10**7:
            raise InvalidParameterError(
                f"frames * per_frame must be at most 1e7 analog samples, got {frames * per_frame}"
            )
        self._mj = mujoco
        self.model, self.data = plant.model, plant.data
        self.params: BodyParams = plant.params
        self.floor = self.model.geom("floor").id
        self.plates = plates
        self._lo = np.array([p.centre[:2] - p.half for p in plates])
        self._hi = np.array([p.centre[:2] + p.half for p in plates])
        self._centres = np.array([p.centre for p in plates])
        self._buffer = np.zeros(6)
        self.model_name = model_name
        try:
            self.feet = [
                (side, self.model.body(body).id, self.model.joint(joint).id, y)
                for side, body, joint, y in _FEET[model_name]
            ]
        except KeyError:
            raise InvalidParameterError(
                f"model_name {model_name!r} does not name the plant's model (its feet)"
            ) from None
        self.off_plate = 0
        self._plant = plant
        self.per_frame, self.decimation = per_frame, decimation
        analog = frames * per_frame
        #: Label -> (frames, 3) marker positions [m].
        self.marker_frames = {label: np.zeros((frames, 3)) for label in MARKER_LABELS}
        #: Per analog sample and plate: force on the subject [N], moment about the centre [N m].
        self.forces = np.zeros((analog, len(plates), 3))
        self.moments = np.zeros((analog, len(plates), 3))
        #: Per analog sample and foot (:attr:`feet`' order): the floor's vertical force on the
        #: foot's body [N], on the plates or off them (the feet of ``foot`` and ``torso`` are
        #: one body: both columns carry its whole load).
        self.foot_load = np.zeros((analog, len(self.feet)))
        self._foot_bodies = np.array([body for _, body, _, _ in self.feet])
        #: Per analog sample: the hip torque held [N m] and the plant's own CoP (world x) [m].
        self.hip_torque = np.zeros(analog)
        self.plant_cop = np.zeros(analog)

    def on_step(self, index: int, step: Step, command: Command) -> None:
        """Record analog sample (and marker frame) of physics step ``index``, if one is due."""
        if index % self.decimation:
            return
        a = index // self.decimation
        if a >= len(self.hip_torque):
            return  # the run goes on past the recording (to the end of its last tick)
        self.loads(self.forces[a], self.moments[a], self.foot_load[a])
        self.hip_torque[a] = step.applied[1]
        self.plant_cop[a] = self._plant.measured_cop_world()
        if a % self.per_frame == 0:
            self.markers(self.marker_frames, a // self.per_frame)

    def markers(self, out: dict[str, FloatArray], i: int) -> None:
        """Write marker frame ``i`` from the current kinematics."""
        d, p = self.data, self.params
        out["CentreOfMass"][i] = d.subtree_com[0]
        out["CentreOfMass"][i, 1] = 0.0
        lift = MARKER_HEIGHT - ANKLE_HEIGHT  # 0: the ankle hinge sits at the marker height
        for side, body, joint, y in self.feet:
            rot = d.xmat[body].reshape(3, 3)
            axis, up = rot[:, 0], rot[:, 2]  # the foot's own x (toe-ward) and z axes
            ankle = d.xanchor[joint] + lift * up
            for label, along in (("HEE", p.heel), ("TOE", p.toe)):
                marker = out[side + label][i]
                marker[:] = ankle + along * axis
                marker[1] = y
            out[side + "ANK"][i] = d.xanchor[joint]
            out[side + "ANK"][i, 1] = y

    def loads(self, force: FloatArray, moment: FloatArray, feet: FloatArray) -> None:
        """Write each plate's force on the subject [N] and moment about its centre [N m].

        ``feet``: each foot body's vertical load from the floor [N] (``foot_load``'s row).
        """
        force[:] = 0.0
        moment[:] = 0.0
        feet[:] = 0.0
        d, floor = self.data, self.floor
        ncon = d.ncon
        if ncon == 0:
            return
        geoms = d.contact.geom[:ncon]
        # The contact frame's normal points from geom1 to geom2 and mj_contactForce gives the
        # force geom1 exerts on geom2 (positive normal: pushing apart), so the floor's force on
        # the subject is +frame^T f when the floor is geom1 (always, for a plane) else −.
        # Checked: F_z = +m g standing, and from rest to rest ∫F_x dt = −J of a push.
        sign = np.where(geoms[:, 0] == floor, 1.0, np.where(geoms[:, 1] == floor, -1.0, 0.0))
        wrench = np.zeros((ncon, 6))
        for k in np.flatnonzero(sign).tolist():
            self._mj.mj_contactForce(self.model, d, k, self._buffer)
            wrench[k] = self._buffer
        frames = d.contact.frame[:ncon].reshape(ncon, 3, 3)
        f = sign[:, None] * np.einsum("kji,kj->ki", frames, wrench[:, :3])  # frame^T f
        tau = sign[:, None] * np.einsum("kji,kj->ki", frames, wrench[:, 3:])
        bodies = self.model.geom_bodyid[np.where(sign > 0.0, geoms[:, 1], geoms[:, 0])]
        for i, body in enumerate(self._foot_bodies):
            feet[i] = f[(bodies == body) & (sign != 0.0), 2].sum()
        pos = d.contact.pos[:ncon]
        inside = np.all((pos[:, None, :2] >= self._lo) & (pos[:, None, :2] < self._hi), axis=2)
        loaded = sign != 0.0
        for j in range(len(self.plates)):
            mine = inside[:, j] & loaded
            loaded &= ~inside[:, j]  # a contact on a shared edge counts for the first plate
            if not mine.any():
                continue
            r = pos[mine] - self._centres[j]
            force[j] = f[mine].sum(axis=0)
            moment[j] = np.cross(r, f[mine]).sum(axis=0) + tau[mine].sum(axis=0)
        if loaded.any() and np.abs(f[loaded, 2]).sum() > 0.0:
            self.off_plate += 1


def plate_channels(
    area: PlateArea, force: FloatArray, moment: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """CoP on the surface z = 0 and free moment from the force and moment about the centre.

    With the force F applied at the CoP c (on the surface) plus a free moment T about z:
    M = (c − O) × F + T ẑ, so c_x − O_x = −M_y / F_z, c_y − O_y = M_x / F_z and
    T = M_z − (c_x − O_x) F_y + (c_y − O_y) F_x.
    """
    fz = force[:, 2]
    loaded = fz >= UNLOADED_FORCE
    safe = np.where(loaded, fz, 1.0)
    dx = np.where(loaded, -moment[:, 1] / safe, np.nan)
    dy = np.where(loaded, moment[:, 0] / safe, np.nan)
    cop = np.column_stack([area.centre[0] + dx, area.centre[1] + dy, np.where(loaded, 0.0, np.nan)])
    free = np.where(loaded, moment[:, 2] - dx * force[:, 1] + dy * force[:, 0], 0.0)
    return force, cop, free, area.corners()
