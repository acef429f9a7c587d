"""The capture-point plane: feet, support polygon, CMP region and pushes coloured by verdict.

One panel shows the ground plane of a stance (x forward, y left, world frame [m], equal
aspect): the feet (the lifted one dashed in single support), the support polygon (the ankle
strategy's capture region, Eq. 4 in the plane), the CMP region (the polygon grown by the pitch
and roll flywheels' offsets, corrected Eq. 15: hip) and sample states: pushes of many headings
and speeds from a CoM at rest above the stance's reference point (``support.ankle``), each
drawn at its capture point ξ = r + ṙ/ω and coloured by
:func:`~pushrecovery.surfaces.classify.classify_states` (ankle, hip, step, fall). The dashed
blue curve is the largest push some strategy recovers along each heading: the limit of
``max_steps`` steps (the N-step capture regions), found by bisection on the same classifier.

:func:`capture_plane_figure` draws one stance, whole and close to the feet;
:func:`capture_plane_panels` draws double, left and right support side by side on one scale.
Figures are built outside pyplot (``matplotlib.figure.Figure``): nothing to close.
"""

from pushrecovery.plots.plane.draw import (
    capture_plane_figure,
    capture_plane_panels,
    draw_capture_plane,
)
from pushrecovery.plots.plane.samples import (
    HEADINGS,
    LIMIT_HEADINGS,
    SPEEDS,
    PlaneSamples,
    plane_samples,
    recovery_limits,
    threshold_lines,
)

__all__ = [
    "HEADINGS",
    "LIMIT_HEADINGS",
    "SPEEDS",
    "PlaneSamples",
    "capture_plane_figure",
    "capture_plane_panels",
    "draw_capture_plane",
    "plane_samples",
    "recovery_limits",
    "threshold_lines",
]
