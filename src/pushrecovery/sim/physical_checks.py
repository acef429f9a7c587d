r"""Physical checks of a run: loaded feet that slide, implausible contacts and torques.

A simulated push is only ``recovered`` if it is physically what it claims. A MuJoCo plant's
:class:`~pushrecovery.sim.mujoco.contact_audit.ContactAudit` watches every physics step of a run
and sums it up as :class:`PhysicalChecks`:

* **Loaded-foot slip** [m]: while a foot carries at least :data:`LOAD_FRACTION` of the body
  weight m g (the vertical force of the floor on it), the horizontal travel of its sole in the
  floor's plane, integrated from the instant the load began: each sole point c (the foot's
  lowest points in its standing pose, :func:`~pushrecovery.control.wbc.bodies.sole_points`)
  moves by d_c = ∫ (v_p + ω_z ẑ × (c − p))_xy dt, with p the foot's CoP
  Σ F_z,i p_i / Σ F_z,i over its floor contacts, v_p = v_o + ω × (p − o) the velocity of the
  foot's material point at p (o the foot body's origin, v_o and ω its linear and angular
  velocity, from MuJoCo's ``cvel``, world frame). A foot rolling about its toe or heel edge
  (ω_x, ω_y about the CoP) does not count; a foot spinning about a point (ω_z: MuJoCo's
  point contacts without torsional friction let a foot yaw on one toe corner) does, as a
  real sole would slide. A foot below the load threshold for at least :data:`LIFT_TIME`
  (a step's swing, not a bounce: a foot that chatters while it slides keeps its interval)
  starts a new interval at its next load. The check is the largest ‖d_c‖ of any point and
  interval.
* **Peak vertical ground force** [N] of the floor on the body (all floor contacts, world z) and
  its ratio to m g: a touchdown that bounces shows tens of body weights in one step.
* **Largest penetration** [m] of any floor contact (MuJoCo's contact distance below 0).
* **Friction-cone use** [-]: the largest ‖f_t‖ / (μ f_n) of any floor contact carrying more
  than :data:`LOAD_FRACTION` / 100 of m g (1: on the cone's edge, sliding; contact frame, μ the
  contact's sliding friction).
* **Torque use per joint group** [-]: the largest ‖τ‖ / τ_limit of the actuators of each group
  (:data:`JOINT_GROUPS`, by actuator name; τ_limit the actuator's force range, else its control
  range times its gear, else its joint's actuator force range; an unlimited actuator counts 0).
* **Joint-limit steps**: physics steps in which any joint sat on its range limit (an active
  joint-limit constraint).

A run is ``recovered`` only with ``foot_slip <= slip_limit`` (1 cm unless set) and no torque use
above 1 (:meth:`PhysicalChecks.violations`); the plants' runs turn such a run's outcome into
``slipped`` (:func:`~pushrecovery.sim.result.judge`; docs/conventions.md, "Outcome").
"""

from __future__ import annotations

from dataclasses import dataclass

from pushrecovery.arguments import require_type

__all__ = [
    "DEFAULT_SLIP_LIMIT",
    "JOINT_GROUPS",
    "LIFT_TIME",
    "LOAD_FRACTION",
    "PhysicalChecks",
    "joint_group",
]

#: A foot carrying at least this fraction of m g is loaded: its slip counts [-].
LOAD_FRACTION = 0.1
#: A foot unloaded this long [s] has lifted: its next load starts a new slip interval.
LIFT_TIME = 0.05
#: Largest loaded-foot slip of a run that may count as recovered [m].
DEFAULT_SLIP_LIMIT = 0.01
#: Joint groups by a word in the actuator's name (the first match; else ``"other"``).
JOINT_GROUPS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("ankle", ("ankle",)),
    ("knee", ("knee",)),
    ("hip", ("hip",)),
    ("waist", ("waist", "torso", "spine", "abdomen", "pelvis")),
    ("arm", ("shoulder", "elbow", "wrist", "arm", "hand")),
    ("head", ("head", "neck")),
)
#: Torque use above 1 by more than this is over the limit (float rounding of a clipped command).
_OVER = 1e-9


def joint_group(name: str) -> str:
    """Return the joint group (:data:`JOINT_GROUPS`) of an actuator called ``name``.

    Raises
    ------
    ParameterTypeError
        If ``name`` is not a str.
    """
    require_type("name", name, str)
    lowered = name.lower()
    for group, words in JOINT_GROUPS:
        if any(word in lowered for word in words):
            return group
    return "other"


@dataclass(frozen=True, slots=True)
class PhysicalChecks:
    """What :class:`ContactAudit` found over a run (module docstring for the definitions).

    Attributes
    ----------
    foot_slip : float
        Largest horizontal slip of a loaded foot [m].
    slip_foot : str
        The foot body that slipped the most ("" when none was loaded).
    peak_ground_force : float
        Largest vertical force of the floor on the body in one physics step [N].
    peak_force_ratio : float
        ``peak_ground_force`` / (m g) [-].
    max_penetration : float
        Largest depth of a floor contact [m] (0: none below the surface).
    friction_use : float
        Largest ‖f_t‖ / (μ f_n) of a loaded floor contact [-] (1: sliding).
    torque_use : tuple of (str, float)
        Per joint group, the largest ‖τ‖ / τ_limit of its actuators [-], groups in
        :data:`JOINT_GROUPS` order.
    joint_limit_steps : int
        Physics steps with a joint on its range limit.
    physics_steps : int
        Physics steps audited.
    slip_limit : float
        Largest slip that may count as recovered [m].
    """

    foot_slip: float
    slip_foot: str
    peak_ground_force: float
    peak_force_ratio: float
    max_penetration: float
    friction_use: float
    torque_use: tuple[tuple[str, float], ...]
    joint_limit_steps: int
    physics_steps: int
    slip_limit: float = DEFAULT_SLIP_LIMIT

    @property
    def peak_torque_use(self) -> float:
        """The largest torque use of any group [-]."""
        return max((use for _, use in self.torque_use), default=0.0)

    def violations(self) -> tuple[str, ...]:
        """Return what keeps the run from counting as recovered: ``"slip"``, ``"torque"``."""
        found = ("slip",) if self.foot_slip > self.slip_limit else ()
        return found + (("torque",) if self.peak_torque_use > 1.0 + _OVER else ())

    def to_dict(self) -> dict[str, object]:
        """Return the checks for JSON (the ``physics`` key of ``simulate --json``), SI units."""
        return {
            "foot_slip_m": self.foot_slip,
            "slip_foot": self.slip_foot,
            "slip_limit_m": self.slip_limit,
            "peak_ground_force_n": self.peak_ground_force,
            "peak_force_body_weights": self.peak_force_ratio,
            "max_penetration_m": self.max_penetration,
            "friction_use": self.friction_use,
            "torque_use": dict(self.torque_use),
            "joint_limit_steps": self.joint_limit_steps,
            "physics_steps": self.physics_steps,
            "violations": list(self.violations()),
        }
