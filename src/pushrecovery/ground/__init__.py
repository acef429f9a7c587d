"""The ground plane: convex polygons, feet and the support polygon of a stance."""

from pushrecovery.ground.polygon import ConvexPolygon, convex_hull, convex_polygon, rectangle
from pushrecovery.ground.support import FootPose, Stance, Support, foot_shape

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
