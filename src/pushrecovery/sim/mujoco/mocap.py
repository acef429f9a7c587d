"""A MuJoCo push recorded as a gait lab would measure it: markers and force plates, with truth.

:func:`record_push` runs one push on a MuJoCo plant (``foot``, ``torso`` or ``biped``) with its
controller and samples what motion capture and force plates would give, so that an analysis of
measured data (C3D files) can be tested against what the simulation really did
(:attr:`MocapRecording.truth`).

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
  markers coincide in x and z; the real contacts stay at |y| ≤ 0.05 m, the sole's half width,
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
pushed body's centre of mass (``plant.schedule_push``), not through the floor: the plates see
it only through the dynamics, as a real plate would (Newton: J + ∫F_x dt = m Δv).

Closed loop
-----------
The controller runs from the start of the quiet standing. During a force push the body holds
still as in ``plant.push`` (CoP under the CoM, no hip torque; a human's reaction takes longer
than the 10 ms push) and as the push ends the controller restarts on the pushed state: the
response is then the one of ``pushed_state(..., force=True)`` + ``simulate()`` in the
campaigns and the validation (``react_during_push=True`` keeps the controller running
instead). The plant advances in single 1 ms physics steps (``plant.step(state, command,
1 ms)``); the controller computes a command at its own period, held in between (zero-order
hold), and the fall and rest criteria are checked at every control tick as
:func:`~pushrecovery.sim.simulate.simulate` does, from the end of the push. The one
difference to ``simulate``: the ``foot`` and ``torso`` plants refresh their torque map at every
call of ``step``, so every 1 ms here instead of every ``TORQUE_HOLD`` = 10 ms with the MPC's
20 ms ticks (docs/validation.md: < 0.1 % on critical pushes); ``foot`` with ``ankle-pd``
(1 ms ticks) and ``biped`` (1 ms servos) are unchanged.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command, make_controller
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, TIMESTEP
from pushrecovery.sim.mujoco.plant import PUSH_DURATION, MujocoPlant
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import RestCriterion, check_run
from pushrecovery.sim.validation import SETUPS
from pushrecovery.surfaces.classify import classify

__all__ = [
    "DEFAULT_CONTROLLERS",
    "FALL_TAIL",
    "HIP_TORQUE_THRESHOLD",
    "MARKER_HEIGHT",
    "MARKER_LABELS",
    "PLATE_LENGTH",
    "PLATE_WIDTH",
    "STANCE_HALF_WIDTH",
    "UNLOADED_FORCE",
    "MocapRecording",
    "record_push",
]

FloatArray = NDArray[np.float64]
#: One plate's channels: force on the subject (n, 3) [N], CoP (n, 3) [m], free moment (n,)
#: [N m], corners (4, 3) [m].
Plate = tuple[FloatArray, FloatArray, FloatArray, FloatArray]

#: Controller of each model by default: the one the validation and the campaigns use for it.
DEFAULT_CONTROLLERS: dict[str, str] = {
    model: controller for model, controller in SETUPS["mujoco"].values()
}
#: Half the distance between the left and right foot markers [m] (stance width 0.2 m).
STANCE_HALF_WIDTH = 0.1
#: Height of the heel and toe markers above the sole [m] (that of the ankle hinge).
MARKER_HEIGHT = 0.01
#: Plate size along x (AP) and along y (ML) [m].
PLATE_LENGTH = 0.9
PLATE_WIDTH = 0.6
#: Vertical force below which a plate counts as unloaded: CoP NaN, free moment 0 [N].
UNLOADED_FORCE = 20.0
#: Largest |hip torque| [N m] that still counts as not using the hip strategy.
HIP_TORQUE_THRESHOLD = 1.0
#: Time recorded after a fall is detected [s]; a fallen model is no lab data.
FALL_TAIL = 0.1
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
class _PlateArea:
    """A plate's centre on the floor and half sizes (x, y) [m]."""

    centre: FloatArray
    half: tuple[float, float]

    def corners(self) -> FloatArray:
        cx, cy, _ = self.centre
        hx, hy = self.half
        return np.array(
            [[cx + hx, cy + hy, 0.0], [cx - hx, cy + hy, 0.0], [cx - hx, cy - hy, 0.0],
             [cx + hx, cy - hy, 0.0]]
        )  # fmt: skip


def _plate_areas(first_centre_x: float) -> tuple[_PlateArea, _PlateArea]:
    half = (0.5 * PLATE_LENGTH, 0.5 * PLATE_WIDTH)
    return (
        _PlateArea(np.array([first_centre_x, 0.0, 0.0]), half),
        _PlateArea(np.array([first_centre_x + PLATE_LENGTH, 0.0, 0.0]), half),
    )


class _Lab:
    """Reads one sample of markers and plate loads from the plant's MuJoCo data."""

    def __init__(self, plant: MujocoPlant, model_name: str, plates: tuple[_PlateArea, ...]) -> None:
        import mujoco

        self._mj = mujoco
        self.model, self.data = plant.model, plant.data
        self.params: BodyParams = plant.params
        self.floor = self.model.geom("floor").id
        self.plates = plates
        self._lo = np.array([p.centre[:2] - p.half for p in plates])
        self._hi = np.array([p.centre[:2] + p.half for p in plates])
        self._centres = np.array([p.centre for p in plates])
        self._buffer = np.zeros(6)
        self.feet = [
            (side, self.model.body(body).id, self.model.joint(joint).id, y)
            for side, body, joint, y in _FEET[model_name]
        ]
        self.off_plate = 0

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

    def loads(self, force: FloatArray, moment: FloatArray) -> None:
        """Write each plate's force on the subject [N] and moment about its centre [N m]."""
        force[:] = 0.0
        moment[:] = 0.0
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


def _plate_channels(
    area: _PlateArea, force: FloatArray, moment: FloatArray
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


def _rate_ratio(message: str, numerator: float, denominator: float) -> int:
    """Return numerator / denominator if it is a whole number >= 1, else raise ``message``."""
    ratio = numerator / denominator
    whole = round(ratio)
    if whole < 1 or abs(ratio - whole) > 1e-9 * max(1.0, ratio):
        raise InvalidParameterError(message)
    return whole


def record_push(
    model: str,
    params: BodyParams,
    *,
    x0: float = 0.0,
    xdot: float | None = None,
    impulse: float | None = None,
    controller: str | None = None,
    duration: float = 3.0,
    point_rate: float = 100.0,
    analog_rate: float = 1000.0,
    quiet: float = 0.5,
    react_during_push: bool = False,
) -> MocapRecording:
    """Simulate a push on a MuJoCo model and record it as markers and force plates.

    The body settles, stands at rest at ``x0`` for ``quiet`` seconds with the controller
    running, is pushed, and the response is recorded until ``duration`` (or ``FALL_TAIL``
    after a fall). Frames and conventions: module docstring.

    Parameters
    ----------
    model : {"foot", "torso", "biped"}
        MuJoCo model (:data:`pushrecovery.sim.mujoco.PLANTS`).
    params : BodyParams
        The body.
    x0 : float
        CoM position relative to the stance ankle while standing, before the push [m].
    xdot : float, optional
        Push as a velocity jump: the CoM velocity set instantly at the push time [m/s],
        positive forward. The plates see no push, only the response.
    impulse : float, optional
        Push as a real force at the pushed body's CoM, J [N s] (positive forward) over
        ``PUSH_DURATION`` = 10 ms. At most one of ``xdot`` and ``impulse``; neither records
        standing without a push.
    controller : str, optional
        Controller name; default :data:`DEFAULT_CONTROLLERS` (``ankle-pd`` for ``foot``,
        ``mpc`` for ``torso``, ``recovery`` for ``biped``).
    duration : float
        Length of the whole recording, quiet standing included [s], > ``quiet``.
    point_rate : float
        Marker rate [Hz].
    analog_rate : float
        Force-plate rate [Hz]: 1000 (every physics step) or 1000 / n, an integer multiple of
        ``point_rate``. Samples are instantaneous (no anti-alias filter).
    quiet : float
        Quiet standing recorded before the push [s], >= 0.
    react_during_push : bool
        False (default): the body holds still during a force push (CoP under the CoM, no hip
        torque, no step) and the controller restarts on the pushed state as the push ends,
        as ``plant.push`` and the campaigns do, so that the response is the one the surfaces
        predict for ``truth["state_after_push"]``. True: the controller keeps running during
        the push (``schedule_push`` before ``simulate``); the ``recovery`` controller then
        plans its step 5-8 ms into the push on a part of the velocity (0.74 m instead of
        0.82 m for 1.3 m/s from x0 = 0).

    Returns
    -------
    MocapRecording
        With ``truth``: ``model``, ``controller``, ``outcome`` (``recovered``, ``fell`` or
        ``undecided``, by the simulator's criteria), ``decided_time`` [s] (NaN: undecided),
        ``push_time`` [s], ``push`` (``kind`` ``force``/``velocity``/``none``, ``impulse``
        [N s], ``velocity`` [m/s], ``duration`` [s], ``body``), ``push_force`` (n_analog,) [N]
        (x force on the pushed body), ``state_after_push`` ``{"x", "xdot"}`` (CoM relative to
        the stance ankle as the plant estimates it when the push ends [m, m/s]),
        ``predicted`` (:func:`~pushrecovery.surfaces.classify.classify` of that state,
        ``to_dict()``), ``used`` (``ankle``, ``hip`` or ``step``, the strategy the run used
        whatever its outcome: ``step`` if the biped stepped, ``hip`` if |hip torque| exceeded
        :data:`HIP_TORQUE_THRESHOLD`), ``peak_hip_torque`` [N m], ``hip_torque`` (n_analog,)
        [N m], ``plant_cop`` (n_analog,) (the plant's own ``measured_cop_world()``, world x
        of the CoP of the soles' normal forces on all plates and off them [m]), ``steps``,
        ``step_lengths`` (foot to foot [m], signed), ``footholds`` (world x of every stance
        ankle [m]), ``stance_width`` [m], ``off_plate_samples`` (analog samples with floor
        contacts outside both plates) and ``params`` (the body, as a dict).

    Raises
    ------
    InvalidParameterError
        For an unknown model or controller, both pushes, rates that do not fit the 1 ms step,
        or a duration not longer than ``quiet``.
    """
    import mujoco

    from pushrecovery.sim.mujoco import PLANTS

    if model not in PLANTS:
        raise InvalidParameterError(f"model must be one of {sorted(PLANTS)}, got {model!r}")
    if xdot is not None and impulse is not None:
        raise InvalidParameterError("give a push as xdot or as impulse, not both")
    for name, value in (("x0", x0), ("xdot", xdot), ("impulse", impulse)):
        if value is not None and not math.isfinite(value):
            raise InvalidParameterError(f"{name} must be finite, got {value!r}")
    if not (point_rate > 0.0 and analog_rate > 0.0):
        raise InvalidParameterError(
            f"rates must be > 0, got point_rate={point_rate:g}, analog_rate={analog_rate:g}"
        )
    h = TIMESTEP
    decimation = _rate_ratio(
        f"analog_rate must be 1/{h:g} s = {1 / h:g} Hz divided by a whole number, "
        f"got {analog_rate:g}",
        1.0 / analog_rate,
        h,
    )
    per_frame = _rate_ratio(
        f"analog_rate must be a whole multiple of point_rate, got {analog_rate:g} and "
        f"{point_rate:g}",
        analog_rate,
        point_rate,
    )
    if not (math.isfinite(quiet) and quiet >= 0.0):
        raise InvalidParameterError(f"quiet must be >= 0 s, got {quiet!r}")
    if not (math.isfinite(duration) and duration > quiet):
        raise InvalidParameterError(f"duration must exceed quiet = {quiet:g} s, got {duration!r}")
    n_frames = max(1, round(duration * point_rate))
    n_analog = n_frames * per_frame
    total_steps = n_analog * decimation
    push_step = round(quiet / h)
    if push_step >= total_steps:
        raise InvalidParameterError("duration leaves no time after the push")

    name = controller or DEFAULT_CONTROLLERS[model]
    plant: MujocoPlant = PLANTS[model](params)
    ctrl = make_controller(name, params)
    state = plant.reset(x0, 0.0)
    # The controller's own period (else 1 ms), checked against the model as simulate() does.
    state, period, _ = check_run(plant, ctrl, state, duration)
    rest = RestCriterion()
    rest_ticks = max(1, math.ceil(rest.duration / period - 1e-9))

    # The initial stance foot: the first ankle (both feet side by side for the biped).
    first_ankle = float(plant.ankle_x())
    footholds = plant.info().footholds
    lab = _Lab(plant, model, _plate_areas(first_ankle + 0.5 * (params.heel + params.toe)))
    n_plates = len(lab.plates)
    markers = {label: np.zeros((n_frames, 3)) for label in MARKER_LABELS}
    forces = np.zeros((n_analog, n_plates, 3))
    moments = np.zeros((n_analog, n_plates, 3))
    push_force = np.zeros(n_analog)
    hip_torque = np.zeros(n_analog)
    plant_cop = np.zeros(n_analog)

    push_steps = round(PUSH_DURATION / h) if impulse is not None else 0
    push_size = impulse / (push_steps * h) if impulse is not None else 0.0
    kind = "force" if impulse is not None else "velocity" if xdot is not None else "none"
    push_end = push_step + push_steps
    after: tuple[float, float] | None = None
    vel = len(state) // 2

    ctrl.reset(state)
    command = Command(float(state[0]))
    outcome, decided, at_rest = Outcome.UNDECIDED, math.nan, 0
    tick, next_tick, origin = 0, 0, 0  # control ticks since the (re)start at step `origin`
    peak, end = 0.0, total_steps
    s = 0
    while s < end:
        if s == push_step:
            if impulse is not None:
                plant.schedule_push(impulse)
            elif xdot is not None:
                plant.pose(float(state[0]), xdot)
                mujoco.mj_forward(plant.model, plant.data)
                state = plant.read_state()
        if s == push_end and after is None:
            after = (float(state[0]), float(state[vel]))
            if not react_during_push:
                # As pushed_state() + simulate(): the controller starts on the pushed state.
                ctrl.reset(state)
                tick, next_tick, origin = 0, s, s
        if push_step <= s < push_end and not react_during_push:
            # The body holds still during the push, as plant.push(): CoP under the CoM.
            command = Command(float(state[0]))
        elif s >= next_tick:
            if tick and outcome is Outcome.UNDECIDED:
                # The criteria of simulate(), on the state at the end of the last tick.
                if plant.falling(state):
                    outcome, decided = Outcome.FELL, s * h
                    end = min(end, s + round(FALL_TAIL / h))
                elif s > push_end:
                    x, v = float(state[0]), float(state[vel])
                    resting = (
                        abs(v) <= rest.speed
                        and params.heel < x < params.toe
                        and not command.saturated
                    )
                    at_rest = at_rest + 1 if resting else 0
                    if at_rest >= rest_ticks:
                        outcome, decided = Outcome.RECOVERED, s * h
            command = ctrl.compute(tick * period, state)
            tick += 1
            # Whole physics steps per tick, rounded per tick as the plants do.
            next_tick = origin + round(tick * period / h)
        try:
            step = plant.step(command, h)
        except PushRecoveryError:
            if outcome is not Outcome.FELL:
                raise
            end = s  # a fallen model blew up: the recording ends here
            break
        state, torque, footholds = step.state, float(step.applied[1]), step.info.footholds
        peak = max(peak, abs(torque))
        if s % decimation == 0:
            a = s // decimation
            lab.loads(forces[a], moments[a])
            hip_torque[a] = torque
            plant_cop[a] = plant.measured_cop_world()
            push_force[a] = push_size if push_step <= s < push_end else 0.0
            if a % per_frame == 0:
                lab.markers(markers, a // per_frame)
        s += 1
    if after is None:  # the push ended with the recording
        after = (float(state[0]), float(state[vel]))

    # Whole marker frames only (C3D: a fixed number of analog samples per frame).
    frames = max(1, min(n_frames, end // (decimation * per_frame)))
    n_kept = frames * per_frame
    plates = tuple(
        _plate_channels(area, forces[:n_kept, j].copy(), moments[:n_kept, j])
        for j, area in enumerate(lab.plates)
    )
    steps = len(footholds) - 1
    used = "step" if steps else "hip" if peak > HIP_TORQUE_THRESHOLD else "ankle"
    truth: dict[str, object] = {
        "model": model,
        "controller": name,
        "outcome": outcome.value,
        "decided_time": decided,
        "push_time": push_step * h,
        "push": {
            "kind": kind,
            "impulse": impulse if impulse is not None else params.mass * (xdot or 0.0),
            "velocity": xdot if xdot is not None else (impulse or 0.0) / params.mass,
            "duration": push_steps * h,
            "body": plant.pushed_body,
        },
        "push_force": push_force[:n_kept],
        "state_after_push": {"x": after[0], "xdot": after[1]},
        "predicted": classify(after[0], after[1], params).to_dict(),
        "used": used,
        "peak_hip_torque": peak,
        "hip_torque": hip_torque[:n_kept],
        "plant_cop": plant_cop[:n_kept],
        "steps": steps,
        "step_lengths": [b - a for a, b in itertools.pairwise(footholds)],
        "footholds": list(footholds),
        "stance_width": 2.0 * STANCE_HALF_WIDTH,
        "off_plate_samples": lab.off_plate,
        "params": dataclasses.asdict(params),
    }
    return MocapRecording(
        point_rate=float(point_rate),
        markers={label: m[:frames] for label, m in markers.items()},
        analog_rate=float(analog_rate),
        plates=plates,
        mass=float(plant.model.body_subtreemass[0]),
        truth=truth,
    )
