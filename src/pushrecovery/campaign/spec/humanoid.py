r"""What a campaign on the 3-D models adds: push directions, the WBC's strategies, predictions.

A campaign on ``biped3d`` or ``g1`` (``--backend mujoco``, docs/campaigns.md, "The 3-D
humanoids") pushes the standing body at its torso with an impulse J [N s] at each azimuth ψ
[deg] (0 forward +x, 90 left +y) under the whole-body controller with the tasks of one strategy
(:data:`WBC_CONTROLLERS`). The pushes may be given as fractions f of the ankle strategy's
predicted critical impulse along ψ (:func:`critical_impulse`), J = f J*_ankle(ψ), so that one
grid means the same from every direction (the side's limit is not the front's). The prediction
is the ground plane's (:func:`predict_push`; docs/validation3d.md derives it).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from typing import Any

from pushrecovery.arguments import finite_float, finite_vector, require_type
from pushrecovery.campaign.ranges import value_range
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mjcf_source import MjcfSource

__all__ = [
    "AZIMUTH_LIMIT",
    "MAX_AZIMUTHS",
    "MODELS_3D",
    "WBC_CONTROLLERS",
    "azimuth_grid",
    "check_azimuths",
    "check_spec3d",
    "critical_impulse",
    "predict_push",
    "push_geometry",
    "standing_origin",
]

#: The 3-D models a campaign runs (``sim.registry.PLANTS_3D``, and ``mjcf``: the spec's
#: :class:`~pushrecovery.sim.mjcf_source.MjcfSource`).
MODELS_3D: tuple[str, ...] = ("biped3d", "g1", "mjcf")
#: The whole-body controller's strategy sets, by campaign controller name: the highest
#: strategy it may use (ankle only; + the hip task; + the hip and the stepping task).
WBC_CONTROLLERS: Mapping[str, str] = {"wbc-ankle": "ankle", "wbc-hip": "hip", "wbc-step": "step"}
#: Largest abs(azimuth) [deg] and most azimuths of a campaign.
AZIMUTH_LIMIT = 360.0
MAX_AZIMUTHS = 360


def check_azimuths(values: Sequence[float], name: str = "azimuths") -> tuple[float, ...]:
    """Return ``values`` as floats: 1 to 360 finite angles in [−360, 360] deg, distinct mod 360.

    Raises
    ------
    InvalidParameterError
        Naming ``name``, for an empty or too long list, a value that is not a finite number
        in range, or two values that are the same direction.
    """
    require_type("name", name, str)
    if isinstance(values, str | bytes) or not isinstance(values, Sequence):
        raise InvalidParameterError(f"{name} must be a sequence of angles [deg], got {values!r}")
    if not 1 <= len(values) <= MAX_AZIMUTHS:
        raise InvalidParameterError(
            f"{name} must hold 1 to {MAX_AZIMUTHS} angles, got {len(values)}"
        )
    angles = []
    for value in values:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InvalidParameterError(f"{name} must be numbers [deg], got {value!r}")
        angle = float(value)
        if not (math.isfinite(angle) and abs(angle) <= AZIMUTH_LIMIT):
            raise InvalidParameterError(
                f"{name} must be in [-{AZIMUTH_LIMIT:g}, {AZIMUTH_LIMIT:g}] deg, got {angle:g}"
            )
        angles.append(angle)
    turns = [round(a % 360.0, 9) % 360.0 for a in angles]
    if len(set(turns)) != len(turns):
        raise InvalidParameterError(f"{name} repeats a direction (mod 360 deg): {angles}")
    return tuple(angles)


def azimuth_grid(text: str, name: str = "--azimuths") -> tuple[float, ...]:
    """Parse ``START:STOP:STEP`` (STOP included, but not a full turn's 360 = START) or a list.

    ``"0:360:30"`` gives 0, 30, ..., 330; ``"0,90,180"`` those three; ``"45"`` one angle.

    Raises
    ------
    InvalidParameterError
        Naming ``name``, for text that is neither form, or angles :func:`check_azimuths`
        refuses.
    """
    require_type("name", name, str)
    if not isinstance(text, str) or not text.strip():
        raise InvalidParameterError(f"{name} needs START:STOP:STEP or a list A,B,... [deg]")
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) != 3:
                raise ValueError
            values = [float(v) for v in value_range(name, (parts[0], parts[1], parts[2]), 10_000)]
            if len(values) > 1 and math.isclose(values[-1] - values[0], 360.0, abs_tol=1e-9):
                values.pop()  # a full turn: 360 is 0 again
        else:
            values = [float(p) for p in text.split(",")]
    except ValueError:
        raise InvalidParameterError(
            f"{name} needs START:STOP:STEP or a list A,B,... [deg], got {text!r}"
        ) from None
    return check_azimuths(values, name)


def check_spec3d(spec: Any) -> tuple[float, ...] | None:
    """Check a campaign's controller and, on a 3-D model, x0, sweeps, duration and pushes.

    ``spec`` is the :class:`~pushrecovery.campaign.spec.CampaignSpec` being built. Returns
    its azimuths: None on the 2-D models, (0,) by default on the 3-D ones.

    Raises
    ------
    InvalidParameterError
        Naming the field: azimuths or fraction on a 2-D model, an unknown controller, x0
        other than 0, a sweep of the G1's body, a duration over 60 s, a push range starting
        below 0, bad azimuths.
    """
    from pushrecovery.control.base import controller_class

    if not all(hasattr(spec, f) for f in ("model", "mjcf", "controller", "sweeps")):
        # Checked by its fields: spec.py imports this module.
        raise ParameterTypeError(f"spec must be a CampaignSpec, got {type(spec).__name__}")

    if (spec.model == "mjcf") != (spec.mjcf is not None):
        raise InvalidParameterError(
            "model 'mjcf' needs its file (mjcf, an MjcfSource), and mjcf needs model 'mjcf'"
        )
    if spec.model not in MODELS_3D:
        controller_class(spec.controller)  # raises, naming the controllers
        if spec.azimuths is not None or spec.fraction is not None:
            raise InvalidParameterError(
                "azimuths and fraction apply to the 3-D models (biped3d, g1, mjcf) only"
            )
        return None
    pushes = [p for p in (spec.xdot, spec.impulse, spec.fraction) if p is not None]
    push = pushes[0] if len(pushes) == 1 else None
    if spec.controller not in WBC_CONTROLLERS:
        raise InvalidParameterError(
            f"controller must be one of {list(WBC_CONTROLLERS)} on the 3-D model "
            f"{spec.model}, got {spec.controller!r}"
        )
    angles = (0.0,) if spec.azimuths is None else check_azimuths(spec.azimuths)
    x0 = spec.x0
    if len(x0) != 3 or float(x0[0]) != 0.0 or float(x0[1]) != 0.0:
        raise InvalidParameterError(
            f"x0 must be 0 on the 3-D model {spec.model} (it stands in its own posture), got {x0!r}"
        )
    if spec.model in ("g1", "mjcf") and spec.sweeps:
        robot = "the g1" if spec.model == "g1" else "an MJCF model"
        raise InvalidParameterError(f"{robot} has the robot's own body: no --param sweeps")
    if not spec.duration <= 60.0:
        raise InvalidParameterError(
            f"duration must be at most 60 s on the 3-D models, got {spec.duration:g}"
        )
    if push is not None and len(push) == 3 and not float(push[0]) >= 0.0:
        raise InvalidParameterError(
            f"pushes must be >= 0 on the 3-D models (the azimuth is the direction), "
            f"got START {push[0]!r}"
        )
    return angles


@functools.lru_cache(maxsize=32)
def push_geometry(model: str | MjcfSource, params: BodyParams) -> tuple[tuple[float, float], float]:
    """Return r₀ [m] and d/z₀ [-] of 3-D ``model`` with body ``params``, standing.

    r₀ is the standing CoM's ground point (the plant's reset state's x, y, in the frame of
    ``Support.from_params``: the ankles' midpoint at the origin); d the pushed torso's CoM
    height above the whole-body CoM and z₀ the CoM's above the soles [m]. Built once per
    body and process (a MuJoCo model is compiled).
    """
    from pushrecovery.sim.registry import make_plant3d

    if not isinstance(model, MjcfSource) and model not in MODELS_3D[:-1]:
        raise InvalidParameterError(
            f"model must be one of {list(MODELS_3D[:-1])} or an MjcfSource, got {model!r}"
        )
    plant = make_plant3d(model, params)
    return plant.standing_origin, plant.push_lever / float(plant.standing_height)


def standing_origin(model: str | MjcfSource, params: BodyParams) -> tuple[float, float]:
    """Return the standing CoM's ground point r₀ [m] (:func:`push_geometry`)."""
    require_type("params", params, BodyParams)
    require_type("model", model, (str, MjcfSource))
    return push_geometry(model, params)[0]


def critical_impulse(
    params: BodyParams, origin: tuple[float, float], azimuth: float, strategy: str = "ankle"
) -> float:
    """Return J*_R(ψ) = m ω ρ_R(r₀, ψ) [N s] for ``ankle`` or ``hip``.

    The push J along ψ gives the standing CoM's ground point r₀ the velocity J/m (cos ψ, sin ψ)
    and its capture point ξ = r₀ + J/(m ω) (cos ψ, sin ψ); ρ_R is the distance from r₀ to the
    boundary of the region R along ψ: the support polygon P (ankle, Eq. 4 in the plane) or the
    CMP region P ⊕ box(a_pitch, a_roll) (hip, corrected Eq. 15).

    Raises
    ------
    InvalidParameterError
        For another strategy, or ``origin`` outside the region.
    """
    require_type("params", params, BodyParams)
    origin = tuple(finite_vector("origin", origin, 2, 1e3, "m"))
    azimuth = finite_float("azimuth", azimuth, "deg")
    require_type("strategy", strategy, str)
    from pushrecovery.ground.support import Support
    from pushrecovery.surfaces.plane import cmp_polygon

    support = Support.from_params(params)
    if strategy == "ankle":
        region = support.polygon
    elif strategy == "hip":
        region = cmp_polygon(support, params)
    else:
        raise InvalidParameterError(f"strategy must be 'ankle' or 'hip', got {strategy!r}")
    heading = math.radians(float(azimuth))
    return params.mass * params.omega * region.ray_distance(origin[0], origin[1], heading)


def predict_push(
    params: BodyParams,
    origin: tuple[float, float],
    impulse: float,
    azimuth: float,
    lever_ratio: float = 0.0,
) -> tuple[Any, str]:
    """Return the ground plane's verdict for a push, and the verdict corrected for its height.

    The standing CoM at ``origin`` r₀ [m] gets the velocity J/m (cos ψ, sin ψ) from
    ``impulse`` J [N s] at ``azimuth`` ψ [deg]: ``surfaces.classify.classify`` on the body's
    double support. The corrected verdict is the same for the velocity
    × (1 + d/z₀), ``lever_ratio`` = d/z₀ >= 0 (the push at the torso's height:
    docs/validation3d.md, "The critical push from every direction").

    Returns
    -------
    (Classification, str)
        The verdict (strategy, capture point, margins, steps) and the corrected strategy.
    """
    require_type("params", params, BodyParams)
    origin = tuple(finite_vector("origin", origin, 2, 1e3, "m"))
    azimuth = finite_float("azimuth", azimuth, "deg")
    impulse = finite_float("impulse", impulse, "N s")
    from pushrecovery.arguments import bounded_float
    from pushrecovery.sim.push import Push3D
    from pushrecovery.surfaces.classify import classify

    ratio = bounded_float("lever_ratio", lever_ratio, 0.0, 100.0)
    dvx, dvy = Push3D(impulse, azimuth).delta_velocity(params.mass)
    found = classify(origin[0], dvx, params, y=origin[1], ydot=dvy)
    scale = 1.0 + ratio
    corrected = classify(origin[0], scale * dvx, params, y=origin[1], ydot=scale * dvy)
    return found, corrected.strategy.value
