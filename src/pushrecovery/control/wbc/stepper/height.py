r"""How high the pelvis may stand while the legs step: the leg's reach (:mod:`.stepper.stepper`).

World frame, x forward, y left, z up, SI units. A leg of thigh a and shank b with its knee bent
by κ spans

.. math:: \ell(\kappa) = \sqrt{a^2 + b^2 + 2 a b \cos\kappa}

from hip to ankle, so with the ankle at horizontal distance r from the hip and height z_a the
hip stands at most z_a + sqrt(ℓ(κ)² − r²) if the knee is to stay bent by κ.
:func:`pelvis_limit` takes the lowest such bound over the legs (the swinging foot at its
foothold, seen from where its hip will be at touchdown), converted to the pelvis.
docs/humanoid3d_stepping.md, "The plan" (pelvis height), gives the rule and the numbers.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.stepper.leg import Leg
from pushrecovery.errors import InvalidParameterError

FloatArray = NDArray[np.float64]

__all__ = []


def segment_lengths(data: HumanoidObservation, leg: Leg) -> tuple[float, float]:
    """Return the thigh (hip to knee anchor) and shank (knee anchor to ankle) lengths [m].

    The ankle is the foot body's origin (the ankle joint); constant for rigid segments.

    Raises
    ------
    InvalidParameterError
        If the leg has no hip pitch or knee joint (:func:`~.leg.leg_joints`).
    """
    if leg.hip_pitch < 0 or leg.knee < 0:
        raise InvalidParameterError("the leg needs a hip_pitch and a knee joint to measure")
    hip = np.asarray(data.xanchor[leg.hip_pitch], dtype=float)
    knee = np.asarray(data.xanchor[leg.knee], dtype=float)
    ankle = np.asarray(data.xpos[leg.foot], dtype=float)
    return float(np.linalg.norm(knee - hip)), float(np.linalg.norm(ankle - knee))


def leg_span(thigh: float, shank: float, knee: float) -> float:
    """Return ℓ(κ) = sqrt(a² + b² + 2ab cos κ) [m], hip to ankle with the knee bent κ [rad]."""
    return math.sqrt(thigh**2 + shank**2 + 2.0 * thigh * shank * math.cos(knee))


def pelvis_limit(
    data: HumanoidObservation,
    legs: tuple[Leg, ...],
    spans: tuple[float, ...],
    pelvis: int,
    *,
    swing: int | None = None,
    foothold: FloatArray | None = None,
    shift: FloatArray | None = None,
) -> float:
    """Return the highest pelvis origin [m] at which every leg reaches its ankle (module doc).

    Parameters
    ----------
    data : HumanoidObservation
        The state (after ``mj_kinematics``).
    legs : tuple of Leg
        The legs (their hip pitch anchors are the hips, their foot bodies the ankles).
    spans : tuple of float
        Each leg's ℓ(κ) [m] (:func:`leg_span`).
    pelvis : int
        The body the hips hang from (its origin is the pelvis height task's point).
    swing : int, optional
        The leg in the air: its ankle at ``foothold`` [m] (world xy), its hip moved by
        ``shift`` [m] (world xy, the CoM's motion to touchdown), at the other ankle's height.
    """
    base = float(data.xpos[pelvis][2])
    best = math.inf
    for index, (leg, span) in enumerate(zip(legs, spans, strict=True)):
        hip = np.asarray(data.xanchor[leg.hip_pitch], dtype=float)
        ankle = np.asarray(data.xpos[leg.foot], dtype=float)
        hip_xy, ankle_xy, ankle_z = hip[:2], ankle[:2], float(ankle[2])
        if index == swing and foothold is not None:
            other = legs[1 - index] if len(legs) == 2 else leg
            ankle_xy, ankle_z = np.asarray(foothold, dtype=float), float(data.xpos[other.foot][2])
            if shift is not None:
                hip_xy = hip_xy + np.asarray(shift, dtype=float)
        distance = float(np.linalg.norm(hip_xy - ankle_xy))
        height = ankle_z + math.sqrt(max(span**2 - distance**2, 0.0))
        best = min(best, height - (float(hip[2]) - base))
    return best
