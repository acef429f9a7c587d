"""Parameters of one balancing body, validated once, and the built-in presets.

A :class:`BodyParams` holds everything the decision surfaces, models and controllers need.
Lengths are signed x-coordinates relative to the ankle, x forward (see ``docs/conventions.md``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

from pushrecovery.arguments import bounded_float, finite_float, positive_float, require_type
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "FIELD_NAMES",
    "GROWTH_TOLERANCE",
    "LIMITS",
    "OMEGA_MAX",
    "OMEGA_MIN",
    "UNITS",
    "BodyParams",
    "default_max_steps",
]

#: Narrowest foot [m]: a narrower one is a line, whose distances are rounding noise.
MIN_FOOT_WIDTH = 1e-3
#: Longest step time [s] (e^{-ω Δt_s} is then far below any margin) and most steps.
MAX_STEP_TIME = 5.0
MAX_STEPS = 50
#: Largest friction coefficient μ (dimensionless): above it a ground holds any LIPM force.
MAX_FRICTION = 10.0
#: The physical parameters' ranges (name: low, high, unit), docs/reliability.md: wide enough
#: for a 10 g toy and a 10 t machine, on the Moon or at 10 g, and narrow enough that no
#: formula of the project leaves float64 (a gravity of 1e15 m/s^2 or a leg of 1e300 m is
#: refused, not computed). The roll axis has the pitch axis's ranges.
LIMITS: dict[str, tuple[float, float, str]] = {
    "mass": (1e-2, 1e4, "kg"),
    "com_height": (1e-2, 10.0, "m"),
    "gravity": (0.1, 100.0, "m/s^2"),
    "flywheel_inertia": (1e-6, 1e4, "kg m^2"),
    "torque_max": (0.0, 1e5, "N m"),
    "flywheel_angle_max": (1e-3, math.pi, "rad"),
    "leg_length": (1e-2, 10.0, "m"),
}
#: The unit of every field of :class:`BodyParams` (``foot_polygon``: its vertices).
UNITS: dict[str, str] = {
    "mass": "kg", "com_height": "m", "gravity": "m/s^2", "heel": "m", "toe": "m",
    "flywheel_inertia": "kg m^2", "torque_max": "N m", "flywheel_angle_max": "rad",
    "leg_length": "m", "max_step_length": "m", "foot_width": "m", "stance_width": "m",
    "foot_polygon": "m", "flywheel_inertia_roll": "kg m^2", "torque_max_roll": "N m",
    "flywheel_angle_max_roll": "rad", "min_step_time": "s", "max_steps": "-",
    "min_step_width": "m", "ankle_torque_max": "N m", "friction": "-",
}  # fmt: skip
#: sqrt(g/L) over the bodies :data:`LIMITS` admits [1/s]: 0.1 to 100 (for functions that take
#: ω itself rather than a body).
OMEGA_MIN = math.sqrt(LIMITS["gravity"][0] / LIMITS["com_height"][1])
OMEGA_MAX = math.sqrt(LIMITS["gravity"][1] / LIMITS["com_height"][0])


@dataclass(frozen=True, slots=True)
class BodyParams:
    """Physical parameters of one balancing body (sagittal plane, SI units).

    Parameters
    ----------
    mass : float
        Total mass m [kg], in [0.01, 1e4] (every range: :data:`LIMITS`).
    com_height : float
        Height L of the centre of mass above the ankle, constant in the LIPM [m], in
        [0.01, 10].
    gravity : float
        Gravitational acceleration g [m/s^2], in [0.1, 100].
    heel : float
        Back edge of the support δ⁻, x-coordinate relative to the ankle [m], < 0.
    toe : float
        Front edge of the support δ⁺, x-coordinate relative to the ankle [m], > 0.
    flywheel_inertia : float
        Upper-body (flywheel) inertia I of Eq. (7) [kg m^2], in [1e-6, 1e4].
    torque_max : float
        Hip (flywheel) torque limit τmax of Eq. (5) [N m], in [0, 1e5].
    flywheel_angle_max : float
        Flywheel joint limit θmax of Eq. (11) [rad], in [0.001, π].
    leg_length : float or None
        Leg length for stepping, Sec. IV [m], in [0.01, 10]; ``None`` means equal to
        ``com_height``.
    max_step_length : float or None
        Longest step the legs can take, foot to foot [m], in (0, 2 leg_length); ``None``
        means equal to ``leg_length`` (a 30° stance-leg angle at impact).
    foot_width : float
        Width of the rectangular foot [heel, toe] × [−w/2, +w/2] [m], > 0 (paper preset 0.10).
    stance_width : float
        Lateral distance between the two ankles standing in double support [m], in
        (0, 2 leg_length) (paper preset 0.20).
    foot_polygon : tuple of (x, y) pairs or None
        Vertices of a left foot that is not a rectangle, in the foot's frame (ankle at the
        origin, x forward, y left) [m]: convex, non-degenerate, containing the ankle. The right
        foot is its mirror image (y → −y). ``None``: the rectangle above. When given, ``heel``,
        ``toe`` and ``foot_width`` must equal its extents (:func:`load_params` fills them in).
    flywheel_inertia_roll, torque_max_roll, flywheel_angle_max_roll : float or None
        The upper body's roll axis (CMP moved sideways, Eq. 6 in y): inertia [kg m^2], torque
        limit [N m] and joint limit [rad]; ``None`` means equal to the pitch value. Like
        ``leg_length``, the value is fixed when the parameters are built: ``dataclasses.replace``
        of a pitch value keeps the roll value (``load_params`` re-derives it).
    min_step_time : float
        Δt_s, the shortest time from deciding to step to the swing foot's touchdown [s], in
        [0, 5] (0: the paper's instantaneous step). Preset 0.2 s: a fast human compensatory
        swing, and longer than every swing of the project's simulated biped (0.04-0.15 s), so
        that its verdicts are on the safe side for the bodies we simulate (``docs/steps.md``).
    max_steps : int or None
        Largest number of steps a ``step`` verdict may take, in [1, 50]; ``None``: the smallest
        N beyond which the N-step capture region grows by less than 1 mm
        (:func:`pushrecovery.surfaces.n_step.default_max_steps`).
    min_step_width : float or None
        Narrowest lateral distance [m] between the stance ankle and the landing ankle, measured
        outward on the swing foot's side (a kinematic limit that forbids crossing the stance
        leg), in [0, max_step_length); ``None`` (preset): no limit, the reach is a disc and
        crossover steps count (people take them after sideways pushes; 0 keeps the landing
        ankle on its own side of the stance foot's line).
    ankle_torque_max : float or None
        Ankle torque limit [N m], in [0, 1e5]: the magnitude of the horizontal torque vector
        m g (p − a) × ẑ the support's vertical force m g exerts about the ankle a through a
        CoP p, ‖τ‖ = m g ‖p − a‖ (a plan's ``ankle_torque_ok``,
        :class:`~pushrecovery.surfaces.capture.plan.CapturePlan`); ``None`` (preset): not
        limited (the foot's edges are then the only bound on the CoP).
    friction : float or None
        Static friction coefficient μ of the ground, dimensionless, in (0, 10]: a plan's
        horizontal ground force m ω² ‖r − p‖ must stay within μ m g (``friction_ok``);
        ``None`` (preset): not limited. The generated MuJoCo models (``foot``, ``torso``,
        ``biped``, ``biped3d``) take it as their contacts' sliding friction (else 1).

    Raises
    ------
    InvalidParameterError
        If any value is non-finite or outside its range; the message names the field.
    """

    mass: float
    com_height: float
    gravity: float
    heel: float
    toe: float
    flywheel_inertia: float
    torque_max: float
    flywheel_angle_max: float
    leg_length: float = field(default=None)  # type: ignore[assignment]
    max_step_length: float = field(default=None)  # type: ignore[assignment]
    foot_width: float = 0.10
    stance_width: float = 0.20
    foot_polygon: tuple[tuple[float, float], ...] | None = None
    flywheel_inertia_roll: float = field(default=None)  # type: ignore[assignment]
    torque_max_roll: float = field(default=None)  # type: ignore[assignment]
    flywheel_angle_max_roll: float = field(default=None)  # type: ignore[assignment]
    min_step_time: float = 0.2
    max_steps: int = field(default=None)  # type: ignore[assignment]
    min_step_width: float | None = None
    ankle_torque_max: float | None = None
    friction: float | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for name in ("mass", "com_height", "gravity"):
            set_(self, name, bounded_float(name, getattr(self, name), *LIMITS[name]))
        heel = finite_float("heel", self.heel, "m")
        toe = finite_float("toe", self.toe, "m")
        if heel >= toe:
            raise InvalidParameterError(
                "heel must be < toe (an empty or inverted foot), "
                f"got heel={heel:g} m, toe={toe:g} m"
            )
        if heel >= 0.0:
            raise InvalidParameterError(f"heel must be < 0 m (behind the ankle), got heel={heel:g}")
        if toe <= 0.0:
            raise InvalidParameterError(f"toe must be > 0 m (ahead of the ankle), got toe={toe:g}")
        # The CoP <-> ankle-torque map of the pendulum divides by (1 - δ sinθ / L): keep |δ| < L.
        if max(-heel, toe) >= self.com_height:
            raise InvalidParameterError(
                "foot edges must lie closer to the ankle than com_height, got "
                f"heel={heel:g} m, toe={toe:g} m, com_height={self.com_height:g} m"
            )
        set_(self, "heel", heel)
        set_(self, "toe", toe)
        for name in ("flywheel_inertia", "torque_max", "flywheel_angle_max"):
            set_(self, name, bounded_float(name, getattr(self, name), *LIMITS[name]))
        leg = self.com_height if self.leg_length is None else self.leg_length
        leg = bounded_float("leg_length", leg, *LIMITS["leg_length"])
        set_(self, "leg_length", leg)
        reach = leg if self.max_step_length is None else self.max_step_length
        reach = positive_float("max_step_length", reach, "m")
        if reach >= 2.0 * leg:
            raise InvalidParameterError(
                f"max_step_length must be < 2 leg_length = {2 * leg:g} m, got {reach:g}"
            )
        set_(self, "max_step_length", reach)
        self._check_ground_plane(leg)
        self._check_steps()
        if self.ankle_torque_max is not None:
            limit = bounded_float("ankle_torque_max", self.ankle_torque_max, *LIMITS["torque_max"])
            set_(self, "ankle_torque_max", limit)
        if self.friction is not None:
            mu = finite_float("friction", self.friction, "")
            if not 0.0 < mu <= MAX_FRICTION:
                raise InvalidParameterError(
                    f"friction must be in (0, {MAX_FRICTION:g}] (a dimensionless coefficient), "
                    f"got {mu:g}"
                )
            set_(self, "friction", mu)

    def _check_steps(self) -> None:
        """Validate the step timing and limits; derive ``max_steps`` when not given."""
        set_ = object.__setattr__
        step_time = bounded_float("min_step_time", self.min_step_time, 0.0, MAX_STEP_TIME, "s")
        set_(self, "min_step_time", step_time)
        if self.min_step_width is not None:
            width = finite_float("min_step_width", self.min_step_width, "m")
            if not 0.0 <= width < self.max_step_length:
                raise InvalidParameterError(
                    f"min_step_width must be in [0, max_step_length = {self.max_step_length:g})"
                    f" m, got {width:g}"
                )
            set_(self, "min_step_width", width)
        steps = self.max_steps
        if steps is None:
            steps = default_max_steps(self)
        elif isinstance(steps, bool) or not (
            isinstance(steps, int) or (isinstance(steps, float) and steps.is_integer())
        ):
            raise InvalidParameterError(
                f"max_steps must be a whole number in [1, {MAX_STEPS}], got {steps!r}"
            )
        if not 1 <= steps <= MAX_STEPS:
            raise InvalidParameterError(f"max_steps must be in [1, {MAX_STEPS}], got {steps:g}")
        set_(self, "max_steps", int(steps))

    def _check_ground_plane(self, leg: float) -> None:
        """Validate the foot width, stance width, foot polygon and the roll axis."""
        set_ = object.__setattr__
        width = positive_float("foot_width", self.foot_width, "m")
        if not MIN_FOOT_WIDTH <= width < 2.0 * self.com_height:
            raise InvalidParameterError(
                f"foot_width must be in [{MIN_FOOT_WIDTH:g}, 2 com_height) m, got {width:g}"
            )
        set_(self, "foot_width", width)
        stance = positive_float("stance_width", self.stance_width, "m")
        if stance >= 2.0 * leg:
            raise InvalidParameterError(
                f"stance_width must be < 2 leg_length = {2 * leg:g} m, got {stance:g}"
            )
        set_(self, "stance_width", stance)
        if self.foot_polygon is not None:
            from pushrecovery.ground.user_polygon import convex_polygon

            polygon = convex_polygon("foot_polygon", self.foot_polygon, contains_origin=True)
            set_(self, "foot_polygon", tuple((float(x), float(y)) for x, y in polygon.vertices))
            extents = {
                "heel": polygon.xmin,
                "toe": polygon.xmax,
                "foot_width": polygon.ymax - polygon.ymin,
            }
            if max(-polygon.ymin, polygon.ymax) >= self.com_height:
                raise InvalidParameterError(
                    "foot_polygon must lie closer to the ankle than com_height, got y in "
                    f"[{polygon.ymin:g}, {polygon.ymax:g}] m, com_height={self.com_height:g} m"
                )
            for name, value in extents.items():
                if abs(getattr(self, name) - value) > 1e-9:
                    raise InvalidParameterError(
                        f"{name} must equal the extent of foot_polygon ({value:g} m) or be "
                        f"left out, got {name}={getattr(self, name):g}"
                    )
                set_(self, name, value)
        for pitch in ("flywheel_inertia", "torque_max", "flywheel_angle_max"):
            name = f"{pitch}_roll"
            value = getattr(self, name)
            value = getattr(self, pitch) if value is None else value
            set_(self, name, bounded_float(name, value, *LIMITS[pitch]))

    @property
    def foot_radius(self) -> float:
        """Distance from the ankle to the foot's farthest vertex [m] (rectangle or polygon)."""
        if self.foot_polygon is not None:
            return max(math.hypot(x, y) for x, y in self.foot_polygon)
        half = 0.5 * self.foot_width
        return max(math.hypot(self.heel, half), math.hypot(self.toe, half))

    @property
    def omega(self) -> float:
        """Natural frequency ω = sqrt(g / L) of the LIPM, Eq. (4) [1/s]."""
        return math.sqrt(self.gravity / self.com_height)

    @property
    def weight(self) -> float:
        """Body weight m g [N]; the vertical ground reaction force of the LIPM."""
        return self.mass * self.gravity

    @property
    def hip_fall_limits(self) -> tuple[float, float]:
        """Return δ⁻ − τmax/(m g), δ⁺ + τmax/(m g) [m]: the fall limits with the hip.

        Beyond them, moving outward, no CMP the hip can produce stops the CoM
        (docs/conventions.md).
        """
        reach = self.torque_max / self.weight
        return self.heel - reach, self.toe + reach

    def clip_cop(self, cop: float) -> float:
        """Return ``cop`` [m] moved onto the foot [heel, toe]."""
        return min(self.toe, max(self.heel, cop))

    def clip_hip_torque(self, torque: float) -> float:
        """Return ``torque`` [N m] clipped to ±torque_max."""
        return min(self.torque_max, max(-self.torque_max, torque))

    def to_dict(self) -> dict[str, float]:
        """Return the parameters as a plain dict (the ``params`` object of the JSON contract).

        ``foot_polygon`` becomes a list of [x, y] lists (what JSON reads back), or None.
        """
        data = asdict(self)
        if self.foot_polygon is not None:
            data["foot_polygon"] = [list(vertex) for vertex in self.foot_polygon]
        return data


FIELD_NAMES: tuple[str, ...] = tuple(f.name for f in fields(BodyParams))

#: One more step must grow every N-step region by less than this for N to be the default
#: ``max_steps`` [m].
GROWTH_TOLERANCE = 1e-3


def default_max_steps(params: BodyParams) -> int:
    """Smallest N whose next step grows every N-step region by less than 1 mm.

    From (S2) of docs/steps.md, one more step moves the support function by a_{N+1} (h_R +
    h_{F_{N+1}} − h_{F_N}) <= β^{N+1} (l + 2 ρ_F), β = e^{−ωΔt_s}, l the reach and ρ_F the
    foot's farthest vertex from its ankle: N is the smallest with that bound under
    :data:`GROWTH_TOLERANCE`. With Δt_s = 0 (the paper's instantaneous step) the regions never
    stop growing: N = 1, the paper's one step.
    """
    require_type("params", params, BodyParams)
    beta = math.exp(-params.omega * params.min_step_time)
    size = params.max_step_length + 2.0 * params.foot_radius
    if beta >= 1.0:
        return 1
    for steps in range(1, 51):
        if beta ** (steps + 1) * size < GROWTH_TOLERANCE:
            return steps
    return 50
