"""The ground plane: convex polygons, feet and the support polygon of a stance."""

from pushrecovery.ground.polygon import ConvexPolygon, convex_hull, rectangle
from pushrecovery.ground.support import FootPose, Stance, Support, foot_shape
from pushrecovery.ground.user_polygon import convex_polygon

__all__ = [
    "ConvexPolygon",
    "FootPose",
    "Stance",
    "Support",
    "convex_hull",
    "convex_polygon",
    "foot_shape",
    "rectangle",
]
