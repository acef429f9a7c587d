r"""Stepping on the ground plane: the planar LIPM with two flywheels and feet that land.

The model of the N-step analysis (:mod:`pushrecovery.surfaces.n_step`, docs/steps.md; Koolen
et al. 2012's 3-D LIPM with a finite foot and a reaction mass), simulated:

- **State** ``[x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r]`` in the world frame (x forward, y left), as
  :mod:`pushrecovery.models.flywheel.plane`; the feet are the plant's, in :attr:`support`.
- **Start**: every run (``begin``, ``reset``) starts on :attr:`start_support`: both feet at
  their default poses unless the user gives a stance and poses (``support=``, e.g. a robot on
  one foot). Each step's :class:`~pushrecovery.control.base.StepInfo` reports the feet
  (``feet``: the :class:`~pushrecovery.ground.support.Support`, stance and poses), which a
  controller reads in ``observe``.
- **Stance**: Eq. (3) in x and y with the hip torques (the planar Eq. 16), advanced exactly
  (zero-order hold, :func:`~pushrecovery.models.flywheel.plane.plane_discrete`) with the
  commanded CoP moved to the nearest point of the support polygon and the torques clipped to
  ±τmax of each axis (physics, not politeness). A hip joint past its limit stops at it and the
  stopping impulse reacts on the CoM, as in :class:`~pushrecovery.sim.plants.FlywheelPlant`.
- **A step** (a command with ``foothold``): the free foot lifts at once (from double support
  the command's ``swing`` foot), leaving the other foot as the support, and lands at the
  commanded touchdown time, but no sooner than ``min_step_time`` after the lift, with its ankle
  at the foothold moved to the nearest point within reach of the stance ankle
  (:func:`~pushrecovery.surfaces.n_step.reach_polygon`) and the stance foot's yaw. At the
  touchdown the stance foot lifts (the model of the analysis: one foot carries the body from
  touchdown to touchdown), so the landed foot alone is the new support. The LIPM keeps its
  height: no impact (docs/steps.md, "What Sec. IV's single step gets wrong, and what this
  fixes", for what Sec. IV's impact would take).
- **Fall**: the CoM farther than ``max_step_length`` from the support polygon and moving away:
  no foot can land under it any more within a step's reach.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.base import Command, StepInfo
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.models.flywheel.plane import PLANE_STATE_LABELS, plane_discrete
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import PlantBase, check_com_state
from pushrecovery.surfaces.n_step import reach_polygon

__all__ = ["PlaneSteppingPlant"]

FloatArray = NDArray[np.float64]


class PlaneSteppingPlant(PlantBase):
    """The planar LIPM + flywheels with stepping feet (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        The stance and foot poses every run starts on (:attr:`start_support`); default both
        feet at their default poses (:meth:`Support.from_params`).

    Attributes
    ----------
    support : Support
        The feet on the ground now (:attr:`start_support` at the start of a run).
    footholds : list of float
        World x of the stance reference at the start and of every landed ankle [m].
    footholds_xy : list of tuple
        The same points in (x, y) [m].
    """

    name: ClassVar[str] = "stepping-plane"
    state_labels: ClassVar[tuple[str, ...]] = PLANE_STATE_LABELS
    #: Applied inputs per tick: CoP x, y [m], pitch and roll torques [N m].
    input_labels: ClassVar[tuple[str, ...]] = ("cop_x", "cop_y", "pitch_torque", "roll_torque")

    def __init__(self, params: BodyParams, support: Support | None = None) -> None:
        super().__init__(params)
        self.start_support = Support.from_params(params) if support is None else support
        self.fall_limits = (params.heel, params.toe)  # along x from the start: reporting only
        self._limits = (
            (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max),
            (params.torque_max_roll, params.flywheel_inertia_roll, params.flywheel_angle_max_roll),
        )
        self._matrices: dict[tuple[float, float], tuple[FloatArray, FloatArray]] = {}
        self._restart_records()

    @property
    def start_support(self) -> Support:
        """The stance and foot poses every run starts on (world frame [m], yaw [rad]).

        Set it (or pass ``support`` to the constructor or :meth:`reset`) to start on one foot
        or on feet placed elsewhere; the soles are this body's (``params``) at the given
        stance and poses.

        Raises
        ------
        ParameterTypeError
            If the value set is not a :class:`~pushrecovery.ground.support.Support`.
        InvalidParameterError
            If its feet overlap or stand farther apart than two legs in double support.
        """
        return self._start_support

    @start_support.setter
    def start_support(self, support: Support) -> None:
        require_type("support", support, Support)
        self._start_support = Support.from_params(
            self.params, support.stance, left=support.left, right=support.right
        )

    def _restart_records(self) -> None:
        self.stop_impacts = 0
        self.support = self._start_support
        self.time = 0.0
        self._swing: tuple[Stance, tuple[float, float], float] | None = None
        ankle = self.support.ankle
        self.footholds: list[float] = [ankle[0]]
        self.footholds_xy: list[tuple[float, float]] = [ankle]

    def _start(self, x: float, xdot: float) -> FloatArray:
        return np.array([x, 0.0, 0.0, 0.0, xdot, 0.0, 0.0, 0.0])

    def reset(
        self,
        x: float,
        xdot: float,
        y: float = 0.0,
        ydot: float = 0.0,
        *,
        support: Support | None = None,
    ) -> FloatArray:
        """Start with the CoM at (x, y) [m] moving at (ẋ, ẏ) [m/s] (contract item 2).

        On :attr:`start_support` (both feet by default); a ``support`` given becomes it.
        """
        if support is not None:
            self.start_support = support
        return self.begin(np.array([x, y, 0.0, 0.0, xdot, ydot, 0.0, 0.0]))

    def _in_stance(self) -> bool:
        """Stance unless a foot swings toward its landing."""
        return self._swing is None

    def info(self) -> StepInfo:
        """:meth:`PlantBase.info` with the (x, y) footholds and the feet, ``feet``.

        The report is kept while none of it changes.
        """
        info = super().info()
        if info.feet is not self.support or len(info.footholds_xy) != len(self.footholds_xy):
            info = self._info = replace(
                info, footholds_xy=tuple(self.footholds_xy), feet=self.support
            )
        return info

    def check_state(self, state: FloatArray) -> None:
        """Require a planar state within the model: the CoM within L of the start's ankle."""
        if state.shape != (8,):
            raise InvalidParameterError(
                f"state must be {list(PLANE_STATE_LABELS)}, got shape {state.shape}"
            )
        ax, ay = self._start_support.ankle
        names = (("x", "xdot"), ("y", "ydot"))
        if (ax, ay) != (0.0, 0.0):  # the CoM from the start's ankle: say so
            names = (("x - ankle x", "xdot"), ("y - ankle y", "ydot"))
        check_com_state(float(state[0]) - ax, float(state[4]), self.params, names[0])
        check_com_state(float(state[1]) - ay, float(state[5]), self.params, names[1])
        for index, (_, _, limit) in zip((2, 3), self._limits, strict=True):
            if abs(float(state[index])) > limit:
                raise InvalidParameterError(
                    f"{PLANE_STATE_LABELS[index]} must satisfy |angle| <= {limit:g} rad, "
                    f"got {float(state[index]):g}"
                )

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        """Advance by dt [s]; return the state and the mean CoP (x, y) and the torques held."""
        state = self.state
        if command.step_length is not None:
            raise InvalidParameterError(
                "the stepping-plane model steps to a foothold: set foothold, not step_length"
            )
        if command.foothold is not None and self._swing is None:
            self._lift(command.foothold, command.touchdown, command.swing)
        torques = np.array(
            [
                min(limit, max(-limit, value))
                for value, (limit, _, _) in zip(
                    (command.flywheel_torque, command.roll_torque), self._limits, strict=True
                )
            ]
        )
        wanted = (command.cop, command.cop_y)
        cop_sum = np.zeros(2)
        left = dt
        swing = self._swing
        if swing is not None and self.time + dt >= swing[2] - 1e-12:
            before = max(0.0, swing[2] - self.time)
            state = self._hold(state, wanted, torques, before, cop_sum)
            self._land(swing[0], *swing[1])
            left = dt - before
        if left > 0.0:
            state = self._hold(state, wanted, torques, left, cop_sum)
        self.time += dt
        return state, (*(cop_sum / dt).tolist(), *torques.tolist())

    def _hold(
        self,
        state: FloatArray,
        wanted: tuple[float, float],
        torques: FloatArray,
        dt: float,
        cop_sum: FloatArray,
    ) -> FloatArray:
        """Exact ZOH over dt on the current support; add CoP · dt to ``cop_sum``."""
        if dt <= 0.0:
            return state
        cop = self.support.polygon.nearest_point(*wanted)
        cop_sum += np.array(cop) * dt
        yaw = self.support.yaw
        key = (dt, yaw)
        matrices = self._matrices.get(key)
        if matrices is None:
            matrices = plane_discrete(self.params, dt, yaw)
            if len(self._matrices) < 8:  # the control period's, and a few split ticks
                self._matrices[key] = matrices
        a, b = matrices
        new = a @ state + b @ np.concatenate([cop, torques])
        axes = ((math.cos(yaw), math.sin(yaw)), (-math.sin(yaw), math.cos(yaw)))
        momentum_scale = self.params.mass * self.params.com_height
        for angle, (_, inertia, limit), axis in zip((2, 3), self._limits, axes, strict=True):
            if abs(new[angle]) > limit:
                # The joint stop's impulse −I θ̇ reacts on the CoM: m L Δṙ = I θ̇ e_axis.
                new[angle] = math.copysign(limit, new[angle])
                kick = inertia * new[angle + 4] / momentum_scale
                new[4] += kick * axis[0]
                new[5] += kick * axis[1]
                new[angle + 4] = 0.0
                self.stop_impacts += 1
        return np.asarray(new, dtype=np.float64)

    def _lift(self, wanted: tuple[float, float], at: float | None, swing: str | None) -> None:
        """Lift the free foot (from double support: ``swing``) toward the foothold ``wanted``."""
        support = self.support
        if support.stance is Stance.DOUBLE:
            if not isinstance(swing, str) or swing not in ("left", "right"):
                raise InvalidParameterError(
                    f"a step from double support needs swing 'left' or 'right', got {swing!r}"
                )
            side = Stance(swing)
        else:
            side = Stance.RIGHT if support.stance is Stance.LEFT else Stance.LEFT
        stance = Stance.RIGHT if side is Stance.LEFT else Stance.LEFT
        pose = support.left if stance is Stance.LEFT else support.right
        reach = reach_polygon(self.params, side, pose.yaw).transformed(pose.x, pose.y, 0.0)
        foothold = reach.nearest_point(*wanted)
        touchdown = self.time + self.params.min_step_time
        if at is not None:
            touchdown = max(touchdown, at)
        self.support = Support.from_params(
            self.params, stance, left=support.left, right=support.right
        )
        self._swing = (side, foothold, touchdown)

    def _land(self, side: Stance, x: float, y: float) -> None:
        """Put the swing foot down at (x, y); the stance foot lifts (module docstring)."""
        support = self.support
        stance_pose = support.left if support.stance is Stance.LEFT else support.right
        pose = FootPose(x, y, stance_pose.yaw)
        left, right = (pose, support.right) if side is Stance.LEFT else (support.left, pose)
        self.support = Support.from_params(self.params, side, left=left, right=right)
        self.footholds.append(x)
        self.footholds_xy.append((x, y))
        self._swing = None

    @property
    def swinging(self) -> bool:
        """True between a lift and its touchdown."""
        return self._swing is not None

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """CoM speed at most ``speed`` [m/s], CoM over the support polygon, no foot swinging."""
        return (
            self._swing is None
            and math.hypot(float(state[4]), float(state[5])) <= speed
            and self.support.polygon.point_signed_distance(float(state[0]), float(state[1])) > 0.0
        )

    def falling(self, state: FloatArray) -> bool:
        """Farther than ``max_step_length`` from the support and moving away (module docstring)."""
        x, y = float(state[0]), float(state[1])
        nx, ny = self.support.polygon.nearest_point(x, y)
        gap_x, gap_y = x - nx, y - ny
        if math.hypot(gap_x, gap_y) <= self.params.max_step_length:
            return False
        return gap_x * float(state[4]) + gap_y * float(state[5]) > 0.0
