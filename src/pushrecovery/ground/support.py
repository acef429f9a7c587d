"""Feet on the ground plane and the support polygon of a stance.

A foot is a convex polygon in its own frame (ankle at the origin, x forward, y left): the
rectangle [heel, toe] × [−foot_width/2, foot_width/2] by default, or ``foot_polygon``
(:class:`~pushrecovery.params.BodyParams`). That shape is the *left* foot; the right foot is its
mirror image (y → −y). A :class:`FootPose` places a foot's ankle at (x, y) with a yaw. The
support polygon is the foot in single support and the convex hull of both feet in double
support (where the CoP can be anywhere between the feet: any convex combination of the two
feet's CoPs).

Default poses (``Support.from_params``): both ankles on the y axis, x = 0, the left at
+stance_width/2 and the right at −stance_width/2, yaw 0, so the world origin is the midpoint of
the ankles and the sagittal model's x axis runs between the feet.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from pushrecovery.arguments import finite_float, require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import ConvexPolygon, convex_hull, rectangle
from pushrecovery.ground.user_polygon import convex_polygon
from pushrecovery.params import BodyParams

__all__ = ["FootPose", "Stance", "Support", "foot_shape"]

#: Largest ankle coordinate of a pose [m]: far beyond any lab or map a balance query needs.
MAX_POSE = 1e6


class Stance(StrEnum):
    """Which feet carry the body."""

    DOUBLE = "double"
    LEFT = "left"
    RIGHT = "right"


@dataclass(frozen=True, slots=True)
class FootPose:
    """Where a foot stands: its ankle at (x, y) [m] and its yaw [rad], counter-clockwise.

    Raises
    ------
    InvalidParameterError
        If x or y is not finite or beyond ±:data:`MAX_POSE` m, or the yaw is not a finite
        number in [−π, π] rad (a yaw in degrees, such as 10.0, is refused, not wrapped).
    """

    x: float
    y: float
    yaw: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y"):
            value = finite_float(f"foot pose {name}", getattr(self, name), "m")
            if abs(value) > MAX_POSE:
                raise InvalidParameterError(
                    f"foot pose {name} must be within ±{MAX_POSE:g} m, got {value:g}"
                )
            object.__setattr__(self, name, value)
        yaw = finite_float("foot pose yaw", self.yaw, "rad")
        if abs(yaw) > math.pi:  # most likely degrees: refused rather than wrapped
            raise InvalidParameterError(
                f"foot pose yaw must be within [−π, π] rad (radians, not degrees), got {yaw:g}"
            )
        object.__setattr__(self, "yaw", yaw)

    @classmethod
    def parse(cls, name: str, text: str) -> FootPose:
        """Parse ``"X,Y[,YAW]"`` ([m], [m], [rad]) or raise naming ``name``."""
        parts = [part.strip() for part in text.split(",")]
        if len(parts) not in (2, 3):
            raise InvalidParameterError(f"{name} must be X,Y or X,Y,YAW (m, m, rad), got {text!r}")
        try:
            values = [float(part) for part in parts]
        except ValueError:
            raise InvalidParameterError(
                f"{name} must be X,Y or X,Y,YAW numbers (m, m, rad), got {text!r}"
            ) from None
        if not all(math.isfinite(value) for value in values):
            raise InvalidParameterError(f"{name} must be finite, got {text!r}")
        return cls(*values)


def foot_shape(params: BodyParams) -> ConvexPolygon:
    """Return the left foot in its own frame: ``foot_polygon`` or the heel/toe/width rectangle."""
    require_type("params", params, BodyParams)
    if params.foot_polygon is not None:
        return convex_polygon("foot_polygon", params.foot_polygon, contains_origin=True)
    return rectangle(params.heel, params.toe, params.foot_width)


@dataclass(frozen=True, slots=True, eq=False)
class Support:
    """The support polygon of a stance, with the feet that make it.

    Attributes
    ----------
    stance : Stance
        ``double``, ``left`` or ``right``.
    left, right : FootPose
        Poses of both feet (the lifted one is kept: the next issue steps with it).
    foot : ConvexPolygon
        The left foot in its own frame [m].
    polygon : ConvexPolygon
        The support polygon in the world frame [m].
    soles : (ConvexPolygon, ConvexPolygon) or None
        In double support, the left and right soles in the world frame, whose hull
        ``polygon`` is [m]; None in single support (the sole is ``polygon``).
    """

    stance: Stance
    left: FootPose
    right: FootPose
    foot: ConvexPolygon
    polygon: ConvexPolygon
    soles: tuple[ConvexPolygon, ConvexPolygon] | None = field(default=None, repr=False)

    @classmethod
    def from_params(
        cls,
        params: BodyParams,
        stance: str | Stance = Stance.DOUBLE,
        *,
        left: FootPose | None = None,
        right: FootPose | None = None,
    ) -> Support:
        """Support polygon of ``stance`` for feet at ``left``/``right`` (default poses: module).

        The last supports built are kept (everything here is immutable), so asking again for
        the same body, stance and feet costs a dictionary look-up, not a hull.

        Raises
        ------
        InvalidParameterError
            Unknown stance, overlapping or too distant feet in double support.
        """
        try:
            stance = Stance(stance)
        except ValueError:
            raise InvalidParameterError(
                f"stance must be one of {[s.value for s in Stance]}, got {stance!r}"
            ) from None
        require_type("params", params, BodyParams)
        for name, pose in (("left", left), ("right", right)):
            if pose is not None and not isinstance(pose, FootPose):
                raise ParameterTypeError(
                    f"{name} must be a FootPose(x, y, yaw) [m, m, rad], got {type(pose).__name__}"
                )
        half = 0.5 * params.stance_width
        left = FootPose(0.0, half) if left is None else left
        right = FootPose(0.0, -half) if right is None else right
        if cls is Support:
            return _support(params, stance, left, right)
        return cls._build(params, stance, left, right)

    @classmethod
    def _build(cls, params: BodyParams, stance: Stance, left: FootPose, right: FootPose) -> Support:
        foot, mirrored = _feet(params)
        if stance is Stance.LEFT:
            return cls(stance, left, right, foot, foot.transformed(left.x, left.y, left.yaw))
        placed = mirrored.transformed(right.x, right.y, right.yaw)
        if stance is Stance.RIGHT:
            return cls(stance, left, right, foot, placed)
        other = foot.transformed(left.x, left.y, left.yaw)
        _check_double_support(params, left, right, other, placed)
        polygon = convex_hull(np.vstack([other.vertices, placed.vertices]))
        return cls(stance, left, right, foot, polygon, (other, placed))

    def single(self, stance: str | Stance) -> Support:
        """Return the single support on one of these feet, the other lifted (the same poses).

        From double support the sole is the one the hull was built from (no polygon built:
        a lift-off in a loop costs a µs); the sole is otherwise placed as
        :meth:`from_params` places it.

        Raises
        ------
        InvalidParameterError
            If ``stance`` is not ``left`` or ``right``.
        """
        if stance not in (Stance.LEFT, Stance.RIGHT):
            raise InvalidParameterError(f"stance must be 'left' or 'right', got {stance!r}")
        stance = Stance(stance)
        if stance is self.stance:
            return self
        if self.soles is not None:
            sole = self.soles[0 if stance is Stance.LEFT else 1]
        elif stance is Stance.LEFT:
            sole = self.foot.transformed(self.left.x, self.left.y, self.left.yaw)
        else:
            sole = self.foot.mirrored().transformed(self.right.x, self.right.y, self.right.yaw)
        return type(self)(stance, self.left, self.right, self.foot, sole)

    @property
    def ankle(self) -> tuple[float, float]:
        """Reference point of the stance [m]: the stance ankle, or the ankles' midpoint."""
        if self.stance is Stance.LEFT:
            return self.left.x, self.left.y
        if self.stance is Stance.RIGHT:
            return self.right.x, self.right.y
        return 0.5 * (self.left.x + self.right.x), 0.5 * (self.left.y + self.right.y)

    @property
    def yaw(self) -> float:
        """Heading of the stance [rad]: the stance foot's yaw, or the mean of both (double).

        With the feet facing opposite ways (no mean), the left foot's yaw.
        """
        if self.stance is Stance.LEFT:
            return self.left.yaw
        if self.stance is Stance.RIGHT:
            return self.right.yaw
        sin = math.sin(self.left.yaw) + math.sin(self.right.yaw)
        cos = math.cos(self.left.yaw) + math.cos(self.right.yaw)
        if math.hypot(sin, cos) < 1e-9:  # feet facing opposite ways: no mean heading
            return self.left.yaw
        return math.atan2(sin, cos)

    def to_dict(self) -> dict[str, object]:
        """JSON form: stance, foot poses and the support polygon's vertices [m]."""
        return {
            "stance": self.stance.value,
            "left": {"x": self.left.x, "y": self.left.y, "yaw": self.left.yaw},
            "right": {"x": self.right.x, "y": self.right.y, "yaw": self.right.yaw},
            "vertices": self.polygon.to_list(),
            "area": self.polygon.area,
        }


def _check_double_support(
    params: BodyParams,
    left: FootPose,
    right: FootPose,
    left_sole: ConvexPolygon,
    right_sole: ConvexPolygon,
) -> None:
    """Refuse two feet on the ground that overlap or stand farther apart than two legs."""
    apart = math.hypot(left.x - right.x, left.y - right.y)
    if apart >= 2.0 * params.leg_length:
        raise InvalidParameterError(
            f"the ankles are {apart:g} m apart in double support, beyond 2 leg_length = "
            f"{2.0 * params.leg_length:g} m"
        )
    depth = left_sole.overlap_depth(right_sole)
    if depth > 1e-9:
        raise InvalidParameterError(
            f"the feet overlap by {depth:g} m in double support (left ankle at "
            f"({left.x:g}, {left.y:g}), right at ({right.x:g}, {right.y:g}); stance_width "
            f"{params.stance_width:g} m, foot_width {params.foot_width:g} m)"
        )


@functools.lru_cache(maxsize=16)
def _feet(params: BodyParams) -> tuple[ConvexPolygon, ConvexPolygon]:
    """Return the left foot in its own frame and its mirror image, the right foot (kept)."""
    foot = foot_shape(params)
    return foot, foot.mirrored()


@functools.lru_cache(maxsize=64)
def _support(params: BodyParams, stance: Stance, left: FootPose, right: FootPose) -> Support:
    """:meth:`Support._build`, remembered (params and poses are frozen and hashable)."""
    return Support._build(params, stance, left, right)
